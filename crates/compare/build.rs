//! Compiles NVIDIA's FLIP reference implementation (flip/FLIP.h, BSD-3-Clause) and our C ABI over
//! it with the system C++ compiler (`cargo xtask setup` installs g++ on Debian/Ubuntu).

fn main() {
    println!("cargo:rerun-if-changed=flip/FLIP.h");
    println!("cargo:rerun-if-changed=flip/flip_capi.cpp");
    cc::Build::new()
        .cpp(true)
        .std("c++17")
        // The reference is built optimised (CMake Release); at -O0 a debug build would take
        // seconds per image.
        .opt_level(3)
        // FLIP.h's own warnings (unused variables, sign comparisons) are not ours to fix.
        .warnings(false)
        .file("flip/flip_capi.cpp")
        .compile("spectra_flip");
}
