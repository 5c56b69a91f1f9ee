#!/usr/bin/env python3
"""Conformance run over real glTF assets (the Khronos glTF sample models).

For each model: `spectra render` in rgb and spectral mode, `spectra truth` (direct lighting),
`spectra diff --json` of each render against the truth (per pixel and on BLOCK x BLOCK block
means), and a "black" check of every image (mean Rec. 709 luminance of the linear EXR, read
here with the standard library). Writes OUT/conformance.json and OUT/conformance.md, one row
per model; exits 1 if a listed model fails to load or render, or any of its images is black
(--allow-fail: exit 0 anyway).

    tools/conformance.py --fetch ~/khronos                     # download the default models, then run
    tools/conformance.py ~/khronos --out conformance-out        # run on models already there
    tools/conformance.py PATH/glTF-Sample-Assets/Models --all   # every model found
    tools/conformance.py ~/khronos --set core --size 160x120     # the glTF conformance set (issue 12)
    tools/conformance.py --fetch ~/khronos --set materials --size 160x120 --spp 256   # films, glass (issue 30)
    tools/conformance.py ~/khronos --envs default,rooitou_park,venice_sunset --out conf-envs   # issue 34

With --envs the whole list runs once per environment (OUT/<environment>/) and
OUT/conformance-envs.md tabulates the spectral render's block-mean ΔE2000 over the model per
environment. Every table has the share of the emitted power the real-time lights keep (from
`spectra render`'s line on its emissive area lights; 100 % when they are clustered, less when
emitting materials outnumber the lights, or with a binary from before the clusters).

Per model it also records the loader's `warning:` lines, the first line of any error, whether
the files a .gltf refers to are all there ("incomplete" otherwise: nothing is rendered), and
writes a contact sheet OUT/sheets/<Model>.png: rgb | spectral | truth | the Khronos screenshot
(ROOT/<Model>/screenshot/screenshot.*). The screenshot column needs Pillow; without it the sheet
holds the three renders only (standard library PNG). --resume reuses OUT/<Model>/result.json.

Layout of the model root (as in KhronosGroup/glTF-Sample-Assets `Models/`):
`ROOT/<Model>/glTF-Binary/<Model>.glb` or `ROOT/<Model>/glTF/<Model>.gltf` (the .glb is used
when both exist; --variant glTF picks the other). A root holding a `Models/` folder works too.

Python 3 standard library only (Pillow optional, for the screenshot in the contact sheets).
docs/conformance.md explains the table; docs/gltf-conformance.md has the glTF conformance run.
"""

import argparse
import json
import math
import re
import os
import shlex
import signal
import struct
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.parse
import urllib.request
import zlib

DEFAULT_MODELS = ["DamagedHelmet", "FlightHelmet", "WaterBottle", "Avocado", "BoxTextured", "Duck"]
# glTF conformance (issue 12): the Khronos test assets for the core spec and its extensions, then
# the classic showcase models. `--set core`; `--set issue` is the assets the issue names.
ISSUE_MODELS = [
    "TextureSettingsTest", "AlphaBlendModeTest", "VertexColorTest", "BoxVertexColors", "MultiUVTest",
    "TextureTransformTest", "TextureTransformMultiTest", "SimpleInstancing", "NegativeScaleTest", "OrientationTest",
    "TextureCoordinateTest", "TwoSidedPlane", "MeshPrimitiveModes", "SimpleDolly",
]
CORE_MODELS = ISSUE_MODELS + [
    "Cameras", "TextureLinearInterpolationTest", "TextureEncodingTest", "BoxTexturedNonPowerOfTwo", "BoxInterleaved",
    "Box With Spaces", "NormalTangentTest", "NormalTangentMirrorTest", "MetalRoughSpheresNoTextures", "UnlitTest",
    "EmissiveStrengthTest", "SimpleSparseAccessor", "TriangleWithoutIndices", "Triangle", "SimpleMeshes",
    "MultipleScenes", "Cube", "Suzanne",
    "Box", "BoxTextured", "Duck", "Avocado", "DamagedHelmet", "WaterBottle", "Lantern", "BoomBox", "Fox", "CesiumMan",
    "CesiumMilkTruck", "Sponza", "MetalRoughSpheres", "FlightHelmet", "SciFiHelmet",
]
# Wavelength-dependent materials (issue 30): thin films, transmission, volumes, dispersion.
# `--set materials`; docs/gltf-conformance.md has the verdicts.
MATERIAL_MODELS = [
    "IridescenceSuzanne", "IridescenceDielectricSpheres", "IridescenceMetallicSpheres", "IridescentDishWithOlives",
    "IridescenceLamp", "TransmissionTest", "TransmissionRoughnessTest", "AttenuationTest", "DispersionTest",
    "DragonDispersion",
]
MODEL_SETS = {"default": DEFAULT_MODELS, "issue": ISSUE_MODELS, "core": CORE_MODELS, "materials": MATERIAL_MODELS}
FETCH_BASE = "https://raw.githubusercontent.com/KhronosGroup/glTF-Sample-Assets/main/Models"
REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LUMA = (0.2126, 0.7152, 0.0722)  # linear sRGB / Rec. 709 -> Y


class Interrupted(Exception):
    pass


