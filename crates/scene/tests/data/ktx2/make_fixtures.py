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
