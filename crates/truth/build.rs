//! `CODE_HASH`: a hash of the source the tracer's images depend on (this crate, `scene` and
//! `color`), so that a stored ground truth (a merge chunk, the evaluation's truth cache) is
//! reused only by a tracer built from the same code. Conservative on purpose: a change to a
//! comment invalidates too, which costs a render, where a stale truth would cost a wrong figure.

use std::path::{Path, PathBuf};

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else { return };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            files(&p, out);
        } else {
            out.push(p);
        }
    }
}

fn main() {
    let here = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    // Inside the workspace the sibling crates sit beside this one; a published crate has only
    // its own source, which is then all that is hashed.
    let dirs = [here.join("src"), here.join("../scene/src"), here.join("../color/src")];
    // FNV-1a 64 (as color::signature::fnv1a64, which a build script cannot call).
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    for (i, dir) in dirs.iter().enumerate() {
        println!("cargo:rerun-if-changed={}", dir.display());
        let mut list = Vec::new();
        files(dir, &mut list);
        let mut rel: Vec<(String, PathBuf)> = list
            .into_iter()
            .map(|p| (p.strip_prefix(dir).unwrap_or(&p).to_string_lossy().replace('\\', "/"), p))
            .collect();
        rel.sort();
        for (name, p) in rel {
            let Ok(bytes) = std::fs::read(&p) else { continue };
            // Line endings are a checkout's choice, not the code's.
            let text: Vec<u8> = bytes.into_iter().filter(|&b| b != b'\r').collect();
            eat(format!("{i}/{name}\0{}\0", text.len()).as_bytes());
            eat(&text);
        }
    }
    println!("cargo:rustc-env=TRUTH_CODE_HASH={h:016x}");
}
