//! Writes every built-in scene as a self-contained glTF file:
//! `cargo run -p scene --example export_builtins -- OUT_DIR` (default `crates/scene/examples/scenes`).

use std::path::PathBuf;

fn main() {
    let dir = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/scenes"), PathBuf::from);
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("error: cannot create {}: {e}", dir.display());
        std::process::exit(1);
    }
    for name in scene::BUILTIN_NAMES {
        let path = dir.join(format!("{name}.gltf"));
        let result = scene::builtin(name).and_then(|s| scene::write_gltf(&s, &path));
        match result {
            Ok(()) => println!("wrote {}", path.display()),
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(1);
            }
        }
    }
}
