//! The signature every on-disk cache appends to what it writes (upsampling tables, water light
//! fields): a damaged, truncated, edited or substituted file is told from the one written and
//! recomputed, not used. FNV-1a over the payload — not a defence against someone forging it,
//! which each cache's own plausibility check covers for files that would render wrongly.

/// Marks the signature after a payload (readers of `.coeff` files, ours and Mitsuba's, ignore
/// trailing bytes).
const TAG: &[u8] = b"\nspectra-cache-signature fnv1a64=";

/// FNV-1a, 64 bits.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

/// `payload` with its signature appended.
pub fn sign(mut payload: Vec<u8>) -> Vec<u8> {
    let sum = fnv1a64(&payload);
    payload.extend_from_slice(TAG);
    payload.extend_from_slice(format!("{sum:016x}\n").as_bytes());
    payload
}

/// Whether `trailer` is the signature of `payload` (exactly: nothing before or after it).
pub fn verify(payload: &[u8], trailer: &[u8]) -> bool {
    let Some(hex) = trailer.strip_prefix(TAG).and_then(|t| t.strip_suffix(b"\n")) else {
        return false;
    };
    std::str::from_utf8(hex).ok().and_then(|h| u64::from_str_radix(h, 16).ok()) == Some(fnv1a64(payload))
}

/// The payload of signed `bytes` whose payload is `payload_len` bytes long, if the signature
/// matches.
pub fn payload(bytes: &[u8], payload_len: usize) -> Option<&[u8]> {
    let (p, t) = bytes.split_at_checked(payload_len)?;
    verify(p, t).then_some(p)
}

/// Bytes a signature adds.
pub const LEN: usize = TAG.len() + 17;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_every_single_byte_change_is_caught() {
        let p: Vec<u8> = (0..200u32).map(|i| (i * 37 % 251) as u8).collect();
        let s = sign(p.clone());
        assert_eq!(s.len(), p.len() + LEN);
        assert_eq!(payload(&s, p.len()), Some(&p[..]));
        for i in 0..s.len() {
            let mut t = s.clone();
            t[i] ^= 0x10;
            assert_eq!(payload(&t, p.len()), None, "byte {i}");
        }
        assert_eq!(payload(&s[..s.len() - 1], p.len()), None);
        let mut longer = s.clone();
        longer.push(b'\n');
        assert_eq!(payload(&longer, p.len()), None);
        assert_eq!(payload(&p, p.len()), None, "unsigned");
    }

    #[test]
    fn fnv1a64_matches_the_published_test_vectors() {
        // From the FNV reference (Fowler, Noll, Vo): FNV-1a 64 of "" and "a".
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
    }
}
