"""Makes the KTX2 fixtures from the Khronos glTF-Sample-Assets StainedGlassLamp model.

Usage: python3 make_fixtures.py MODEL_DIR   (MODEL_DIR = .../Models/StainedGlassLamp)
Needs Pillow and zstandard. See README.md for what each file is.
"""

import shutil
import struct
import sys
from pathlib import Path

import zstandard
from PIL import Image

here = Path(__file__).parent
model = Path(sys.argv[1])
ktx, png = model / "glTF-KTX-BasisU", model / "glTF"

# Verbatim copies.
shutil.copy(ktx / "StainedGlassLamp_hardware_basecolor.ktx2", here / "hardware_basecolor.ktx2")
shutil.copy(ktx / "StainedGlassLamp_grill_basecolor-alpha.ktx2", here / "grill_basecolor_alpha.ktx2")
shutil.copy(ktx / "StainedGlassLamp_steel_occlusion-rough-metal.ktx2", here / "steel_orm.ktx2")
shutil.copy(png / "StainedGlassLamp_steel_occlusion-rough-metal.png", here / "steel_orm.png")

# The base colours' PNGs are 2048² and their KTX2 images 1024² (grill) and 512² (hardware): the
# references are the PNGs averaged over 16×16 blocks (128², in the stored sRGB values), which the
# test compares with the KTX2 images averaged to the same size.
for name, mode in [("hardware_basecolor", "RGB"), ("grill_basecolor-alpha", "RGBA")]:
    src = Image.open(png / f"StainedGlassLamp_{name}.png")
    assert src.size == (2048, 2048) and src.mode == mode, (src.size, src.mode)
    src.reduce(16).save(here / f"{name.replace('-', '_')}_128.png", optimize=True)


def one_level(data: bytes, level: int) -> bytes:
    """A KTX2 holding only mip `level` of UASTC file `data`, without supercompression."""
    vk, ts, w, h, d, layers, faces, levels, scheme = struct.unpack_from("<9I", data, 12)
    assert vk == 0 and scheme == 2 and layers == 0 and faces == 1
    dfd_off, dfd_len = struct.unpack_from("<2I", data, 48)
    off, length, unpacked = struct.unpack_from("<3Q", data, 80 + 24 * level)
    payload = zstandard.ZstdDecompressor().decompress(data[off : off + length], max_output_size=unpacked)
    assert len(payload) == unpacked
    dfd = data[dfd_off : dfd_off + dfd_len]
    dfd_at = 80 + 24
    level_at = (dfd_at + len(dfd) + 15) // 16 * 16
    head = bytearray(data[:12])
    head += struct.pack("<9I", 0, 1, max(w >> level, 1), max(h >> level, 1), 0, 0, 1, 1, 0)
    head += struct.pack("<4I2Q", dfd_at, len(dfd), 0, 0, 0, 0)
    head += struct.pack("<3Q", level_at, len(payload), len(payload))
    head += dfd
    head += b"\0" * (level_at - len(head))
    return bytes(head) + payload


steel = (here / "steel_orm.ktx2").read_bytes()
(here / "steel_orm_raw.ktx2").write_bytes(one_level(steel, 0))
(here / "steel_orm_8x8.ktx2").write_bytes(one_level(steel, 5))


def seed_glb(ktx2: bytes) -> bytes:
    """The fuzz corpus's KTX2 seed: a textured triangle whose image, in the GLB's binary chunk, is
    the 8×8 UASTC fixture, so that the fuzzer's byte mutations reach the KTX2 header and blocks."""
    import json

    geometry = struct.pack("<15f", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1)
    blob = geometry + ktx2
    blob += b"\0" * (-len(blob) % 4)
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_texture_basisu"],
        "extensionsRequired": ["KHR_texture_basisu"],
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1}}}
        ],
        "textures": [
            {"extensions": {"KHR_texture_basisu": {"source": 0}}},
            {"source": 1, "extensions": {"KHR_texture_basisu": {"source": 0}}},
        ],
        "images": [{"bufferView": 2, "mimeType": "image/ktx2"}, {"bufferView": 2, "mimeType": "image/ktx2"}],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": [
            {"buffer": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 24},
            {"buffer": 0, "byteOffset": 60, "byteLength": len(ktx2)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
        ],
    }
    j = json.dumps(doc, separators=(",", ":")).encode()
    j += b" " * (-len(j) % 4)
    total = 12 + 8 + len(j) + 8 + len(blob)
    return (
        b"glTF" + struct.pack("<II", 2, total) + struct.pack("<I", len(j)) + b"JSON" + j
        + struct.pack("<I", len(blob)) + b"BIN\0" + blob
    )


(here / "../../../../fuzz/corpus/gltf/ktx2-basisu.glb").write_bytes(seed_glb((here / "steel_orm_8x8.ktx2").read_bytes()))
