"""spectra from Python: the real-time spectral renderer, the CPU spectral path tracer and the
CLI's ΔE2000 / MAE statistics, on numpy arrays.

>>> import spectra
>>> scene = spectra.load("cornell")
>>> img = spectra.Renderer(scene, size=(64, 48)).render(mode="spectral")   # (48, 64, 3) float32
>>> ref = spectra.truth(scene, spp=64, size=(64, 48), direct_only=True)
>>> spectra.diff(ref, img)["delta_e2000"]["mean"]

See docs/python.md.
"""

from ._spectra import BUILTINS, Renderer, Scene, __version__, diff, load, read_image, truth

__all__ = ["BUILTINS", "Renderer", "Scene", "__version__", "diff", "load", "read_image", "truth"]
