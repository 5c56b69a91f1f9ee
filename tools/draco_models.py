#!/usr/bin/env python3
"""Extracts the Khronos glTF sample models that have a glTF-Draco variant, with their plain
glTF variant, from a git checkout or mirror of KhronosGroup/glTF-Sample-Assets, textures
stripped (the test compares geometry): what `crates/scene/tests/draco.rs`'s
`every_khronos_draco_model` reads (also the source of its fixtures in tests/data/draco).

    tools/draco_models.py REPO OUT [MODEL ...]
    DRACO_MODELS=OUT cargo test --release -p scene --test draco -- --ignored --nocapture
"""
import json
import os
import subprocess
import sys


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    repo, out, only = sys.argv[1], sys.argv[2], sys.argv[3:]

    def git(*a, text=False):
        return subprocess.run(["git", "-C", repo, *a], capture_output=True, check=True, text=text).stdout

    names = git("ls-tree", "-r", "--name-only", "HEAD", text=True).split("\n")
    models = sorted({n.split("/")[1] for n in names if "/glTF-Draco/" in n and n.startswith("Models/")})
    for m in models:
        if only and m not in only:
            continue
        for variant in ["glTF", "glTF-Draco"]:
            os.makedirs(os.path.join(out, m, variant), exist_ok=True)
            for f in [n for n in names if n.startswith(f"Models/{m}/{variant}/")]:
                dst = os.path.join(out, m, variant, os.path.basename(f))
                if f.endswith(".gltf"):
                    j = json.loads(git("cat-file", "blob", f"HEAD:{f}"))
                    for k in ("images", "textures", "samplers"):
                        j.pop(k, None)
                    if "materials" in j:
                        j["materials"] = strip(j["materials"])
                    with open(dst, "w") as fh:
                        json.dump(j, fh, indent=1)
                elif f.endswith(".bin"):
                    with open(dst, "wb") as fh:
                        fh.write(git("cat-file", "blob", f"HEAD:{f}"))
        lic = f"Models/{m}/LICENSE.md"
        if lic in names:
            with open(os.path.join(out, m, "LICENSE.md"), "wb") as fh:
                fh.write(git("cat-file", "blob", f"HEAD:{lic}"))
        print(m)


def strip(o):
    """The materials without their textures (every `…Texture` key, extensions included)."""
    if isinstance(o, dict):
        return {k: strip(v) for k, v in o.items() if not k.endswith("Texture")}
    if isinstance(o, list):
        return [strip(v) for v in o]
    return o


if __name__ == "__main__":
    main()
