//! Prints the world-space corners of every triangle the loader makes of a glTF file, posed as
//! `--animation`/`--time` ask (at rest without them), as JSON: what `tools/pose_check.py`
//! compares with the three.js oracle (`tools/pose_oracle`).
//!
//! `cargo run --release -p scene --example posed_positions -- FILE [--animation X] [--time T]`

use std::process::ExitCode;

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let mut file = None;
    let mut opts = scene::LoadOptions::default();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--animation" => opts.animation = args.next().map(scene::AnimationRef::NameOrIndex),
            "--time" => match args.next().and_then(|t| t.parse().ok()) {
                Some(t) => opts.time = Some(t),
                None => {
                    eprintln!("--time needs a number of seconds");
                    return ExitCode::FAILURE;
                }
            },
            _ if file.is_none() => file = Some(a),
            _ => {
                eprintln!("usage: posed_positions FILE [--animation NAME|INDEX] [--time SECONDS]");
                return ExitCode::FAILURE;
            }
        }
    }
    let Some(file) = file else {
        eprintln!("usage: posed_positions FILE [--animation NAME|INDEX] [--time SECONDS]");
        return ExitCode::FAILURE;
    };
    let s = match scene::load_with(&file, &opts) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    // The loader moves a far-off scene to the origin; the file's own frame is what the oracle has.
    let o = s.origin;
    let meshes: Vec<String> = s
        .meshes
        .iter()
        .map(|m| {
            let tris: Vec<String> = m
                .indices
                .chunks_exact(3)
                .map(|t| {
                    let c: Vec<String> = t
                        .iter()
                        .map(|&i| {
                            let p = m.positions[i as usize].as_dvec3() + o;
                            format!("[{:.7e},{:.7e},{:.7e}]", p.x, p.y, p.z)
                        })
                        .collect();
                    format!("[{}]", c.join(","))
                })
                .collect();
            format!("{{\"triangles\":[{}]}}", tris.join(","))
        })
        .collect();
    // The camera as the file places it (the loader frames a scene without one itself).
    let has_camera = std::fs::read(&file)
        .ok()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        .and_then(|v| v.get("nodes")?.as_array().map(|n| n.iter().any(|n| n.get("camera").is_some())))
        .unwrap_or(false);
    let camera = if !has_camera {
        "null".to_string()
    } else {
        let t = s.camera.transform;
        let p = t.w_axis.truncate().as_dvec3() + o;
        let f = (-t.z_axis.truncate()).normalize();
        format!(
            "{{\"position\":[{:.7e},{:.7e},{:.7e}],\"forward\":[{:.7e},{:.7e},{:.7e}]}}",
            p.x, p.y, p.z, f.x, f.y, f.z
        )
    };
    println!("{{\"meshes\":[{}],\n\"camera\":{camera}}}", meshes.join(",\n"));
    ExitCode::SUCCESS
}
