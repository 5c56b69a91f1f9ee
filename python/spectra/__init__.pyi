"""Type stub of the `spectra` package (the extension module spectra._spectra). See docs/python.md."""

import os
from typing import Any, Literal, Optional, Sequence, Tuple, TypedDict, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

#: The built-in scene names `load` accepts.
BUILTINS: list[str]
#: The built-in observer and camera names `observer` and `observer=` accept.
OBSERVERS: list[str]
#: The tabulated illuminant names (`illuminant`, `white=`); "5000K" / "blackbody:5000" too.
ILLUMINANTS: list[str]

RGBImage = npt.NDArray[np.float32]
"""A linear RGB image: float32, shape (height, width, 3), C-contiguous."""
_FloatImage = npt.NDArray[Union[np.float32, np.float64]]
"""An image argument: a numpy float32 or float64 array of shape (height, width, 3)."""
_Bands = npt.NDArray[np.float32]
"""Per-pixel spectral values: float32, shape (height, width, N)."""
_Wavelengths = npt.NDArray[np.float64]
"""Wavelengths in nm (node wavelengths, band edges): float64, 1-D."""
_Path = Union[str, os.PathLike[str]]
"""A file's name: a str or an os.PathLike (pathlib.Path)."""
_Size = Union[Tuple[int, int], Sequence[int]]
"""(width, height): a tuple, a list or a 1-D array of two ints."""
_Range = Union[Tuple[float, float], Sequence[float]]
"""(min_nm, max_nm): a tuple, a list or a 1-D array of two floats."""
_Crop = Union[Tuple[int, int, int, int], Sequence[int]]
"""(x, y, width, height): a tuple, a list or a 1-D array of four ints."""

class Stats(TypedDict):
    mean: float
    median: float
    p95: float
    p99: float
    max: float

class DiffSummary(TypedDict):
    width: int
    height: int
    white_luminance: float
    delta_e2000: Stats
    mae_linear: Stats
    mae_srgb: Stats

class Placement(TypedDict):
    """Where an image's pixels lie in its frame (an EXR's data window in its display window)."""

    frame: Tuple[int, int]
    x: int
    y: int
    width: int
    height: int

class Region(TypedDict):
    """The part of the frame `diff` of two files compared, where it is not simply both images."""

    frame: list[int]
    x: int
    y: int
    width: int
    height: int

class Scene:
    """A loaded scene (from `load`); immutable. Pickles as `load` with the same arguments (a
    file by its absolute path), so it can be a Ray task's argument."""

    @property
    def source(self) -> str:
        """Where it came from: a path, or `builtin:NAME`."""
    @property
    def warnings(self) -> list[str]:
        """What the loader skipped or approximated."""
    @property
    def lights(self) -> int:
        """The number of lights (stand-ins included)."""
    @property
    def animation_end(self) -> Optional[float]:
        """The end of the animation the scene is posed by (its last key, s); None at rest."""

def load(
    path_or_builtin: _Path,
    allow_outside_scene_dir: bool = False,
    env: Optional[_Path] = None,
    env_intensity: Optional[float] = None,
    env_rotation: Optional[float] = None,
    env_sun: bool = True,
    env_sun_share: Optional[float] = None,
    variant: Optional[str] = None,
    animation: Optional[Union[str, int]] = None,
    time: Optional[float] = None,
) -> Scene:
    """Loads a built-in scene by name (cornell, colorchecker, metamerism, iridescence, glass,
    clearcoat, specular, sheen, anisotropy, translucent, underwater, fog, tinted-fog) or a .gltf/.glb file, as `spectra render SCENE` does; a scene
    without lights gets the default environment (rendered with `water=`, by `Renderer` or
    `truth`, a sun overhead instead, as `spectra render FILE --water` lights it).
    `allow_outside_scene_dir`: let the file's references leave its folder. `env`: an equirectangular .hdr/.exr, "default" or "none"
    (`--env`), scaled by `env_intensity`, turned by `env_rotation` degrees about +Y; `env_sun`:
    the map's sun, where it has one, as a shadowed directional light in real time (False:
    `--no-env-sun`); `env_sun_share`: the share of the map's light a compact bright region must
    give to be that sun, in (0, 1] (`--env-sun-share`; default 0.15); `variant`: the file's
    KHR_materials_variants variant to draw, by name (`--variant`); `animation`, `time`: pose
    the file by this animation (a str: its name, else an index as `--animation` reads it; an
    int: its index, whatever the names) at this moment in
    seconds (`--animation`, `--time`; a time alone poses the first animation; default: at rest,
    skins and morph weights applied). Raises ValueError (bad scene, unknown variant or
    animation, a time outside [0, 1e6]), FileNotFoundError."""

