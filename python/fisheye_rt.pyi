"""Fisheye and wide-angle lens rendering by ray tracing in wgpu compute shaders: lens models
and the GPU tracer of fisheye-rt, with numpy arrays in and out.

Camera frames are OpenCV's (x right, y down, z forward); a pose is a 4×4 `T_scene_camera`
(camera coordinates to scene coordinates). Pixel coordinates are this project's unless
`pixel_origin="opencv"`: "corner" puts the top-left pixel's corner at (0, 0) and its centre at
(0.5, 0.5); "opencv" puts its centre at (0, 0). Errors are `ValueError` (bad input), `OSError`
(files) or `RuntimeError` (the GPU), carrying the library's message.
"""

from os import PathLike
from typing import Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

PixelOrigin = Literal["corner", "opencv"]
Output = Literal[
    "colour", "srgb", "range", "normal", "id", "direction", "mask", "depth", "point", "spp"
]

class Lens:
    """A lens at an image size: a classic model or a calibrated camera."""

    @staticmethod
    def from_spec(spec: str, size: Sequence[int]) -> "Lens":
        """A lens from its spec (`fisheye lens list`: "samyang-7.5mm",
        "equisolid:f=0.6,fov=180", "kb:fx=...,k1=...", or "prescription:FILE[,sensor=MM]
        [,fstop=N][,focus=METRES][,rays=glass|fit][,model=kb|ds|equidistant]" for a lens's
        glass: rendered through its surfaces, mapped by its chief rays) at
        size = (width, height)."""
    @staticmethod
    def from_calibration(path: Union[str, PathLike], camera: int = 0) -> "Lens":
        """Camera `camera` of a calibration file (OpenCV YAML/XML, Kalibr, Basalt), at its
        calibrated size."""
    @property
    def size(self) -> Tuple[int, int]:
        """(width, height) in pixels."""
    @property
    def spec(self) -> str:
        """The lens as a spec `from_spec` reads back."""
    def unproject(
        self,
        pixels: npt.ArrayLike,
        pixel_origin: PixelOrigin = "corner",
        gpu: bool = False,
    ) -> npt.NDArray[np.float64]:
        """Unit directions, shape (..., 3), of pixels, shape (..., 2); NaN rows where a pixel
        has no ray (outside the image or the lens's field). gpu=True runs the WGSL code (f32)
        instead of the f64 reference."""
    def project(
        self,
        directions: npt.ArrayLike,
        pixel_origin: PixelOrigin = "corner",
        gpu: bool = False,
    ) -> npt.NDArray[np.float64]:
        """Pixels, shape (..., 2), where directions, shape (..., 3), land; NaN rows where one
        lands outside the field or the image."""

class Scene:
    """A scene: built-in, a scene file or an OBJ."""

    @staticmethod
    def load(spec: Union[str, PathLike]) -> "Scene":
        """Loads "builtin:NAME", a scene file (.toml) or an OBJ file."""
    @property
    def triangles(self) -> int:
        """How many triangles it has."""
    @property
    def camera(self) -> npt.NDArray[np.float64]:
        """Its own camera as a 4×4 T_scene_camera."""
    @property
    def warnings(self) -> list[str]:
        """What loading repaired, one line each."""
    @property
    def key_span(self) -> Optional[Tuple[float, float]]:
        """The first and last key times (seconds) of what moves it (glTF animations,
        scene-file keys), for Renderer.render(time=...); None where nothing moves."""

class Renderer:
    """A scene on the GPU (uploaded once), rendered through any lens from any pose."""

    def __init__(self, scene: Scene, max_depth: int = 5, bvh: str = "fast") -> None:
        """Builds the scene's BVH ("fastest", "very-fast", "fast", "medium", "slow") and
        uploads it; max_depth (0 to 8) bounds reflection and refraction."""
    @property
    def adapter(self) -> str:
        """The GPU adapter it renders on."""
    def render(
        self,
        lens: Lens,
        pose: Optional[npt.ArrayLike] = None,
        spp: int | str = 16,
        outputs: Sequence[Output] = ("colour", "srgb"),
        exposure: float = 0.0,
        tone: Literal["aces", "clamp"] = "aces",
        time: float = 0.0,
        filter: Literal["box", "tent"] = "box",
    ) -> dict[str, np.ndarray]:
        """Renders through `lens` from `pose` (4×4 T_scene_camera; the scene's camera if None)
        with `spp` rays per pixel (a square, 1 to 256, or "auto[:THRESHOLD[:MAX]]": adaptive
        sampling, as `fisheye render --spp` takes it). Returns one array per output:
        "colour" H×W×4 float32 (linear RGB, alpha the lens's coverage), "srgb" H×W×4 uint8
        (through `exposure` stops and the `tone` curve), and the centre ray's "range" H×W
        float32, "normal" H×W×3 float32, "id" H×W uint32 (4294967295: none), "direction"
        H×W×3 float32 (scene frame), "mask" H×W uint8, "depth" H×W float32 (the hit's z in the
        camera's frame) and "point" H×W×3 float32 (the hit in the camera's frame: x right, y
        down, z forward), as `fisheye render --outputs` writes them, bit for bit, and "spp" H×W uint32, the rays each pixel's colour took (adaptive
        sampling's count, 0 where a pixel was interpolated; `spp` at each pixel with a ray). Moving objects are placed at scene time `time` (seconds), as
        `fisheye render --time` places them. `filter` "tent" blends each pixel of a frame of
        one ray a pixel at most with its neighbours, as `fisheye render --filter tent` (with more
        rays a `UserWarning` says each pixel keeps its rays' mean). The GIL
        is released while the GPU works."""

def look_at(
    eye: npt.ArrayLike,
    target: npt.ArrayLike,
    up: Optional[npt.ArrayLike] = None,
) -> npt.NDArray[np.float64]:
    """The 4×4 T_scene_camera of a camera at `eye` looking at `target`, level with `up`
    ((0, 1, 0) if None); each three finite numbers (a tuple, a list or a numpy array)."""
