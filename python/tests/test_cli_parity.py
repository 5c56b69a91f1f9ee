"""Parity of the Python API with the command line: every `spectra truth` / `spectra render`
option that changes the image has a keyword of `spectra.truth` / `Renderer` / `Renderer.render`
that gives the CLI's image with the corresponding flag, bit for bit, and refuses bad values
naming the argument.

The CLI is the binary of test_spectra.py (`$SPECTRA_BIN`, else the workspace's debug build)."""

import os
import subprocess

import numpy as np
import pytest

import spectra
from test_spectra import read_exr, spectra_bin

SIZE = (24, 18)
FOG = (
    '{"sigma_a": 0.05, "sigma_s": {"wavelengths": [380, 550, 730], "values": [0.4, 0.2, 0.1]}, '
    '"phase": {"hg": 0.5}}'
)


def _env(tmp_path):
    return {**os.environ, "XDG_RUNTIME_DIR": os.environ.get("XDG_RUNTIME_DIR", str(tmp_path))}


def _same(a, b):
    assert a.shape == b.shape, (a.shape, b.shape)
    assert np.array_equal(a.view(np.uint32), b.view(np.uint32)), np.abs(a - b).max()


@pytest.fixture(scope="module")
def cli():
    return spectra_bin()


@pytest.fixture(scope="module")
def table8(cli, tmp_path_factory):
    """A coarse sRGB coefficient table (8³, unrefined): another table than the default, so
    that an image made with it differs."""
    path = tmp_path_factory.mktemp("table") / "srgb8.coeff"
    subprocess.run(
        [cli, "lut", "--res", "8", "--no-refine", "--check", "0", "--out", str(path)],
        check=True,
        capture_output=True,
    )
    return path


def _cli_truth(cli, tmp_path, scene, *flags, spp=2):
    out = tmp_path / "t.exr"
    if out.exists():
        out.unlink()
    subprocess.run(
        [cli, "truth", scene, "--size", f"{SIZE[0]}x{SIZE[1]}", "--spp", str(spp), *flags, "--out", str(out)],
        check=True,
        env=_env(tmp_path),
        capture_output=True,
    )
    return read_exr(out)


def _cli_render(cli, tmp_path, scene, *flags, size=SIZE):
    out = tmp_path / "r.exr"
    if out.exists():
        out.unlink()
    subprocess.run(
        [cli, "render", scene, "--size", f"{size[0]}x{size[1]}", *flags, "--out", str(out)],
        check=True,
        env=_env(tmp_path),
        capture_output=True,
    )
    return read_exr(out)


def test_truth_medium_equals_the_cli(cli, tmp_path):
    """`medium=` inline JSON or a file (str or Path) is `--medium`; the image changes."""
    s = spectra.load("cornell")
    plain = spectra.truth(s, spp=2, size=SIZE)
    f = tmp_path / "fog.json"
    f.write_text(FOG)
    want = _cli_truth(cli, tmp_path, "cornell", "--medium", FOG)
    _same(want, _cli_truth(cli, tmp_path, "cornell", "--medium", str(f)))
    for m in (FOG, str(f), f):
        _same(want, spectra.truth(s, spp=2, size=SIZE, medium=m))
    assert not np.array_equal(want, plain)


def test_truth_lambert_equals_the_cli(cli, tmp_path):
    s = spectra.load("cornell")
    want = _cli_truth(cli, tmp_path, "cornell", "--lambert")
    got = spectra.truth(s, spp=2, size=SIZE, lambert=True)
    _same(want, got)
    assert not np.array_equal(got, spectra.truth(s, spp=2, size=SIZE))


def test_truth_xyz_equals_the_cli(cli, tmp_path):
    """`xyz=True` is `--xyz`: the tracer's XYZ, with a CIE observer and with a camera."""
    s = spectra.load("cornell")
    for extra in ([], ["--observer", "canon_eos_r5"]):
        want = _cli_truth(cli, tmp_path, "cornell", "--xyz", *extra)
        kw = dict(observer="canon_eos_r5") if extra else {}
        got = spectra.truth(s, spp=2, size=SIZE, xyz=True, **kw)
        _same(want, got)
        assert not np.array_equal(got, spectra.truth(s, spp=2, size=SIZE, **kw))
    # With a crop, and with bins (which the image's colour space does not change).
    full = spectra.truth(s, spp=2, size=SIZE, xyz=True)
    img, bands, _ = spectra.truth(s, spp=2, size=SIZE, xyz=True, crop=(2, 3, 8, 6), spectral_bin=50)
    _same(full[3:9, 2:10], img)
    _, bands_srgb, _ = spectra.truth(s, spp=2, size=SIZE, crop=(2, 3, 8, 6), spectral_bin=50)
    assert np.array_equal(bands, bands_srgb)