class Renderer:
    """The real-time renderer (wgpu; lavapipe without a GPU) for one scene at one size. The GPU
    device, pipelines and scene buffers are kept between `render()` calls."""

    def __init__(
        self,
        scene: Scene,
        size: _Size = (640, 480),
        *,
        water: Optional[str] = None,
        depth: Optional[float] = None,
        rgb_medium: Optional[_Path] = None,
        table: Optional[_Path] = None,
        scatter_steps: int = 16,
        single_scattering: bool = False,
        phase_g: float = 0.924,
        paper_model: bool = False,
        isotropic: bool = False,
        tabulated_kd: bool = False,
        surface_irradiance: bool = True,
        forward_cone: float = 15.0,
        light_field_photons: int = 8000,
        scalar_irradiance: bool = False,
        split_beams: bool = False,
        water_surface: Optional[bool] = None,
        sea_floor: bool = True,
    ) -> None:
        """`water`: a Jerlov type ("IB", …) with the camera `depth` in metres; `rgb_medium`: the
        `--rgb-medium` JSON or a JSON file; by default the scene's own medium. `table`: a
        Jakob–Hanika .coeff table (`--table`; default the cached sRGB fit).
        The media options are `spectra render`'s flags with its defaults: `scatter_steps`
        (0–32), `single_scattering`, `phase_g`, `paper_model`, `isotropic`, `tabulated_kd`,
        `surface_irradiance=False` (`--no-surface-irradiance`), `forward_cone` (0–45°),
        `light_field_photons`, `scalar_irradiance`, `split_beams`, `water_surface` (None: the
        model's default; True `--water-surface`, False `--no-water-surface`), `sea_floor=False`
        (`--no-sea-floor`). Flags the command refuses together are refused together (ValueError
        naming the arguments)."""
    @overload
    def render(
        self,
        mode: str = "spectral",
        *,
        wavelengths: Optional[int] = None,
        quadrature: str = "prefiltered",
        range: Optional[_Range] = None,
        observer: Optional[_Path] = None,
        white: Optional[str] = None,
        exposure: float = 0.0,
        spectral: Literal[False] = False,
        camera_to_display: bool = False,
        samples: int = 1,
        lambert: bool = False,
        env_occlusion: bool = True,
        shadows: bool = True,
    ) -> RGBImage:
        """One frame: the linear RGB HDR image (`spectra render --out x.exr`'s pixels) × 2^exposure.

        mode: "spectral", "naive" or "rgb". wavelengths: 1–256 (default: the scene's, else 16).
        quadrature: "prefiltered" or "midpoint". range: (min_nm, max_nm) (default: the scene's,
        else (380, 730)). observer: "cie1931" (default, unless the scene sets one), "cie1964", a
        camera (`OBSERVERS`) or a file (CSV, rawtoaces JSON); a camera's channels are white
        balanced, or with camera_to_display=True shown through its ColorChecker fit to XYZ and
        sRGB. white: an illuminant name (default: the scene's, else D65).
        spectral=True: the tuple (image, node radiances float32 (H, W, N), node wavelengths
        float64 (N,)), as `--spectral-out` writes them (not in rgb mode).
        samples: antialiasing, the mean of 1–256 frames each looking at another place in every
        pixel (`--samples`): the image box-filtered over each pixel, as the path tracer's are
        (not with spectral=True).
        lambert=True: Lambert only, base colour / π (`--lambert`); env_occlusion=False:
        `--no-env-occlusion`; shadows=False: `--no-shadows`.
        Unknown keywords and badly typed arguments raise TypeError (its message starts with the
        argument's name), bad values ValueError with the CLI's message; the GIL is released while
        rendering, and `size`, `device` and `repr()` never wait for a render on another thread."""
    @overload
    def render(
        self,
        mode: str = "spectral",
        *,
        wavelengths: Optional[int] = None,
        quadrature: str = "prefiltered",
        range: Optional[_Range] = None,
        observer: Optional[_Path] = None,
        white: Optional[str] = None,
        exposure: float = 0.0,
        spectral: Literal[True],
        camera_to_display: bool = False,
        samples: int = 1,
        lambert: bool = False,
        env_occlusion: bool = True,
        shadows: bool = True,
    ) -> Tuple[RGBImage, _Bands, _Wavelengths]: ...
    @overload
    def render(
        self,
        mode: str = "spectral",
        *,
        wavelengths: Optional[int] = None,
        quadrature: str = "prefiltered",
        range: Optional[_Range] = None,
        observer: Optional[_Path] = None,
        white: Optional[str] = None,
        exposure: float = 0.0,
        spectral: bool = False,
        camera_to_display: bool = False,
        samples: int = 1,
        lambert: bool = False,
        env_occlusion: bool = True,
        shadows: bool = True,
    ) -> Union[RGBImage, Tuple[RGBImage, _Bands, _Wavelengths]]: ...
    @property
    def scene(self) -> Scene: ...
    @property
    def size(self) -> Tuple[int, int]:
        """(width, height)."""
    @property
    def device(self) -> str:
        """The GPU adapter and backend."""

