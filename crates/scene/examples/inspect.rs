//! Prints a summary of a scene: `cargo run -p scene --example inspect -- NAME_OR_PATH`.
//! Useful to check what the loader made of a glTF file (counts, bounds, lights, camera).

fn main() {
    let Some(arg) = std::env::args().nth(1) else {
        eprintln!("usage: inspect <builtin name | file.gltf | file.glb>");
        std::process::exit(2);
    };
    let s = match scene::load_any(&arg) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let tris: usize = s.meshes.iter().map(|m| m.indices.len() / 3).sum();
    println!(
        "{}: {} meshes, {tris} triangles, {} materials, {} textures, {} lights",
        s.source,
        s.meshes.len(),
        s.materials.len(),
        s.textures.len(),
        s.lights.len()
    );
    for w in &s.warnings {
        println!("warning: {w}");
    }
    if let Some((lo, hi)) = s.bounds() {
        println!("bounds {lo} .. {hi}");
    }
    println!(
        "camera at {} yfov {:.3} near {} far {} aspect {:?} ortho {:?}",
        s.camera.position(),
        s.camera.yfov,
        s.camera.znear,
        s.camera.zfar,
        s.camera.aspect,
        s.camera.ortho
    );
    for (i, m) in s.meshes.iter().enumerate() {
        println!(
            "mesh {i}: {} vertices, {} triangles, tangents {}, uvs {}, uvs1 {}, colors {}, material {} '{}' {:?}{}",
            m.positions.len(),
            m.indices.len() / 3,
            m.tangents.len(),
            m.uvs.len(),
            m.uvs1.len(),
            m.colors.len(),
            m.material,
            s.materials[m.material].name,
            s.materials[m.material].alpha_mode,
            if s.materials[m.material].double_sided { " double-sided" } else { "" }
        );
        // Triangles whose winding disagrees with their shading normals: a sign of a transform
        // or winding bug (or of a file authored inside-out).
        let flipped = m
            .indices
            .chunks_exact(3)
            .filter(|t| {
                let p = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
                let n = t.iter().map(|&i| m.normals[i as usize]).sum::<glam::Vec3>();
                (p[1] - p[0]).cross(p[2] - p[0]).dot(n) < 0.0
            })
            .count();
        if flipped > 0 {
            println!("  {flipped} triangles wound against their normals");
        }
    }
    for m in &s.materials {
        println!("material '{}': base {} spectral {}", m.name, m.base_color, m.spectral.is_some());
    }
    for t in &s.textures {
        println!("texture '{}': {}x{} srgb {}", t.name, t.width, t.height, t.srgb);
    }
    for l in &s.lights {
        println!(
            "light '{}': {:?} rgb×I {} spectral {} stand-in {:?}",
            l.name,
            l.kind,
            l.emission.linear_srgb(),
            l.emission.spectrum.is_some(),
            l.stands_in_for
        );
    }
    println!("spectral {:?} water {:?}", s.spectral, s.water);
}