def test_truth_table_equals_the_cli(cli, tmp_path, table8):
    # A scene with RGB colours (cornell's are spectra, which no table touches).
    s = spectra.load("iridescence")
    want = _cli_truth(cli, tmp_path, "iridescence", "--table", str(table8))
    for t in (table8, str(table8)):
        _same(want, spectra.truth(s, spp=2, size=SIZE, table=t))
    assert not np.array_equal(want, spectra.truth(s, spp=2, size=SIZE))


def test_truth_options_together_equal_the_cli(cli, tmp_path, table8):
    s = spectra.load("cornell")
    want = _cli_truth(
        cli, tmp_path, "cornell", "--medium", FOG, "--lambert", "--xyz", "--table", str(table8), "--direct-only"
    )
    got = spectra.truth(s, spp=2, size=SIZE, medium=FOG, lambert=True, xyz=True, table=table8, direct_only=True)
    _same(want, got)


def test_truth_bad_values_name_the_argument(tmp_path):
    s = spectra.load("cornell")
    kw = dict(spp=1, size=(8, 6))
    for call, name in [
        (lambda: spectra.truth(s, medium=3, **kw), "medium"),
        (lambda: spectra.truth(s, lambert="yes", **kw), "lambert"),
        (lambda: spectra.truth(s, xyz=1, **kw), "xyz"),
        (lambda: spectra.truth(s, table=3, **kw), "table"),
    ]:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value).startswith(f"{name}: "), str(e.value)
    # The CLI's messages (`--medium: …`).
    with pytest.raises(ValueError, match="medium.*sigma_a is -1"):
        spectra.truth(s, medium='{"sigma_a": -1, "sigma_s": 0}', **kw)
    with pytest.raises(ValueError, match="medium.*sigma_s"):
        spectra.truth(s, medium='{"sigma_a": 0.1}', **kw)
    with pytest.raises(ValueError, match='medium.*unknown key "fog"'):
        spectra.truth(s, medium='{"sigma_a": 0.1, "sigma_s": 0, "fog": 1}', **kw)
    with pytest.raises(ValueError, match="medium.*phase.hg"):
        spectra.truth(s, medium='{"sigma_a": 0.1, "sigma_s": 0.1, "phase": {"hg": 2}}', **kw)
    with pytest.raises(FileNotFoundError, match="no-such-medium.json"):
        spectra.truth(s, medium=str(tmp_path / "no-such-medium.json"), **kw)
    with pytest.raises(ValueError, match="^medium cannot be used with rgb_medium"):
        spectra.truth(s, medium=FOG, rgb_medium='{"absorption": [0.1, 0.1, 0.1]}', **kw)
    with pytest.raises(ValueError, match="cannot be combined"):
        spectra.truth(spectra.load("underwater"), medium=FOG, **kw)
    with pytest.raises(FileNotFoundError, match="table.*no-such.coeff"):
        spectra.truth(s, table=tmp_path / "no-such.coeff", **kw)
    bad = tmp_path / "bad.coeff"
    bad.write_bytes(b"not a table")
    with pytest.raises(ValueError, match="table.*bad.coeff"):
        spectra.truth(s, table=bad, **kw)


def test_renderer_table_equals_the_cli(cli, tmp_path, table8):
    s = spectra.load("cornell")
    want = _cli_render(cli, tmp_path, "cornell", "--table", str(table8))
    got = spectra.Renderer(s, size=SIZE, table=table8).render()
    _same(want, got)
    assert not np.array_equal(got, spectra.Renderer(s, size=SIZE).render())
    with pytest.raises(FileNotFoundError, match="no-such.coeff"):
        spectra.Renderer(s, size=SIZE, table=tmp_path / "no-such.coeff")
    with pytest.raises(TypeError, match="^table: "):
        spectra.Renderer(s, size=SIZE, table=1)


# (scene, Renderer keywords, `spectra render` flags): each changes the image.
MEDIA = [
    ("underwater", dict(scatter_steps=4, phase_g=0.8, forward_cone=5.0),
     ["--scatter-steps", "4", "--phase-g", "0.8", "--forward-cone", "5"]),
    ("underwater", dict(paper_model=True), ["--paper-model"]),
    ("underwater", dict(isotropic=True, water_surface=True), ["--isotropic", "--water-surface"]),
    ("underwater", dict(tabulated_kd=True, sea_floor=False, water_surface=False),
     ["--tabulated-kd", "--no-sea-floor", "--no-water-surface"]),
    ("underwater", dict(surface_irradiance=False, light_field_photons=500),
     ["--no-surface-irradiance", "--light-field-photons", "500"]),
    ("underwater", dict(scalar_irradiance=True, split_beams=True), ["--scalar-irradiance", "--split-beams"]),
    ("fog", dict(single_scattering=True, scatter_steps=4), ["--single-scattering", "--scatter-steps", "4"]),
]


