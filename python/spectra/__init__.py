"""spectra from Python: the real-time spectral renderer, the CPU spectral path tracer and the
CLI's ΔE2000 / MAE statistics, on numpy arrays.

>>> import spectra
>>> scene = spectra.load("cornell")
>>> img = spectra.Renderer(scene, size=(64, 48)).render(mode="spectral")   # (48, 64, 3) float32
>>> ref = spectra.truth(scene, spp=64, size=(64, 48), direct_only=True)
>>> spectra.diff(ref, img)["delta_e2000"]["mean"]

See docs/python.md.
"""

import functools

from ._spectra import (
    BUILTINS,
    ILLUMINANTS,
    OBSERVERS,
    Renderer,
    Scene,
    __version__,
    chart,
    diff,
    illuminant,
    load,
    observer,
    read_image,
    truth,
    upsample,
    write_image,
)

__all__ = [
    "BUILTINS",
    "ILLUMINANTS",
    "OBSERVERS",
    "Renderer",
    "Scene",
    "__version__",
    "chart",
    "diff",
    "illuminant",
    "load",
    "observer",
    "read_image",
    "truth",
    "upsample",
    "write_image",
]


@functools.lru_cache(maxsize=8)
def _load_cached(
    path_or_builtin,
    allow_outside_scene_dir=False,
    env=None,
    env_intensity=None,
    env_rotation=None,
    env_sun=True,
    env_sun_share=None,
    variant=None,
    animation=None,
    time=None,
):
    """`load`, kept per process: what an unpickled `Scene` is (a Ray worker loads a scene
    once, however many tasks it runs with it)."""
    return load(
        path_or_builtin,
        allow_outside_scene_dir,
        env,
        env_intensity,
        env_rotation,
        env_sun,
        env_sun_share,
        variant,
        animation,
        time,
    )