def log(msg):
    print(msg, file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------------------------
# OpenEXR reading (scan-line images, NONE / RLE / ZIPS / ZIP compression, half/float/uint).
# `spectra` writes ZIP-compressed float scan lines; other compressions are refused by name.

COMPRESSION_NAMES = ["NONE", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB"]
LINES_PER_CHUNK = {0: 1, 1: 1, 2: 1, 3: 16}
SAMPLE_BYTES = {0: 4, 1: 2, 2: 4}  # UINT, HALF, FLOAT
SAMPLE_FORMAT = {0: "I", 1: "e", 2: "f"}


def _undo_predictor_and_interleave(raw):
    # Inverse of OpenEXR's ZIP/RLE preprocessing: delta predictor, then the two halves of the
    # buffer interleaved byte by byte.
    b = bytearray(raw)
    for i in range(1, len(b)):
        b[i] = (b[i - 1] + b[i] - 128) & 0xFF
    half = (len(b) + 1) // 2
    out = bytearray(len(b))
    out[0::2] = b[:half]
    out[1::2] = b[half:]
    return bytes(out)


def _rle_decode(data, expected):
    out = bytearray()
    i = 0
    while i < len(data) and len(out) < expected:
        n = struct.unpack_from("b", data, i)[0]
        i += 1
        if n < 0:
            out += data[i : i - n]
            i -= n
        else:
            out += data[i : i + 1] * (n + 1)
            i += 1
    return bytes(out)


def read_exr(path):
    """Returns (width, height, {channel: list of floats, row-major})."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(f"{path}: not an OpenEXR file")
    flags = struct.unpack_from("<I", data, 4)[0]
    if flags & 0x200 or flags & 0x1000 or flags & 0x800:
        raise ValueError(f"{path}: tiled, multi-part or deep EXR is not supported here")
    pos = 8
    channels, compression, window = [], None, None
    while True:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        pos = end + 1
        if not name:
            break
        end = data.index(b"\0", pos)
        pos = end + 1
        size = struct.unpack_from("<i", data, pos)[0]
        pos += 4
        value = data[pos : pos + size]
        pos += size
        if name == "channels":
            p = 0
            while value[p] != 0:
                e = value.index(b"\0", p)
                cname = value[p:e].decode()
                ptype, _, xs, ys = struct.unpack_from("<iB3xii", value, e + 1)
                channels.append((cname, ptype, xs, ys))
                p = e + 1 + 16
        elif name == "compression":
            compression = value[0]
        elif name == "dataWindow":
            window = struct.unpack("<iiii", value)
    if window is None or compression is None or not channels:
        raise ValueError(f"{path}: EXR header lacks channels, compression or dataWindow")
    if compression not in LINES_PER_CHUNK:
        cname = COMPRESSION_NAMES[compression] if compression < len(COMPRESSION_NAMES) else compression
        raise ValueError(f"{path}: EXR compression {cname} is not supported by this reader")
    if any(xs != 1 or ys != 1 for _, _, xs, ys in channels):
        raise ValueError(f"{path}: subsampled EXR channels are not supported")
    channels.sort(key=lambda c: c[0])  # file order is alphabetical
    x0, y0, x1, y1 = window
    w, h = x1 - x0 + 1, y1 - y0 + 1
    lines = LINES_PER_CHUNK[compression]
    nchunks = (h + lines - 1) // lines
    offsets = struct.unpack_from(f"<{nchunks}Q", data, pos)
    out = {c[0]: [0.0] * (w * h) for c in channels}
    row_bytes = sum(SAMPLE_BYTES[c[1]] for c in channels) * w
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        chunk = data[off + 8 : off + 8 + size]
        nlines = min(lines, y1 + 1 - y)
        expected = row_bytes * nlines
        if size < expected:
            if compression in (2, 3):
                chunk = _undo_predictor_and_interleave(zlib.decompress(chunk))
            elif compression == 1:
                chunk = _undo_predictor_and_interleave(_rle_decode(chunk, expected))
        if len(chunk) != expected:
            raise ValueError(f"{path}: scan-line chunk at y={y} has {len(chunk)} bytes, expected {expected}")
        p = 0
        for ly in range(nlines):
            row = (y - y0 + ly) * w
            for cname, ptype, _, _ in channels:
                n = SAMPLE_BYTES[ptype] * w
                out[cname][row : row + w] = struct.unpack_from(f"<{w}{SAMPLE_FORMAT[ptype]}", chunk, p)
                p += n
    return w, h, out


def luminance(ch, i):
    return LUMA[0] * ch["R"][i] + LUMA[1] * ch["G"][i] + LUMA[2] * ch["B"][i]


def image_stats(w, h, ch, lit_threshold, mask=None):
    """Mean/max luminance and the fraction of pixels brighter than lit_threshold, over the
    pixels where mask is True (all when mask is None)."""
    total, peak, lit, bad, n = 0.0, 0.0, 0, 0, 0
    for i in range(w * h):
        if mask is not None and not mask[i]:
            continue
        y = luminance(ch, i)
        if not math.isfinite(y):
            bad += 1
            continue
        n += 1
        total += y
        peak = max(peak, y)
        if y > lit_threshold:
            lit += 1
    return {
        "pixels": n,
        "mean_luminance": total / n if n else 0.0,
        "max_luminance": peak,
        "lit_fraction": lit / n if n else 0.0,
        "non_finite_pixels": bad,
    }


def model_delta_e(csv_path, mask, width, block):
    """Mean ΔE2000 over the model: from `spectra diff --per-pixel-out` (one row per pixel, or per
    block with --block), keeping the pixels, or blocks at least half covered, of the model."""
    total, n = 0.0, 0
    with open(csv_path) as f:
        next(f)
        for line in f:
            x, y, de = line.split(",")[:3]
            x, y = int(x), int(y)
            inside = 0
            for yy in range(y * block, y * block + block):
                row = yy * width
                for xx in range(x * block, x * block + block):
                    inside += mask[row + xx]
            if 2 * inside >= block * block:
                total += float(de)
                n += 1
    return {"model_delta_e2000_mean": total / n if n else None, "model_units": n}


# Below this share of the image the background mask is taken to have missed the model.
MIN_MODEL_COVERAGE = 0.02


def default_background_mask(w, h, ch, k):
    """True where a pixel shows the model, False where it shows the default environment's
    background: its sky (k, k, k), its ground (k/4, k/4, k/4), or the blurred horizon between
    them, which is neutral and constant along a row (the camera has no roll). Computed on the
    noise-free rgb render and applied to all three images."""
    model = [True] * (w * h)
    for y in range(h):
        neutral = []
        for x in range(w):
            i = y * w + x
            r, g, b = ch["R"][i], ch["G"][i], ch["B"][i]
            m = max(r, g, b)
            if m > 0.0 and m - min(r, g, b) <= 1e-3 * m and 0.2475 * k <= m <= 1.005 * k:
                neutral.append((m / k, i))
        neutral.sort()
        # Clusters of values within 0.5 % of their neighbours: the sky, the ground, or a
        # horizon row (slowly varying along the row) when the cluster spans a tenth of the row.
        start = 0
        for j in range(1, len(neutral) + 1):
            if j < len(neutral) and neutral[j][0] - neutral[j - 1][0] <= 0.005 * neutral[j][0]:
                continue
            cluster = neutral[start:j]
            wide = len(cluster) >= 0.1 * w
            for v, i in cluster:
                if wide or abs(v - 0.25) <= 0.0025 or abs(v - 1.0) <= 0.005:
                    model[i] = False
            start = j
    return model


def _srgb8(v):
    v = 0.0 if not (v > 0.0) else min(v, 1.0)
    v = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
    return int(round(v * 255))


def _png_bytes(w, h, rows):
    def chunk(kind, payload):
        return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", zlib.crc32(kind + payload))

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(rows), 6)) + chunk(b"IEND", b"")
    return png


def _srgb_rows(w, h, ch):
    """8-bit sRGB pixel rows (no filter byte) of a linear image, clamped."""
    lut = {}
    out = []
    for y in range(h):
        row = bytearray()
        for x in range(w):
            i = y * w + x
            for c in "RGB":
                v = ch[c][i]
                e = lut.get(v)
                if e is None:
                    e = lut[v] = _srgb8(v)
                row.append(e)
        out.append(row)
    return out


def write_preview(exr_path, png_path, image=None):
    """The EXR as an 8-bit sRGB PNG, clamped like `spectra render --out x.png --tonemap none`."""
    w, h, ch = image or read_exr(exr_path)
    rows = bytearray()
    for r in _srgb_rows(w, h, ch):
        rows.append(0)
        rows += r
    with open(png_path, "wb") as f:
        f.write(_png_bytes(w, h, rows))


SHEET_COLUMNS = ("rgb", "spectral", "truth")


def find_screenshot(root, name):
    d = os.path.join(root, name, "screenshot")
    for ext in ("png", "jpg", "jpeg", "gif"):
        p = os.path.join(d, "screenshot." + ext)
        if os.path.isfile(p):
            return p
    return None


def write_sheet(sheet_path, outdir, images, screenshot, title):
    """Contact sheet: rgb | spectral | truth | Khronos screenshot, with labels (Pillow), or the
    three renders side by side without labels or screenshot (standard library). A render that
    failed is a grey tile. Returns a note on what was written."""
    try:
        from PIL import Image, ImageDraw
    except ImportError:
        Image = None
    sizes = [(w, h) for (w, h, _) in images.values()]
    if not sizes:
        return "no sheet: nothing rendered"
    w, h = sizes[0]
    gap = 4
    if Image is None:
        cols = [_srgb_rows(*images[k]) if k in images and images[k][:2] == (w, h) else None for k in SHEET_COLUMNS]
        W = len(cols) * w + (len(cols) - 1) * gap
        rows = bytearray()
        for y in range(h):
            rows.append(0)
            for j, c in enumerate(cols):
                if j:
                    rows += b"\xff" * (3 * gap)
                rows += c[y] if c is not None else b"\x40" * (3 * w)
        with open(sheet_path, "wb") as f:
            f.write(_png_bytes(W, h, rows))
        return "sheet without screenshot (no Pillow)"
    tiles = []
    for k in SHEET_COLUMNS:
        png = os.path.join(outdir, k + ".png")
        if k in images and os.path.isfile(png):
            tiles.append((k, Image.open(png).convert("RGB")))
        else:
            tiles.append((k + " (failed)", Image.new("RGB", (w, h), (64, 64, 64))))
    if screenshot:
        try:
            im = Image.open(screenshot)
            im.seek(0)
            im = im.convert("RGB")
            sw = max(1, round(im.width * h / im.height))
            tiles.append(("Khronos screenshot", im.resize((sw, h), Image.LANCZOS)))
        except (OSError, ValueError) as e:
            tiles.append((f"screenshot unreadable: {e}"[:40], Image.new("RGB", (w, h), (64, 64, 64))))
    label_h = 14
    W = sum(t.width for _, t in tiles) + gap * (len(tiles) - 1)
    sheet = Image.new("RGB", (W, h + 2 * label_h), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    draw.text((2, 1), title, fill=(0, 0, 0))
    x = 0
    for label, t in tiles:
        draw.text((x + 2, label_h + 1), label, fill=(0, 0, 0))
        sheet.paste(t, (x, 2 * label_h))
        x += t.width + gap
    sheet.save(sheet_path)
    return "sheet" + (" with screenshot" if screenshot else " (no Khronos screenshot)")


def missing_files(path):
    """Files a .gltf refers to (buffers, images) that are not there."""
    if not path.lower().endswith(".gltf"):
        return []
    try:
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
    except (OSError, ValueError):
        return []  # the loader reports it
    out = []
    for x in doc.get("buffers", []) + doc.get("images", []):
        u = x.get("uri") if isinstance(x, dict) else None
        if u and not u.startswith("data:"):
            rel = urllib.parse.unquote(u)
            if not os.path.isfile(os.path.join(os.path.dirname(path), rel)):
                out.append(rel)
    return out


# ---------------------------------------------------------------------------------------------
# Running spectra


class Runner:
    def __init__(self, spectra, timeout):
        self.spectra = spectra
        self.timeout = timeout
        self.env = dict(os.environ)
        if not self.env.get("XDG_RUNTIME_DIR"):
            # The software Vulkan driver complains without one; a private directory is enough.
            self.env["XDG_RUNTIME_DIR"] = tempfile.mkdtemp(prefix="spectra-xdg-")
            os.chmod(self.env["XDG_RUNTIME_DIR"], 0o700)
        self.proc = None

    def run(self, args):
        """Runs `spectra ARGS`; returns (exit code, stdout, stderr, seconds)."""
        cmd = [self.spectra, *args]
        t0 = time.monotonic()
        # Own process group: Ctrl-C reaches this script, which then stops the child itself.
        self.proc = subprocess.Popen(
            cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=self.env, start_new_session=True
        )
        try:
            out, err = self.proc.communicate(timeout=self.timeout)
            code = self.proc.returncode
        except subprocess.TimeoutExpired:
            self.stop()
            out, err = self.proc.communicate()
            code = None
            err = (err or "") + f"\ntimed out after {self.timeout} s"
        except KeyboardInterrupt:
            self.stop()
            raise Interrupted() from None
        finally:
            self.proc = None if self.proc is None or self.proc.poll() is not None else self.proc
        return code, out, err, time.monotonic() - t0

    def stop(self):
        p = self.proc
        if p is None or p.poll() is not None:
            return
        try:
            os.killpg(p.pid, signal.SIGTERM)
            p.wait(timeout=5)
        except (ProcessLookupError, subprocess.TimeoutExpired):
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            p.wait()


def error_message(stderr, code):
    """The most useful line of a failed command's stderr (anyhow prints 'Error: ...')."""
    lines = [ln.strip() for ln in (stderr or "").splitlines() if ln.strip()]
    for i, ln in enumerate(lines):
        if ln.startswith("Error:") or ln.startswith("error:"):
            rest = [x for x in lines[i + 1 :] if x not in ("Caused by:",)]
            return " ".join([ln.split(":", 1)[1].strip()] + rest)[:600]
    tail = " ".join(lines[-3:])[:600]
    return tail or f"exit code {code}"


def first_error_line(stderr, code):
    """The first line of the error as spectra prints it ('Error: ...' without the prefix)."""
    for ln in (stderr or "").splitlines():
        ln = ln.strip()
        if ln.startswith(("Error:", "error:")):
            return ln.split(":", 1)[1].strip()[:300]
    lines = [ln.strip() for ln in (stderr or "").splitlines() if ln.strip()]
    return lines[-1][:300] if lines else f"exit code {code}"


def warnings_of(stderr, path=None):
    """The loader's `warning: <scene>: <text>` lines, without the prefix and the scene's path."""
    out = []
    for ln in (stderr or "").splitlines():
        ln = ln.strip()
        if ln.lower().startswith("warning:"):
            ln = ln.split(":", 1)[1].strip()
            if path and ln.startswith(path + ":"):
                ln = ln[len(path) + 1 :].strip()
            if ln not in out:
                out.append(ln)
    return out


def notes_of(stderr):
    return [ln.strip() for ln in (stderr or "").splitlines() if ln.strip().lower().startswith(("note", "warning"))]


def find_model(root, name, variant):
    cands = {
        "glTF-Binary": os.path.join(root, name, "glTF-Binary", name + ".glb"),
        "glTF": os.path.join(root, name, "glTF", name + ".gltf"),
    }
    order = ["glTF-Binary", "glTF"] if variant == "glTF-Binary" else ["glTF", "glTF-Binary"]
    for v in order:
        if os.path.isfile(cands[v]):
            return cands[v]
    return None


def list_models(root):
    names = []
    for d in sorted(os.listdir(root)):
        if find_model(root, d, "glTF-Binary"):
            names.append(d)
    return names


def emitters_of(stderr):
    """What `spectra render` said of the emissive surfaces: {"lights", "polygons", "kept"} (kept: the
    share of the emitted power the real-time lights carry), or None when it lit with none."""
    text = stderr or ""
    m = re.search(r"(\d+) emissive area lights: (\d+) emitting polygons clustered, all of their power", text)
    if m:
        return {"lights": int(m[1]), "polygons": int(m[2]), "kept": 1.0}
    m = re.search(r"(\d+) emissive area lights for (\d+) emitting polygons \(warning: ([\d.]+) % of the emitted", text)
    if m:
        return {"lights": int(m[1]), "polygons": int(m[2]), "kept": 1.0 - float(m[3]) / 100.0}
    # Binaries before the clusters (session 18) kept the brightest polygons and dropped the rest.
    m = re.search(r"(\d+) emissive polygon lights \(warning: (\d+) more left out, ([\d.]+) % of the emitted", text)
    if m:
        return {"lights": int(m[1]), "polygons": int(m[1]) + int(m[2]), "kept": 1.0 - float(m[3]) / 100.0}
    m = re.search(r"(\d+) emissive polygon light", text)
    if m:
        return {"lights": int(m[1]), "polygons": int(m[1]), "kept": 1.0}
    return None


# Short names for --envs (the HDRs in assets/environments/).
ENV_ALIASES = {
    "rooitou_park": os.path.join(REPO_ROOT, "assets", "environments", "rooitou_park.hdr"),
    "venice_sunset": os.path.join(REPO_ROOT, "assets", "environments", "venice_sunset.hdr"),
    "studio_small_03": os.path.join(REPO_ROOT, "assets", "environments", "studio_small_03.hdr"),
}


def env_args(a):
    args = []
    if a.env != "auto":
        args += ["--env", a.env]
    if a.env_intensity is not None:
        args += ["--env-intensity", str(a.env_intensity)]
    if a.env_rotation is not None:
        args += ["--env-rotation", str(a.env_rotation)]
    return args


def run_model(a, runner, name, path, outdir):
    res = {"model": name, "file": path, "status": "ok", "error": None, "renders": {}, "diffs": {}, "notes": [],
           "warnings": []}
    os.makedirs(outdir, exist_ok=True)
    missing = missing_files(path)
    if missing:
        res["status"] = "incomplete"
        res["error"] = "files missing (not rendered): " + ", ".join(missing)
        res["error_first_line"] = res["error"]
        log(f"    {res['error']}")
        return res
    common = ["--size", a.size, *env_args(a)]
    # The truth's pixels are box-filtered (the mean over each pixel); real time's are too with
    # --samples K, so that the comparison is of lighting, not of point sampling.
    aa = ["--samples", str(a.samples)] if a.samples != 1 else []
    jobs = [
        ("rgb", ["render", path, "--mode", "rgb", *common, *aa, *shlex.split(a.render_args)]),
        ("spectral", ["render", path, "--mode", "spectral", *common, *aa, *shlex.split(a.render_args)]),
        ("truth", ["truth", path, *common, "--spp", str(a.spp), *shlex.split(a.truth_args)]),
    ]
    images = {}
    for key, args in jobs:
        img = os.path.join(outdir, key + ".exr")
        if os.path.exists(img):
            os.remove(img)
        args = [*args, "--out", img]
        log(f"    {key:<9} spectra {' '.join(shlex.quote(x) for x in args)}")
        code, out, err, secs = runner.run(args)
        r = {"command": ["spectra", *args], "exit_code": code, "seconds": round(secs, 2), "notes": notes_of(err)}
        res["renders"][key] = r
        for n in r["notes"]:
            if n not in res["notes"]:
                res["notes"].append(n)
        for wn in warnings_of(err, path):
            if wn not in res["warnings"]:
                res["warnings"].append(wn)
        if key == "spectral":
            res["emitters"] = emitters_of(err)
        if code != 0 or not os.path.isfile(img):
            r["error"] = error_message(err, code)
            r["error_first_line"] = first_error_line(err, code)
            if "error_first_line" not in res:
                res["error_first_line"] = r["error_first_line"]
            log(f"    {key:<9} FAILED ({secs:.1f} s): {r['error']}")
            if res["status"] == "ok":
                res["status"] = "error"
                res["error"] = f"{key}: {r['error']}"
            continue
        try:
            images[key] = read_exr(img)
            write_preview(img, os.path.join(outdir, key + ".png"), images[key])
        except (ValueError, OSError, struct.error, zlib.error) as e:
            r["error"] = f"cannot read the image: {e}"
        log(f"    {key:<9} {secs:6.1f} s")
    # Which pixels show the model: the background of the default environment is known, so it is
    # found on an rgb render under it (no noise); the camera does not depend on the environment,
    # so under any other environment one more rgb render with --env default gives the mask.
    mask, k = None, a.env_intensity if a.env_intensity is not None else 1.0
    default_bg = a.env == "default" or (a.env == "auto" and any("default environment" in n for n in res["notes"]))
    base = images.get("rgb") if default_bg else None
    if not default_bg and images and not a.no_mask:
        k = 1.0
        mask_img = os.path.join(outdir, ".mask.exr")
        args = ["render", path, "--mode", "rgb", "--size", a.size, "--env", "default", *shlex.split(a.render_args),
                "--out", mask_img]
        log(f"    {'mask':<9} spectra {' '.join(shlex.quote(x) for x in args)}")
        code, _, err, _ = runner.run(args)
        if code == 0:
            base = read_exr(mask_img)
            os.remove(mask_img)
        else:
            log(f"    mask      FAILED: {error_message(err, code)}")
    if base is not None:
        mask = default_background_mask(*base, k)
        res["model_coverage"] = sum(mask) / len(mask)
        log(f"    model covers {res['model_coverage']:.1%} of the image")
        if res["model_coverage"] < MIN_MODEL_COVERAGE:
            # A flat-lit grey model can look like the sky's horizon band to the mask (neutral
            # and constant along rows): a model it cannot find is judged over the whole image,
            # not called black (Cameras, MultipleScenes and SimpleSparseAccessor were).
            log("    the background mask found too little of the model: judged over the whole image")
            mask = None
    for key, (w, h, ch) in images.items():
        r = res["renders"][key]
        m = mask if mask is not None and len(mask) == w * h else None
        r.update({"width": w, "height": h, "image": image_stats(w, h, ch, a.lit_threshold)})
        if m is not None:
            r["model"] = image_stats(w, h, ch, a.lit_threshold, m)
        st = r.get("model", r["image"])
        r["black"] = st["pixels"] == 0 or st["mean_luminance"] < a.black_threshold or (
            st["lit_fraction"] < a.min_lit_fraction)
        r["mean_luminance"] = st["mean_luminance"]
        r["black_over"] = "model" if m is not None else "image"
        log(f"    {key:<9} mean Y {st['mean_luminance']:.4g} over the {r['black_over']}, "
            f"{st['lit_fraction']:.1%} lit{'  BLACK' if r['black'] else ''}")
    truth = os.path.join(outdir, "truth.exr")
    keys = ["spectral", "rgb"]
    if a.noise_floor and os.path.isfile(truth) and res["renders"]["truth"].get("exit_code") == 0:
        # The truth's own noise: a second truth with another seed, measured like the renders.
        seed2 = os.path.join(outdir, "truth_seed2.exr")
        if os.path.exists(seed2):
            os.remove(seed2)
        args = [*jobs[2][1], "--seed", "2", "--out", seed2]
        log(f"    {'truth2':<9} spectra {' '.join(shlex.quote(x) for x in args)}")
        code, out, err, secs = runner.run(args)
        res["renders"]["truth_seed2"] = {"command": ["spectra", *args], "exit_code": code, "seconds": round(secs, 2)}
        if code == 0:
            keys.append("truth_seed2")
        else:
            res["renders"]["truth_seed2"]["error"] = error_message(err, code)
    for key in keys:
        img = os.path.join(outdir, key + ".exr")
        if not (os.path.isfile(truth) and os.path.isfile(img)) or res["renders"][key].get("exit_code") != 0:
            continue
        d = {}
        for block in sorted({1, a.block}):
            args = ["diff", truth, img, "--json", "--block", str(block)]
            if block == a.block:
                args += ["--heatmap", os.path.join(outdir, f"de_{key}_block{block}.png")]
            csv_path = os.path.join(outdir, f".de_{key}_block{block}.csv")
            if mask is not None:
                args += ["--per-pixel-out", csv_path]
            code, out, err, _ = runner.run(args)
            if code != 0:
                d[f"block{block}"] = {"error": error_message(err, code)}
                continue
            j = json.loads(out)
            d[f"block{block}"] = {
                "delta_e2000_mean": j["delta_e2000"]["mean"],
                "delta_e2000_p95": j["delta_e2000"]["p95"],
                "mae_linear_mean": j["mae_linear"]["mean"],
            }
            if mask is not None and os.path.isfile(csv_path):
                d[f"block{block}"].update(model_delta_e(csv_path, mask, images["truth"][0], block))
                os.remove(csv_path)
        res["diffs"][f"{key}_vs_truth"] = d
        be = d.get(f"block{a.block}", {})
        if be.get("delta_e2000_mean") is not None:
            log(f"    ΔE00 {key} vs truth, {a.block}x{a.block} block mean: {be['delta_e2000_mean']:.3f} over the image"
                + (f", {be['model_delta_e2000_mean']:.3f} over the model's {be['model_units']} blocks"
                   if be.get("model_delta_e2000_mean") is not None else ""))
    if not a.no_sheets:
        sheets = os.path.join(a.out, "sheets")
        os.makedirs(sheets, exist_ok=True)
        shot = find_screenshot(a.root_models, name)
        sheet = os.path.join(sheets, name.replace(os.sep, "_") + ".png")
        try:
            what = write_sheet(sheet, outdir, images, shot, f"{name}  ({a.size}, truth {a.spp} spp)")
            if os.path.isfile(sheet):
                res["sheet"] = os.path.relpath(sheet, a.out)
            res["screenshot"] = shot
            log(f"    {what}: {sheet}")
        except Exception as e:  # a sheet is a convenience: never fail the run over it
            log(f"    sheet failed: {e}")
    return res


# ---------------------------------------------------------------------------------------------
# Report


def fmt(v, prec=2):
    return "–" if v is None else f"{v:.{prec}f}"


def fmtg(v):
    return "–" if v is None else f"{v:.3g}"


def black_cell(r):
    if r is None or r.get("exit_code") != 0:
        return "–"
    b = r.get("black")
    return "?" if b is None else ("**yes**" if b else "no")


def power_cell(r):
    e = r.get("emitters")
    if not e:
        return "–"
    return f"{100 * e['kept']:.1f} % ({e['lights']} / {e['polygons']})"


def model_de(r, block):
    """Block-mean ΔE2000 spectral vs truth over the model (over the image without a mask)."""
    d = r.get("diffs", {}).get("spectral_vs_truth", {}).get(f"block{block}", {})
    v = d.get("model_delta_e2000_mean")
    return v if v is not None else d.get("delta_e2000_mean")


def write_env_summary(out, block, runs, command):
    """OUT/conformance-envs.md: per model and environment, spectral vs truth block-mean ΔE2000 over
    the model and the emitted power kept."""
    labels = [label for label, _ in runs]
    models = []
    for _, results in runs:
        for r in results:
            if r["model"] not in models:
                models.append(r["model"])
    lines = [
        "# Conformance under several environments",
        "",
        f"`{command}`",
        "",
        f"Spectral real time vs truth, {block}×{block} block-mean ΔE2000 over the model (over the image when no"
        " mask could be made); emitted power kept by the real-time lights. Each environment's full table:"
        " OUT/<environment>/conformance.md.",
        "",
        "| model | " + " | ".join(labels) + " | emitted power kept |",
        "|---|" + "---|" * len(labels) + "---|",
    ]
    for m in models:
        cells, power = [], "–"
        for _, results in runs:
            r = next((x for x in results if x["model"] == m), None)
            cells.append("–" if r is None else fmt(model_de(r, block)))
            if r is not None and r.get("emitters"):
                power = power_cell(r)
        lines.append(f"| {m} | " + " | ".join(cells) + f" | {power} |")
    lines.append("")
    os.makedirs(out, exist_ok=True)
    tmp = os.path.join(out, "conformance-envs.md.tmp")
    with open(tmp, "w") as f:
        f.write("\n".join(lines))
    os.replace(tmp, os.path.join(out, "conformance-envs.md"))


def write_reports(a, results, meta):
    os.makedirs(a.out, exist_ok=True)
    doc = {**meta, "models": results}
    tmp = os.path.join(a.out, "conformance.json.tmp")
    with open(tmp, "w") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")
    os.replace(tmp, os.path.join(a.out, "conformance.json"))

    blk = f"block{a.block}"
    lines = [
        "# Conformance: Khronos glTF sample models",
        "",
        f"`{meta['command']}`",
        "",
        f"{meta['size']} px, environment `{a.env}`"
        + (f" × {a.env_intensity}" if a.env_intensity is not None else "")
        + f", real time {a.samples} frame{'s' if a.samples != 1 else ''} per image (`--samples`)"
        + f", truth {a.spp} spp (`{' '.join(meta['truth_flags'])}`); ΔE2000 = mean CIEDE2000 against the truth"
        f" on {a.block}×{a.block} block means (per pixel in brackets), over the whole image and over the model"
        f" (the blocks at least half covered by it; the pixels of it); truth noise = the same block-mean ΔE00"
        f" between the truth and a second truth with --seed 2; black = mean luminance Y < {a.black_threshold}"
        f" or fewer than {a.min_lit_fraction:.0%} of the pixels above Y = {a.lit_threshold}, counted over the"
        f" model's pixels (model px: the share of the image that is not background, found on an rgb render"
        f" under the default environment) unless --no-mask, else over the whole image; mean Y likewise, linear"
        f" (1 = the default sky's radiance); seconds = wall-clock time per command (process start, scene"
        f" load and upload included). Model paths are relative to `{meta['root']}`.",
        "",
        "| model | load | model px | black rgb / spectral / truth | mean Y rgb / spectral / truth |"
        " ΔE00 spectral–truth: image | ΔE00 spectral–truth: model | ΔE00 rgb–truth: image | ΔE00 rgb–truth: model"
        " | truth noise: image / model | emitted power kept (lights / polygons) | seconds rgb / spectral / truth"
        " | warnings |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    def short(text):
        return (text or "").replace(meta["root"] + os.sep, "").replace("|", "\\|")

    for r in results:
        rs = r.get("renders", {})
        if r["status"] != "ok" and not any(x.get("exit_code") == 0 for x in rs.values()):
            err = short(r.get("error"))
            what = "incomplete" if r["status"] == "incomplete" else "error"
            lines.append(f"| {r['model']} | {what}: {err} | – | – | – | – | – | – | – | – | – | – | "
                         f"{len(r.get('warnings', []))} |")
            continue
        load = "ok" if r["status"] == "ok" else "error: " + short(r.get("error"))
        blacks = " / ".join(black_cell(rs.get(k)) for k in ("rgb", "spectral", "truth"))
        means = " / ".join(fmtg(rs.get(k, {}).get("mean_luminance")) for k in ("rgb", "spectral", "truth"))

        def de(key, r=r):
            d = r.get("diffs", {}).get(key, {})
            cells = []
            for field in ("delta_e2000_mean", "model_delta_e2000_mean"):
                b, p = d.get(blk, {}).get(field), d.get("block1", {}).get(field)
                cells.append("–" if b is None else f"{b:.2f} ({fmt(p)})")
            return " | ".join(cells)

        secs = " / ".join(fmt(rs.get(k, {}).get("seconds"), 1) for k in ("rgb", "spectral", "truth"))
        noise = r.get("diffs", {}).get("truth_seed2_vs_truth", {}).get(blk, {})
        noise = " / ".join(fmt(noise.get(f)) for f in ("delta_e2000_mean", "model_delta_e2000_mean"))
        des = f"{de('spectral_vs_truth')} | {de('rgb_vs_truth')} | {noise}"
        cov = r.get("model_coverage")
        cov = "–" if cov is None else f"{cov:.0%}"
        lines.append(f"| {r['model']} | {load} | {cov} | {blacks} | {means} | {des} | {power_cell(r)} | {secs} | "
                     f"{len(r.get('warnings', []))} |")
    lines.append("")
    n_ok = sum(1 for r in results if r["status"] == "ok")
    n_inc = sum(1 for r in results if r["status"] == "incomplete")
    n_black = sum(1 for r in results if r["status"] == "ok" and any(x.get("black") for x in r["renders"].values()))
    lines += [f"{n_ok} of {len(results)} models load and render in all three modes ({n_black} of them with a black"
              f" image); {n_inc} incomplete (files missing, not rendered); "
              f"{len(results) - n_ok - n_inc} fail.", ""]
    warned = [r for r in results if r.get("warnings")]
    if warned:
        lines += ["Loader warnings:", ""]
        for r in warned:
            lines += [f"- {r['model']}: " + "; ".join(short(w) for w in r["warnings"])]
        lines.append("")
    notes = sorted({n for r in results for n in r.get("notes", []) if not n.lower().startswith("warning")})
    if notes:
        lines += ["Notes printed by spectra:", ""] + [f"- {short(n)}" for n in notes] + [""]
    if meta.get("interrupted"):
        lines += ["**Interrupted**: the table holds the models finished before Ctrl-C.", ""]
    lines.append(f"Machine: {meta['machine']}; spectra: `{meta['spectra']}`; {meta['date']}.")
    lines.append("")
    tmp = os.path.join(a.out, "conformance.md.tmp")
    with open(tmp, "w") as f:
        f.write("\n".join(lines))
    os.replace(tmp, os.path.join(a.out, "conformance.md"))


def machine():
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for ln in f:
                if ln.startswith("model name"):
                    cpu = ln.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores"


# ---------------------------------------------------------------------------------------------
# Fetching models from GitHub


def download(url, dest, timeout=60):
    if os.path.isfile(dest) and os.path.getsize(dest) > 0:
        return "present"
    os.makedirs(os.path.dirname(dest), exist_ok=True)
    tmp = dest + ".part"
    try:
        with urllib.request.urlopen(url, timeout=timeout) as r, open(tmp, "wb") as f:
            while True:
                buf = r.read(1 << 16)
                if not buf:
                    break
                f.write(buf)
        head = open(tmp, "rb").read(64)
        if head.startswith(b"version https://git-lfs"):
            raise ValueError(f"{url} is a Git LFS pointer, not the file")
        os.replace(tmp, dest)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    return "downloaded"


def fetch_model(base, name, dest_root, variant):
    """Downloads one model (the .glb, else the .gltf with its buffers and images) and its
    LICENSE.md / README.md. Returns the local path."""
    q = urllib.parse.quote
    mdir = os.path.join(dest_root, name)
    for extra in ("LICENSE.md", "README.md"):
        try:
            download(f"{base}/{q(name)}/{extra}", os.path.join(mdir, extra))
        except urllib.error.HTTPError:
            pass
    if variant == "glTF-Binary":
        glb = os.path.join(mdir, "glTF-Binary", name + ".glb")
        try:
            how = download(f"{base}/{q(name)}/glTF-Binary/{q(name)}.glb", glb)
            log(f"  {name}: glTF-Binary/{name}.glb {how}")
            return glb
        except urllib.error.HTTPError as e:
            if e.code != 404:
                raise
            log(f"  {name}: no .glb, fetching the glTF folder")
    gdir = os.path.join(mdir, "glTF")
    gltf = os.path.join(gdir, name + ".gltf")
    download(f"{base}/{q(name)}/glTF/{q(name)}.gltf", gltf)
    with open(gltf, encoding="utf-8") as f:
        doc = json.load(f)
    uris = [x.get("uri") for x in doc.get("buffers", []) + doc.get("images", [])]
    uris = [u for u in uris if u and not u.startswith("data:")]
    for u in uris:
        rel = urllib.parse.unquote(u)
        if rel.startswith("/") or ".." in rel.split("/"):
            raise ValueError(f"{name}.gltf: refusing the URI {u!r} (outside the model folder)")
        how = download(f"{base}/{q(name)}/glTF/{q(rel)}", os.path.join(gdir, rel))
        log(f"  {name}: glTF/{rel} {how}")
    return gltf


# ---------------------------------------------------------------------------------------------


def _terminate(signum, frame):
    raise KeyboardInterrupt()


def main():
    signal.signal(signal.SIGTERM, _terminate)  # stop as cleanly on kill as on Ctrl-C
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("root", nargs="?",
                    help="folder of models (<root>/<Model>/glTF-Binary/<Model>.glb or glTF/<Model>.gltf)")
    ap.add_argument("--models", help=f"comma-separated model names (default: {','.join(DEFAULT_MODELS)})")
    ap.add_argument("--set", choices=sorted(MODEL_SETS), default=None,
                    help="a named list of models: default (" + ",".join(DEFAULT_MODELS) + "), issue (the glTF test "
                         "assets issue 12 names), core (those, the other core/extension test assets and the classic "
                         "showcase models), materials (the thin-film, transmission, volume and dispersion assets issue 30 "
                         "names); --models overrides")
    ap.add_argument("--all", action="store_true", help="every model found under the root")
    ap.add_argument("--no-sheets", action="store_true", help="do not write the contact sheets OUT/sheets/<Model>.png")
    ap.add_argument("--resume", action="store_true",
                    help="reuse OUT/<Model>/result.json of an earlier run (same --out) instead of rendering again")
    ap.add_argument("--variant", choices=["glTF-Binary", "glTF"], default="glTF-Binary",
                    help="which file to prefer when a model has both (default: glTF-Binary)")
    ap.add_argument("--spectra", default=os.path.join(REPO_ROOT, "target", "release", "spectra"),
                    help="the spectra binary (default: target/release/spectra of this repository)")
    ap.add_argument("--out", default="conformance-out", help="output folder (default: conformance-out)")
    ap.add_argument("--env", default="default",
                    help="environment for every render: default, none, a .hdr/.exr file, or auto (pass no --env: "
                         "the renderers' own choice) (default: default)")
    ap.add_argument("--envs", metavar="LIST",
                    help="run the whole list under each of these environments in turn (comma-separated: default, "
                         "rooitou_park, venice_sunset, studio_small_03 or paths), each into OUT/<name>/, and write "
                         "OUT/conformance-envs.md (per model and environment: spectral vs truth block-mean ΔE2000 "
                         "over the model, emitted power kept); overrides --env")
    ap.add_argument("--env-intensity", type=float)
    ap.add_argument("--env-rotation", type=float, help="passed through to --env-rotation")
    ap.add_argument("--size", default="320x240", help="image size WxH (default: 320x240)")
    ap.add_argument("--spp", type=int, default=64, help="truth samples per pixel (default: 64)")
    ap.add_argument("--truth-args", default="--direct-only",
                    help="extra flags for spectra truth (default: --direct-only)")
    ap.add_argument("--samples", type=int, default=16,
                    help="frames averaged per real-time render (spectra render --samples, 1-256): the truth "
                         "integrates each pixel, so the default 16 antialiases real time to match; 1 = single "
                         "frames at the pixel centres (default: 16)")
    ap.add_argument("--render-args", default="", help="extra flags for both spectra render runs")
    ap.add_argument("--no-mask", action="store_true",
                    help="under an environment other than the default: skip the extra rgb render under the default "
                         "environment that finds the model's pixels (figures are then over the whole image)")
    ap.add_argument("--no-noise-floor", dest="noise_floor", action="store_false",
                    help="skip the second truth (--seed 2) that measures the truth's own noise")
    ap.add_argument("--block", type=int, default=8, help="block size of the block-mean ΔE2000 (default: 8)")
    ap.add_argument("--black-threshold", type=float, default=1e-3,
                    help="an image whose mean luminance is below this is black (default: 1e-3)")
    ap.add_argument("--lit-threshold", type=float, default=1e-2,
                    help="a pixel whose luminance is above this is lit (default: 0.01)")
    ap.add_argument("--min-lit-fraction", type=float, default=0.05,
                    help="an image with fewer lit pixels than this fraction is black too (default: 0.05)")
    ap.add_argument("--timeout", type=float, default=1800, help="seconds allowed per spectra command (default: 1800)")
    ap.add_argument("--allow-fail", action="store_true", help="exit 0 even if a model is black or fails")
    ap.add_argument("--fetch", metavar="DIR", help="download the listed models from GitHub into DIR first "
                    "(files already there are kept), then run on DIR unless a root is given")
    ap.add_argument("--fetch-only", action="store_true", help="with --fetch: download, do not render")
    ap.add_argument("--fetch-base", default=FETCH_BASE, help=f"where --fetch downloads from (default: {FETCH_BASE})")
    a = ap.parse_args()

    if a.models:
        models = [m.strip() for m in a.models.split(",") if m.strip()]
    else:
        models = list(MODEL_SETS[a.set or "default"])
    if a.fetch:
        if a.all:
            ap.error("--fetch downloads a list of models; --all needs them present")
        log(f"fetching {len(models)} models into {a.fetch} from {a.fetch_base}")
        failed = []
        try:
            for m in models:
                try:
                    fetch_model(a.fetch_base.rstrip("/"), m, a.fetch, a.variant)
                except (urllib.error.URLError, OSError, ValueError) as e:
                    log(f"  {m}: download failed: {e}")
                    failed.append(m)
        except KeyboardInterrupt:
            log("interrupted")
            return 130
        if failed:
            log(f"could not download: {', '.join(failed)}")
        if a.fetch_only:
            return 1 if failed else 0
        a.root = a.root or a.fetch
    if not a.root:
        ap.error("give the model folder (or --fetch DIR)")
    root = a.root
    if os.path.isdir(os.path.join(root, "Models")):
        root = os.path.join(root, "Models")
    if not os.path.isdir(root):
        ap.error(f"{root}: not a folder")
    a.root_models = root
    if a.all:
        found = list_models(root)
        # --all with --set/--models: the listed models first, then every other model found
        models = models + [m for m in found if m not in models] if (a.set or a.models) else found
    if not os.path.isfile(a.spectra) or not os.access(a.spectra, os.X_OK):
        ap.error(f"{a.spectra}: no spectra binary there (cargo build --release -p spectra, or --spectra PATH)")
    if a.block < 1:
        ap.error("--block must be at least 1")
    if not 1 <= a.samples <= 256:
        ap.error(f"--samples {a.samples}: frames per real-time render must be 1-256")
    if any(f == "--samples" or f.startswith("--samples=") for f in shlex.split(a.render_args)):
        ap.error("--render-args: give the frames per image as the tool's own --samples K, not inside --render-args")

    meta = {
        "command": "tools/conformance.py " + " ".join(shlex.quote(x) for x in sys.argv[1:]),
        "root": os.path.abspath(root),
        "spectra": a.spectra,
        "size": a.size,
        "env": a.env,
        "env_intensity": a.env_intensity,
        "spp": a.spp,
        "truth_flags": shlex.split(a.truth_args),
        "render_samples": a.samples,
        "render_flags": shlex.split(a.render_args),
        "block": a.block,
        "black_threshold": a.black_threshold,
        "lit_threshold": a.lit_threshold,
        "min_lit_fraction": a.min_lit_fraction,
        "machine": machine(),
        "date": time.strftime("%Y-%m-%d %H:%M %Z"),
        "interrupted": False,
    }
    runner = Runner(a.spectra, a.timeout)
    envs = [("", None)]
    if a.envs:
        envs = []
        for e in (x.strip() for x in a.envs.split(",")):
            if not e:
                continue
            path = ENV_ALIASES.get(e, e)
            if path not in ("default", "none") and not os.path.isfile(path):
                ap.error(f"--envs: {e}: no such environment file (or one of default, {', '.join(ENV_ALIASES)})")
            label = e if e in ENV_ALIASES or e in ("default", "none") else os.path.splitext(os.path.basename(e))[0]
            envs.append((label, path))
    out_root = a.out
    runs = []
    all_results = []
    for label, env in envs:
        if env is not None:
            a.env = env
            a.out = os.path.join(out_root, label)
            meta = {**meta, "env": env}
            log(f"== environment {label}: {env} → {a.out}")
        code, results = run_list(a, runner, models, root, meta)
        runs.append((label, results))
        all_results += results
        if code is not None:
            return code
    if a.envs:
        write_env_summary(out_root, a.block, runs, meta["command"])
        log(f"wrote {os.path.join(out_root, 'conformance-envs.md')}")
    bad = []
    for r in all_results:
        if r["status"] != "ok":
            bad.append(f"{r['model']}: {r.get('error_first_line') or r['error']}")
        for k, x in r.get("renders", {}).items():
            if x.get("black"):
                bad.append(f"{r['model']}: {k} render is black (mean luminance {x['mean_luminance']:.3g})")
    for b in bad:
        log(f"FAIL {b}")
    if bad and not a.allow_fail:
        return 1
    return 0


def run_list(a, runner, models, root, meta):
    """Every model of `models` under `a.env` into `a.out`: (exit code when interrupted, results)."""
    results = []
    t_start = time.monotonic()
    try:
        for i, m in enumerate(models, 1):
            path = find_model(root, m, a.variant)
            log(f"[{i}/{len(models)}] {m}: {path or 'not found'}")
            if path is None:
                results.append({"model": m, "file": None, "status": "error",
                                "error": f"not found under {root} (glTF-Binary/{m}.glb or glTF/{m}.gltf)",
                                "renders": {}, "diffs": {}, "notes": []})
            else:
                saved = os.path.join(a.out, m, "result.json")
                r = None
                if a.resume and os.path.isfile(saved):
                    with open(saved) as f:
                        r = json.load(f)
                    log("    reused " + saved)
                if r is None:
                    r = run_model(a, runner, m, path, os.path.join(a.out, m))
                    with open(saved, "w") as f:
                        json.dump(r, f, indent=2)
                results.append(r)
            write_reports(a, results, meta)
    except (Interrupted, KeyboardInterrupt):
        runner.stop()
        meta["interrupted"] = True
        write_reports(a, results, meta)
        log(f"interrupted: {len(results)} models in {os.path.join(a.out, 'conformance.md')}")
        return 130, results
    meta["seconds"] = round(time.monotonic() - t_start, 1)
    write_reports(a, results, meta)
    log(f"wrote {os.path.join(a.out, 'conformance.md')} and conformance.json ({meta['seconds']} s)")
    return None, results


if __name__ == "__main__":
    sys.exit(main())
