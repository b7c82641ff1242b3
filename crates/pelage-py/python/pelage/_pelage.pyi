"""Type stubs of pelage's Rust extension module (crates/pelage-py/src)."""

from os import PathLike
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
__build_profile__: str  # "release" or "debug"

_Path = Union[str, PathLike[str]]
_Map = Union[float, str]
_Progress = Callable[[int, int], Any]
_Bounds = Tuple[Tuple[float, float, float], Tuple[float, float, float]]

class PelageError(Exception):
    """An error from pelage; the message names the file, line and setting."""

class Mesh:
    """A triangle mesh (immutable)."""
    @staticmethod
    def load(path: _Path, subdivide: int = 0) -> "Mesh": ...
    @staticmethod
    def spot() -> "Mesh": ...
    @staticmethod
    def from_arrays(
        positions: npt.ArrayLike,
        triangles: npt.ArrayLike,
        uvs: Optional[npt.ArrayLike] = None,
        normals: Optional[npt.ArrayLike] = None,
        name: str = "<python mesh>",
        vertex_maps: Optional[Dict[str, npt.ArrayLike]] = None,
        face_sets: Optional[npt.ArrayLike] = None,
        materials: Optional[npt.ArrayLike] = None,
    ) -> "Mesh": ...
    def subdivided(self, levels: int) -> "Mesh": ...
    @property
    def positions(self) -> npt.NDArray[np.float32]: ...
    @property
    def triangles(self) -> npt.NDArray[np.uint32]: ...
    @property
    def normals(self) -> npt.NDArray[np.float32]: ...
    @property
    def corner_uvs(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def triangle_count(self) -> int: ...
    @property
    def has_uvs(self) -> bool: ...
    @property
    def name(self) -> str: ...
    def info(self) -> Dict[str, Any]: ...

class Samples:
    """Sampled hair roots, as numpy arrays."""
    positions: npt.NDArray[np.float32]
    normals: npt.NDArray[np.float32]
    uvs: Optional[npt.NDArray[np.float32]]
    triangles: npt.NDArray[np.uint32]
    barycentrics: npt.NDArray[np.float32]
    def __len__(self) -> int: ...

def sample(
    mesh: Mesh,
    n: int,
    *,
    density: Optional[Union[_Map, npt.NDArray[np.floating[Any]]]] = None,
    seed: int = 1,
    first: int = 0,
    distribution: str = "random",
) -> Samples: ...

class Curves:
    """Hair curves as structure of arrays; arrays are read-only views."""
    @staticmethod
    def from_arrays(
        points: npt.ArrayLike,
        offsets: npt.ArrayLike,
        widths: Optional[npt.ArrayLike] = None,
        colors: Optional[npt.ArrayLike] = None,
        opacities: Optional[npt.ArrayLike] = None,
        normals: Optional[npt.ArrayLike] = None,
        root_uvs: Optional[npt.ArrayLike] = None,
        ids: Optional[npt.ArrayLike] = None,
    ) -> "Curves": ...
    @property
    def points(self, matrix: Optional[npt.ArrayLike] = None) -> npt.NDArray[np.float32]: ...
    @property
    def offsets(self) -> npt.NDArray[np.uint32]: ...
    @property
    def widths(self) -> npt.NDArray[np.float32]: ...
    @property
    def colors(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def opacities(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def normals(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def root_uvs(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def ids(self) -> Optional[npt.NDArray[np.uint64]]: ...
    @property
    def regions(self) -> Optional[npt.NDArray[np.uint32]]: ...
    @property
    def shading(self) -> Optional[dict[str, npt.NDArray[np.float32]]]: ...
    @property
    def root_triangles(self) -> Optional[npt.NDArray[np.uint32]]: ...
    @property
    def root_barycentrics(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def curve_count(self) -> int: ...
    @property
    def point_count(self) -> int: ...
    @property
    def bounds(self) -> Optional[_Bounds]: ...
    def write(
        self, path: _Path, *, basis: str = "catmull-rom", up_axis: str = "y", mesh: Optional[Mesh] = None
    ) -> None: ...
    def __len__(self) -> int: ...

def read_curves(path: _Path, *, time: Optional[float] = None) -> Curves: ...
def operator_schema() -> List[Dict[str, Any]]: ...
def write_curves(
    curves: Curves,
    path: _Path,
    *,
    basis: str = "catmull-rom",
    up_axis: str = "y",
    mesh: Optional[Mesh] = None,
) -> None: ...

class PartIterator(Iterator[Curves]):
    def __next__(self) -> Curves: ...
    def __len__(self) -> int: ...

class Groom:
    """A groom: surface, guides, roots, operators and finish."""
    def __init__(
        self,
        *,
        mesh: Union[Mesh, _Path, Dict[str, Any]],
        guides: Union[Curves, _Path, Dict[str, Any]],
        roots: Union[int, Dict[str, Any]],
        ops: Optional[Sequence[Dict[str, Any]]] = None,
        interpolation: Optional[Dict[str, Any]] = None,
        finish: Optional[Dict[str, Any]] = None,
        output: Optional[Dict[str, Any]] = None,
        animation: Optional[Dict[str, Any]] = None,
        simulation: Optional[Dict[str, Any]] = None,
        regions: Optional[Dict[str, Any]] = None,
        look: Optional[Dict[str, Any]] = None,
        base_dir: Optional[_Path] = None,
        skin: Optional[Dict[float, Any]] = None,
    ) -> None: ...
    @staticmethod
    def load(
        path: _Path,
        *,
        frames: Optional[str] = None,
        mesh: Optional[Mesh] = None,
        fraction: Optional[float] = None,
        skin: Optional[Dict[float, Any]] = None,
    ) -> "Groom": ...
    @staticmethod
    def from_text(text: str, *, path: _Path = "<groom>", mesh: Optional[Mesh] = None) -> "Groom": ...
    @property
    def settings(self) -> str: ...
    @property
    def mesh(self) -> Mesh: ...
    @property
    def guides(self) -> Curves: ...
    @property
    def part_count(self) -> int: ...
    @property
    def part_hair_counts(self) -> List[int]: ...
    @property
    def output_path(self) -> PathLike[str]: ...
    @property
    def frames(self) -> Optional[List[float]]: ...
    def grow(
        self,
        part: Optional[int] = None,
        *,
        seed: Optional[int] = None,
        progress: Optional[_Progress] = None,
        gpu: bool = False,
    ) -> Curves: ...
    def grow_frame(self, time: float, part: Optional[int] = None) -> Curves: ...
    def simulate(self, path: Optional[_Path] = None) -> Dict[str, Any]: ...
    def parts(self, *, seed: Optional[int] = None) -> PartIterator: ...
    def write(
        self,
        path: Optional[_Path] = None,
        *,
        part: Optional[Tuple[int, int]] = None,
        seed: Optional[int] = None,
        progress: Optional[_Progress] = None,
        gpu: bool = False,
    ) -> Dict[str, Any]: ...
    def assemble(self, path: Optional[_Path] = None) -> Dict[str, Any]: ...
    def report(self, *, seed: Optional[int] = None) -> Dict[str, Any]: ...

class GroomSession:
    def __init__(self, groom: Groom, *, fraction: float = 1.0) -> None: ...
    def brush(
        self,
        name: str,
        *,
        at: Tuple[float, float, float],
        radius: float,
        strength: float = 1.0,
        direction: Tuple[float, float, float] = (0.0, 0.0, 0.0),
        falloff: str = "smooth",
        mirror_x: bool = False,
        layer: Optional[str] = None,
        value: Optional[float] = None,
        region: Optional[int] = None,
        count: Optional[int] = None,
    ) -> Optional[Dict[str, int]]: ...
    def set_guides(self, curves: Curves, *, tolerance: float = 1e-3) -> Optional[Dict[str, int]]: ...
    def undo(self) -> bool: ...
    def redo(self) -> bool: ...
    def curves(self) -> Curves: ...
    def points(self) -> npt.NDArray[np.float32]: ...
    def guides(self) -> Curves: ...
    def layer(self, name: str) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def layers(self) -> List[str]: ...
    @property
    def fraction(self) -> float: ...
    @fraction.setter
    def fraction(self, value: float) -> None: ...
    @property
    def hair_count(self) -> int: ...
    @property
    def history(self) -> Tuple[int, int]: ...
    def save(self, path: _Path) -> Dict[str, Optional[str]]: ...
