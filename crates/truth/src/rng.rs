//! Per-pixel random streams: the image depends on the seed only, never on which thread
//! rendered which pixel or in which order.

use rand_core::RngCore;
use rand_pcg::Pcg32;

/// SplitMix64 finaliser: decorrelates nearby seeds (pixel indices differ by 1) before they
/// become PCG states.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The random stream of one pixel (PCG32 with a stream selector derived from the pixel).
pub struct Sampler(Pcg32);

impl Sampler {
    pub fn new(seed: u64, pixel: u64) -> Self {
        Sampler(Pcg32::new(mix(seed ^ mix(pixel)), mix(pixel.wrapping_add(seed.rotate_left(17)))))
    }

    /// The random stream of sample `sample` of pixel `pixel`: every sample has its own, so a
    /// render of samples K … K+N−1 (`--sample-offset`, `--chunk`) draws exactly what those
    /// samples draw in one render of them all, and a crop exactly what its pixels draw.
    pub fn for_sample(seed: u64, pixel: u64, sample: u64) -> Self {
        let key = mix(seed ^ mix(pixel)) ^ mix(sample.wrapping_add(0x5851_f42d_4c95_7f2d));
        Sampler(Pcg32::new(mix(key), mix(key ^ pixel.rotate_left(29) ^ sample.rotate_left(7))))
    }

    /// Uniform in [0, 1) with 24 bits, so it never rounds up to 1.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        (self.0.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    #[inline]
    pub fn next2(&mut self) -> [f32; 2] {
        [self.uniform(), self.uniform()]
    }

    /// 64 random bits: the key of one ray's stochastic decisions ([`hash_uniform`]).
    #[inline]
    pub fn key(&mut self) -> u64 {
        ((self.0.next_u32() as u64) << 32) | self.0.next_u32() as u64
    }
}

/// A uniform number in [0, 1) that depends only on (`key`, `x`): the same triangle seen twice
/// by one ray (a triangle the BVH builder split over several leaves) gets the same value, and
/// the value never depends on traversal order or thread.
#[inline]
pub fn hash_uniform(key: u64, x: u64) -> f32 {
    (mix(key ^ mix(x)) >> 40) as f32 * (1.0 / 16_777_216.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<f32> = (0..8)
            .map({
                let mut s = Sampler::new(7, 3);
                move |_| s.uniform()
            })
            .collect();
        let b: Vec<f32> = (0..8)
            .map({
                let mut s = Sampler::new(7, 3);
                move |_| s.uniform()
            })
            .collect();
        let c: Vec<f32> = (0..8)
            .map({
                let mut s = Sampler::new(7, 4);
                move |_| s.uniform()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert!(a.iter().all(|&x| (0.0..1.0).contains(&x)));
    }
}