@pytest.mark.parametrize("scene,kw,flags", MEDIA, ids=[" ".join(f) for _, _, f in MEDIA])
def test_renderer_media_options_equal_the_cli(cli, tmp_path, scene, kw, flags):
    size = (16, 12)
    s = spectra.load(scene)
    want = _cli_render(cli, tmp_path, scene, "--wavelengths", "4", *flags, size=size)
    got = spectra.Renderer(s, size=size, **kw).render(wavelengths=4)
    _same(want, got)
    base = _cli_render(cli, tmp_path, scene, "--wavelengths", "4", size=size)
    assert not np.array_equal(got, base)
    # The CLI's defaults, given explicitly, are the defaults.
    defaults = dict(scatter_steps=16, phase_g=0.924, forward_cone=15.0, light_field_photons=8000,
                    surface_irradiance=True, sea_floor=True, water_surface=None)
    _same(base, spectra.Renderer(s, size=size, **defaults).render(wavelengths=4))


def test_render_frame_options_equal_the_cli(cli, tmp_path):
    """`lambert`, `env_occlusion=False` and `shadows=False` are `--lambert`,
    `--no-env-occlusion` and `--no-shadows`; each changes the image."""
    for scene, env, kw, flags in [
        ("cornell", None, dict(lambert=True), ["--lambert"]),
        ("cornell", None, dict(shadows=False), ["--no-shadows"]),
        ("cornell", "default", dict(env_occlusion=False), ["--no-env-occlusion"]),
        ("cornell", "default", dict(lambert=True, env_occlusion=False, shadows=False),
         ["--lambert", "--no-env-occlusion", "--no-shadows"]),
    ]:
        s = spectra.load(scene, env=env)
        r = spectra.Renderer(s, size=SIZE)
        env_flags = ["--env", env] if env else []
        want = _cli_render(cli, tmp_path, scene, *env_flags, *flags)
        got = r.render(**kw)
        _same(want, got)
        assert not np.array_equal(got, r.render()), kw
    # A frame option holds for its frame only.
    _same(_cli_render(cli, tmp_path, "cornell", "--env", "default"), r.render())


def test_renderer_bad_media_options_name_the_argument():
    s = spectra.load("cornell")
    sea = spectra.load("underwater")
    for call, name in [
        (lambda: spectra.Renderer(s, size=(8, 6), scatter_steps="4"), "scatter_steps"),
        (lambda: spectra.Renderer(s, size=(8, 6), phase_g="0.5"), "phase_g"),
        (lambda: spectra.Renderer(s, size=(8, 6), water_surface=1), "water_surface"),
        (lambda: spectra.Renderer(s, size=(8, 6), sea_floor=None), "sea_floor"),
        (lambda: spectra.Renderer(s, size=(8, 6)).render(shadows=1), "shadows"),
        (lambda: spectra.Renderer(s, size=(8, 6)).render(lambert=None), "lambert"),
        (lambda: spectra.Renderer(s, size=(8, 6)).render(env_occlusion="no"), "env_occlusion"),
    ]:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value).startswith(f"{name}: "), str(e.value)
    for kw, pattern in [
        (dict(scatter_steps=33), "^scatter_steps 33: .*0–32"),
        (dict(scatter_steps=-1), "^scatter_steps -1"),
        (dict(scatter_steps=True), "^scatter_steps True"),
        (dict(phase_g=1.0), "^phase_g 1: "),
        (dict(forward_cone=90.0), "^forward_cone 90: "),
        (dict(light_field_photons=0), "^light_field_photons 0: "),
        (dict(light_field_photons=2**70), "^light_field_photons"),
        (dict(paper_model=True, scatter_steps=8), "paper_model=True.*scatter_steps|scatter_steps.*paper_model=True"),
        (dict(isotropic=True, water_surface=False), "water_surface=False.*isotropic=True|isotropic=True.*water_surface=False"),
        (dict(isotropic=True, surface_irradiance=False), "isotropic=True.*surface_irradiance=False|surface_irradiance=False.*isotropic=True"),
        (dict(isotropic=True, sea_floor=False), "sea_floor=False.*isotropic=True|isotropic=True.*sea_floor=False"),
    ]:
        with pytest.raises(ValueError, match=pattern) as e:
            spectra.Renderer(sea, size=(8, 6), **kw)
        assert "--" not in str(e.value), str(e.value)