@overload
def truth(
    scene: Scene,
    spp: int = 64,
    size: _Size = (256, 256),
    direct_only: bool = False,
    seed: int = 0,
    *,
    sample_offset: int = 0,
    crop: Optional[_Crop] = None,
    range: Optional[_Range] = None,
    observer: Optional[_Path] = None,
    white: Optional[str] = None,
    max_depth: int = 1024,
    water: Optional[str] = None,
    depth: Optional[float] = None,
    rgb_medium: Optional[_Path] = None,
    spectral_bin: None = None,
    camera_to_display: bool = False,
    medium: Optional[_Path] = None,
    lambert: bool = False,
    xyz: bool = False,
    table: Optional[_Path] = None,
) -> RGBImage:
    """The CPU spectral path tracer's linear sRGB image (what `spectra truth` renders with the same
    options); with `crop=(x, y, w, h)` the crop's pixels, with the full render's samples.
    `sample_offset=K` renders samples K … K+spp−1 (the CLI's --sample-offset / --chunk). The
    same seed gives the same image. water / depth / rgb_medium / observer / camera_to_display as
    for `Renderer.render`.
    spectral_bin=NM: the tuple (image, bands float32 (h, w, B), band edges float64 (B + 1,))
    (`--spectral-out`). medium: a spectral participating medium, inline JSON or a JSON file
    (`--medium`, docs/ground-truth.md; not with rgb_medium). lambert=True: a Lambertian BRDF
    (`--lambert`). xyz=True: the image in CIE XYZ (the observer's tristimulus) instead of linear
    sRGB (`--xyz`). table: a Jakob–Hanika .coeff table (`--table`). size / range / crop may be tuples, lists or 1-D arrays; observer and
    rgb_medium files str or os.PathLike; counts ints (bools and floats are refused). Ctrl-C
    raises KeyboardInterrupt within a fraction of a second (in a forked child too); the GIL is
    released."""

@overload
def truth(
    scene: Scene,
    spp: int = 64,
    size: _Size = (256, 256),
    direct_only: bool = False,
    seed: int = 0,
    *,
    sample_offset: int = 0,
    crop: Optional[_Crop] = None,
    range: Optional[_Range] = None,
    observer: Optional[_Path] = None,
    white: Optional[str] = None,
    max_depth: int = 1024,
    water: Optional[str] = None,
    depth: Optional[float] = None,
    rgb_medium: Optional[_Path] = None,
    spectral_bin: float,
    camera_to_display: bool = False,
    medium: Optional[_Path] = None,
    lambert: bool = False,
    xyz: bool = False,
    table: Optional[_Path] = None,
) -> Tuple[RGBImage, _Bands, _Wavelengths]: ...
@overload
def truth(
    scene: Scene,
    spp: int = 64,
    size: _Size = (256, 256),
    direct_only: bool = False,
    seed: int = 0,
    *,
    sample_offset: int = 0,
    crop: Optional[_Crop] = None,
    range: Optional[_Range] = None,
    observer: Optional[_Path] = None,
    white: Optional[str] = None,
    max_depth: int = 1024,
    water: Optional[str] = None,
    depth: Optional[float] = None,
    rgb_medium: Optional[_Path] = None,
    spectral_bin: Optional[float] = None,
    camera_to_display: bool = False,
    medium: Optional[_Path] = None,
    lambert: bool = False,
    xyz: bool = False,
    table: Optional[_Path] = None,
) -> Union[RGBImage, Tuple[RGBImage, _Bands, _Wavelengths]]: ...

