"""Type stubs of the native module (crates/splatgl-python)."""

import os
from typing import Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, "os.PathLike[str]"]
ArrayLike = npt.ArrayLike
Finding = Tuple[str, str, str]

__version__: str
TILE_CHUNK_SPLATS: int
TILE_BUCKET_SPLATS: int

class SplatglError(Exception): ...
class LoadError(SplatglError): ...
class SaveError(SplatglError): ...
class RenderError(SplatglError): ...
class CameraError(SplatglError): ...
class ConformanceError(SplatglError): ...
class TilesError(SplatglError): ...

class Cloud:
    """A splat cloud; the arrays are the cloud's own (float32)."""

    @staticmethod
    def from_arrays(
        positions: ArrayLike,
        scales: ArrayLike,
        rotations: ArrayLike,
        opacities: ArrayLike,
        sh: Optional[ArrayLike] = None,
        colors: Optional[ArrayLike] = None,
        color_space: Optional[str] = None,
        *,
        max_splats: Optional[int] = None,
    ) -> "Cloud": ...
    @property
    def positions(self) -> npt.NDArray[np.float32]: ...
    @property
    def scales(self) -> npt.NDArray[np.float32]: ...
    @property
    def rotations(self) -> npt.NDArray[np.float32]: ...
    @property
    def opacities(self) -> npt.NDArray[np.float32]: ...
    @property
    def sh(self) -> npt.NDArray[np.float32]: ...
    @property
    def sh_degree(self) -> int: ...
    @property
    def format(self) -> str: ...
    @property
    def meta(self) -> Dict[str, str]: ...
    @property
    def findings(self) -> List[Finding]: ...
    def __len__(self) -> int: ...

class Camera:
    """A pinhole camera, OpenCV axes (x right, y down, z forward)."""

    def __init__(
        self,
        fx: float,
        fy: float,
        cx: float,
        cy: float,
        width: int,
        height: int,
        world_to_camera: ArrayLike,
        near: float = 0.01,
        far: float = 1000.0,
    ) -> None: ...
    @staticmethod
    def look_at(
        eye: ArrayLike,
        target: ArrayLike,
        up: Optional[ArrayLike] = None,
        fov_y_deg: float = 50.0,
        width: int = 1280,
        height: int = 720,
    ) -> "Camera": ...
    @staticmethod
    def from_cameras_json(
        path: PathLike,
        index: int = 0,
        width: Optional[int] = None,
        height: Optional[int] = None,
    ) -> "Camera": ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def fx(self) -> float: ...
    @property
    def fy(self) -> float: ...
    @property
    def cx(self) -> float: ...
    @property
    def cy(self) -> float: ...
    @property
    def eye(self) -> Tuple[float, float, float]: ...
    @property
    def world_to_camera(self) -> npt.NDArray[np.float64]: ...

def load(
    path: PathLike,
    *,
    max_splats: Optional[int] = None,
    max_bytes: Optional[int] = None,
    strict: bool = False,
    allow_outside_paths: bool = False,
) -> Cloud: ...
def load_bytes(
    data: bytes,
    name: Optional[str] = None,
    *,
    max_splats: Optional[int] = None,
    strict: bool = False,
) -> Cloud: ...
def save(
    cloud: Cloud,
    path: PathLike,
    *,
    sh_degree: Optional[int] = None,
    spz_compress: bool = False,
    color_space: Optional[str] = None,
) -> None: ...
class Renderer:
    """A renderer kept open: one GL context (or the reference) and one uploaded cloud."""

    def __init__(
        self, backend: str = "auto", width: Optional[int] = None, height: Optional[int] = None
    ) -> None: ...
    def upload(self, cloud: Cloud) -> None: ...
    def render(
        self,
        camera: Camera,
        sh_degree: int = 3,
        background: Tuple[float, float, float] = (0.0, 0.0, 0.0),
        antialiased: bool = False,
    ) -> npt.NDArray[np.float32]: ...
    def render_many(
        self,
        cameras: Sequence[Camera],
        sh_degree: int = 3,
        background: Tuple[float, float, float] = (0.0, 0.0, 0.0),
        antialiased: bool = False,
    ) -> List[npt.NDArray[np.float32]]: ...
    def close(self) -> None: ...
    @property
    def backend(self) -> str: ...
    @property
    def closed(self) -> bool: ...
    def __enter__(self) -> "Renderer": ...
    def __exit__(self, *args: object) -> bool: ...

def render(
    cloud: Cloud,
    camera: Camera,
    backend: str = "auto",
    sh_degree: int = 3,
    background: Tuple[float, float, float] = (0.0, 0.0, 0.0),
    antialiased: bool = False,
) -> npt.NDArray[np.float32]: ...
def save_image(image: ArrayLike, path: PathLike) -> None: ...
def validate(path: PathLike) -> List[Finding]: ...
def compare(
    a: Union[PathLike, ArrayLike], b: Union[PathLike, ArrayLike], threshold: float = ...
) -> Dict[str, float]: ...
def conformance_generate(dir: str) -> None: ...
def conformance_run(
    dir: str, images: str, out: Optional[str] = None, input_precision: str = "exact"
) -> str: ...
def cli(argv: Sequence[str]) -> int: ...
def tiles_plan(
    input: str, output: str, scratch_dir: str, bucket_splats: int, chunk_splats: int,
    ranges: int
) -> str: ...
def tiles_route(plan: str, range: int) -> str: ...
def tiles_build_bucket(plan: str, bucket: int) -> str: ...
def tiles_join(plan: str, buckets: Sequence[str]) -> str: ...