def diff(
    a: Union[_FloatImage, _Path],
    b: Union[_FloatImage, _Path],
    *,
    white_y: float = 1.0,
    flip: Optional[str] = None,
    flip_ppd: Optional[float] = None,
    maps: bool = False,
    flip_start_exposure: Optional[float] = None,
    flip_stop_exposure: Optional[float] = None,
    flip_exposures: Optional[int] = None,
    flip_tone_mapper: Optional[str] = None,
) -> dict[str, Any]:
    """`spectra diff --json`'s statistics of image `b` against the reference `a` (float32 or
    float64 arrays of shape (H, W, 3), linear sRGB, compared pixel for pixel; or files, read and
    lined up by their data windows as `spectra diff` does, `region` the part of the frame
    compared, a `Region`, or None): ΔE2000, MAE linear and sRGB-encoded
    (a `DiffSummary`); flip="ldr"/"hdr" adds NVIDIA FLIP (`flip`, `flip_kind`, `flip_ppd`,
    and `flip_exposures`: HDR-FLIP's `start`, `stop`, `count`, `tone_mapper`, None for LDR-FLIP);
    flip_ppd and the HDR-FLIP options (`flip_start_exposure`, `flip_stop_exposure` (both needed
    for a black `a`), `flip_exposures` (their number), `flip_tone_mapper` "aces"/"reinhard"/
    "hable") need `flip`, as `spectra diff --flip-…` need `--metric flip`.
    maps=True adds the per-pixel (H, W) arrays `delta_e2000_map`, `mae_linear_map`,
    `mae_srgb_map` (and `flip_map`). ValueError naming the argument for a wrong dtype or
    shape, a non-finite pixel, or a float64 value beyond float32's range."""

@overload
def upsample(rgb: npt.ArrayLike, space: str = "srgb", *, wavelengths: None = None) -> npt.NDArray[np.float64]:
    """Jakob–Hanika coefficients (c0, c1, c2), float64 (..., 3), of linear RGB reflectances
    (..., 3) in [0, 1] in `space` (srgb, p3, rec2020, acescg), the renderers' own fetch; with
    `wavelengths` (nm, 1-D) the tuple (coefficients, spectra (..., L))."""
@overload
def upsample(
    rgb: npt.ArrayLike, space: str = "srgb", *, wavelengths: npt.ArrayLike
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
@overload
def upsample(
    rgb: npt.ArrayLike, space: str = "srgb", *, wavelengths: Optional[npt.ArrayLike] = None
) -> Union[npt.NDArray[np.float64], Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]: ...

def observer(name: _Path, wavelengths: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """An observer's colour-matching functions or a camera's sensitivities at `wavelengths`
    (nm): float64 (L, 3)."""

def illuminant(name: str, wavelengths: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """An illuminant's relative spectral power at `wavelengths` (nm): float64 (L,)."""

def chart(observer: _Path, illuminant: str = "D65", *, balanced: bool = False) -> npt.NDArray[np.float64]:
    """The 24 ColorChecker Classic patches seen by `observer` under `illuminant`: float64
    (24, 3), ∫ sensitivity·R·E dλ at 1 nm over 360–830 nm; balanced=True divides by the
    perfect white's response."""

@overload
def read_image(path: _Path, *, placement: Literal[False] = False) -> RGBImage:
    """An EXR (linear) or PNG (sRGB-decoded) file as `spectra diff` reads it (an EXR crop: its
    data window); placement=True also returns where those pixels lie in the frame."""
@overload
def read_image(path: _Path, *, placement: Literal[True]) -> Tuple[RGBImage, Placement]: ...
@overload
def read_image(path: _Path, *, placement: bool = False) -> Union[RGBImage, Tuple[RGBImage, Placement]]: ...

def write_image(path: _Path, image: _FloatImage) -> None:
    """Writes an (H, W, 3) linear RGB array as `.exr` (float32) or `.png` (sRGB, 8-bit),
    atomically. FileNotFoundError when the directory does not exist; ValueError for a float64
    value beyond float32's range."""
