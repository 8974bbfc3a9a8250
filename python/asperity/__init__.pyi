"""Type stubs of the public API of asperity (see the docstrings in _api.py, re-exported by __init__.py)."""

import os
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._asperity import BeyondFullContactError as BeyondFullContactError
from ._asperity import ConvergenceError as ConvergenceError
from . import reference as reference

__version__: str
__all__: List[str]

F64 = npt.NDArray[np.float64]
ArrayLike = npt.ArrayLike
ProgressArg = Union[None, bool, str, Callable[[int, int], Any]]
PathLike = Union[str, os.PathLike]

@dataclass
class Surface:
    heights: F64
    size: float = ...
    metadata: Dict[str, Any] = ...
    @property
    def shape(self) -> Tuple[int, int]: ...
    @property
    def size_y(self) -> float: ...
    @property
    def physical_sizes(self) -> Tuple[float, float]: ...
    @property
    def seed(self) -> Optional[int]: ...
    @property
    def stats(self) -> Dict[str, Any]: ...
    def __array__(self, dtype: Any = ..., copy: Any = ...) -> np.ndarray: ...
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

@dataclass
class Line:
    heights: F64
    size: float = ...
    metadata: Dict[str, Any] = ...
    @property
    def seed(self) -> Optional[int]: ...
    @property
    def stats(self) -> Dict[str, Any]: ...
    def __len__(self) -> int: ...
    def __array__(self, dtype: Any = ..., copy: Any = ...) -> np.ndarray: ...
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

def surface(
    n: int, *, hurst: float, m: Optional[int] = ..., rolloff: Optional[float] = ...,
    cutoff: Optional[float] = ..., short_cutoff: Optional[float] = ...,
    rms_height: Optional[float] = ..., rms_slope: Optional[float] = ..., size: float = ...,
    seed: int = ...,
) -> Surface: ...
def line(
    n: int, *, hurst: float, rolloff: Optional[float] = ..., cutoff: Optional[float] = ...,
    rms_height: Optional[float] = ..., rms_slope: Optional[float] = ..., size: float = ...,
    seed: int = ...,
) -> Line: ...
def stats(
    values: Any, *, size: Union[None, float, Tuple[float, float]] = ...,
    fit_from: Optional[float] = ..., fit_to: Optional[float] = ..., window: str = ...,
) -> Dict[str, Any]: ...

@dataclass
class Analysis:
    name: str
    columns: List[str]
    x: F64
    y: F64
    metres: bool = ...
    @property
    def table(self) -> Dict[str, F64]: ...
    def __getitem__(self, column: str) -> F64: ...
    def __len__(self) -> int: ...
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

ANALYSES: Tuple[str, ...]

def analysis(
    values: Any, name: str, *, size: Union[None, float, Tuple[float, float]] = ...,
) -> Analysis: ...

@dataclass
class Psd:
    q: F64
    psd: F64
    modes: npt.NDArray[np.uint64]
    wavenumber: F64
    fit: Optional[Dict[str, float]] = ...
    hurst: Optional[float] = ...
    fit_from: Optional[float] = ...
    fit_to: Optional[float] = ...
    fit_note: Optional[str] = ...
    size: float = ...
    ndim: int = ...
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

def psd(
    values: Any, *, size: Union[None, float, Tuple[float, float]] = ...,
    fit_from: Optional[float] = ...,
    fit_to: Optional[float] = ...,
    window: str = ...,
    convention: str = ...,
) -> Psd: ...

@dataclass
class Topography:
    heights: F64
    size: float
    size_y: Optional[float]
    provenance: Dict[str, Any] = ...
    @property
    def physical_sizes(self) -> Tuple[float, ...]: ...
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

def read_topography(
    path: PathLike, *, channel: Union[None, str, int] = ...,
    size: Union[None, float, Tuple[float, float]] = ...,
    detrend: Optional[str] = ..., fill: Optional[str] = ...,
) -> Topography: ...

def import_topography(
    path: PathLike, out: PathLike, *, channel: Union[None, str, int] = ...,
    size: Union[None, float, Tuple[float, float]] = ...,
    detrend: Optional[str] = ..., fill: Optional[str] = ..., force: bool = ...,
) -> Topography: ...

class AsperityWarning(UserWarning): ...
class UnlevelledWarning(AsperityWarning): ...
class UnitWarning(AsperityWarning): ...

@dataclass
class ContactResult:
    force: float
    mean_pressure: float
    indentation: float
    area_fraction: float
    contact_points: int
    iterations: int
    residual: float
    pressure: Optional[F64] = ...
    gap: Optional[F64] = ...
    displacement: Optional[F64] = ...
    plastic_fraction: float = ...
    plastic_points: int = ...
    plastic_displacement: Optional[F64] = ...
    metadata: Dict[str, Any] = ...
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

@dataclass
class Sweep:
    columns: Dict[str, Any]
    metadata: Dict[str, Any]
    force: F64
    mean_pressure: F64
    indentation: F64
    area_fraction: F64
    stiffness: F64
    iterations: npt.NDArray[np.uint64]
    residual: F64
    stiffness_fd: F64
    contact_points: npt.NDArray[np.uint64]
    pressure: List[F64]
    gap: List[F64]
    def __getitem__(self, name: str) -> Any: ...
    def __len__(self) -> int: ...
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

class Solver:
    shape: Tuple[int, int]
    size: float
    modulus: float
    boundary: str
    tolerance: float
    max_iterations: int
    solver: str
    hardness: Optional[float]
    nominal_area: float
    def __init__(
        self, surface: Any, size: Optional[float] = ..., *, modulus: Optional[float] = ...,
        young: Optional[float] = ..., poisson: Optional[float] = ..., boundary: str = ..., tolerance: float = ..., max_iterations: int = ...,
        solver: str = ..., hardness: Optional[float] = ...,
    ) -> None: ...
    def solve(
        self, *, pressure: Optional[float] = ..., force: Optional[float] = ...,
        indentation: Optional[float] = ..., fields: bool = ...,
    ) -> ContactResult: ...
    def stiffness(self) -> float: ...
    def fd_stiffness(
        self, *, pressure: Optional[float] = ..., force: Optional[float] = ...,
        indentation: Optional[float] = ..., step: float = ...,
    ) -> float: ...
    def sweep(
        self, *, pressures: Optional[Sequence[float]] = ..., forces: Optional[Sequence[float]] = ...,
        indentations: Optional[Sequence[float]] = ..., nloads: Optional[int] = ...,
        pmin: Optional[float] = ..., pmax: Optional[float] = ..., stiffness: bool = ...,
        fd_stiffness: bool = ..., fd_step: float = ..., fields: bool = ...,
        progress: ProgressArg = ..., poisson: Optional[float] = ...,
        resistivity: Optional[Sequence[float]] = ...,
        thermal_conductivity: Optional[Sequence[float]] = ...,
        persson: bool = ..., gamma: Optional[float] = ..., kappa: Optional[float] = ...,
        tangential: Optional[str] = ..., timing: bool = ...,
    ) -> Sweep: ...
    def load_path(
        self, *, pressures: Optional[Sequence[float]] = ..., forces: Optional[Sequence[float]] = ...,
        indentations: Optional[Sequence[float]] = ...,
    ) -> Sweep: ...
    def permanent_displacement(self) -> F64: ...
    def full_contact_threshold(self) -> Dict[str, Optional[float]]: ...
    def reset(self) -> None: ...

def effective_modulus(
    *, modulus: Optional[float] = ...,
    young: Union[None, float, Sequence[float]] = ...,
    poisson: Union[None, float, Sequence[float]] = ...,
) -> float: ...

@dataclass
class Patches:
    labels: npt.NDArray[np.uint32]
    points: npt.NDArray[np.uint64]
    areas: F64
    def __len__(self) -> int: ...
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

def patches(contact_set: Any, *, pixel_area: float = ...) -> Patches: ...

def load(path: PathLike) -> Any: ...
def reproduce(figure: str, out: PathLike, *, setting: str = "paper",
              force: bool = False) -> str: ...

def contact(
    surface: Any, size: Optional[float] = ..., *, pressures: Optional[Sequence[float]] = ...,
    modulus: Optional[float] = ..., young: Union[None, float, Sequence[float]] = ...,
    poisson: Union[None, float, Sequence[float]] = ...,
    boundary: str = ..., tolerance: float = ..., map: bool = ...,
    resistivity: Optional[Sequence[float]] = ...,
    thermal_conductivity: Optional[Sequence[float]] = ...,
    hardness: Optional[float] = ..., tangential: Union[bool, str] = ..., load_path: bool = ...,
    progress: ProgressArg = ...,
    work_of_adhesion: Optional[float] = ..., adhesion_range: Optional[float] = ...,
    adhesion_model: Optional[str] = ..., indentations: Optional[Sequence[float]] = ...,
    retract_step: Optional[float] = ...,
) -> Sweep: ...

@dataclass
class MdrCurve:
    indentation: F64
    force: F64
    stiffness: F64
    contacts: npt.NDArray[np.uint64]
    description: str
    spring: str
    critical_depth: float
    branch: Optional[List[str]] = ...
    pull_off: Optional[Dict[str, Dict[str, float]]] = ...
    modulus: Optional[float] = ...
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

def mdr(
    *, line: Any = ..., profile: Optional[str] = ..., radial: Any = ...,
    radial_step: Optional[float] = ..., radius: Optional[float] = ..., slope: Optional[float] = ...,
    coefficient: Optional[float] = ..., exponent: Optional[float] = ..., n: Optional[int] = ...,
    dx: Optional[float] = ..., size: Optional[float] = ..., modulus: Optional[float] = ...,
    spring: Optional[str] = ..., hurst: Optional[float] = ..., rms_height: Optional[float] = ...,
    asperity_radius: Optional[float] = ..., indentations: Optional[Sequence[float]] = ...,
    nloads: Optional[int] = ..., dmin: Optional[float] = ..., dmax: Optional[float] = ...,
    breakpoints: bool = ...,
    work_of_adhesion: Optional[float] = ...,
) -> MdrCurve: ...

@dataclass
class SlipCycle:
    branch: List[str]
    tangential_displacement: F64
    tangential_force: F64
    stick_springs: npt.NDArray[np.uint64]
    stick_radius: Optional[F64]
    summary: Dict[str, Any]
    description: str
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

def mdr_slip(
    *, tangential_force: float, friction: Optional[float] = ..., poisson: Optional[float] = ...,
    cycle_points: Optional[int] = ..., indentations: Optional[Sequence[float]] = ...,
    line: Any = ..., profile: Optional[str] = ..., radial: Any = ...,
    radial_step: Optional[float] = ..., radius: Optional[float] = ..., slope: Optional[float] = ...,
    coefficient: Optional[float] = ..., exponent: Optional[float] = ..., n: Optional[int] = ...,
    dx: Optional[float] = ..., size: Optional[float] = ..., modulus: Optional[float] = ...,
    spring: Optional[str] = ..., hurst: Optional[float] = ..., rms_height: Optional[float] = ...,
    asperity_radius: Optional[float] = ..., work_of_adhesion: Optional[float] = ...,
) -> SlipCycle: ...

@dataclass
class BemAdhesion:
    indentation: F64
    force: F64
    mean_pressure: F64
    area_fraction: F64
    tensile_fraction: F64
    rounds: npt.NDArray[np.uint64]
    cg_iterations: npt.NDArray[np.uint64]
    branch: List[str]
    pull_off: Optional[Dict[str, Any]]
    critical_stress: float
    warning: Optional[str]
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

def bem_adhesion(
    surface: Any, *, work_of_adhesion: float, indentations: Sequence[float],
    size: Optional[float] = ..., modulus: float = ..., boundary: str = ...,
    retract_step: Optional[float] = ..., adhesion_range: Optional[float] = ...,
    adhesion_model: Optional[str] = ...,
) -> BemAdhesion: ...

PERSSON_KAPPA: float

@dataclass
class PerssonTable:
    pressure: F64
    area_fraction: F64
    mean_gap: F64
    stiffness_per_area: F64
    contact_stiffness: F64
    rms_height: float
    rms_gradient: float
    u0: float
    modulus: float
    gamma: float
    kappa: float
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...

def persson(
    surface: Any, pressures: Optional[Sequence[float]] = ..., *, size: Optional[float] = ...,
    modulus: float = ..., gamma: float = ..., kappa: float = ..., nloads: Optional[int] = ...,
    pmin: Optional[float] = ..., pmax: Optional[float] = ...,
) -> PerssonTable: ...

@dataclass
class StudyResult:
    columns: Dict[str, np.ndarray]
    rows: List[Dict[str, Any]]
    tasks: List[Dict[str, Any]]
    comparisons: List[Optional[Dict[str, Any]]] = ...
    comparison_error: Optional[str] = ...
    metadata: Dict[str, Any] = ...
    figures: Dict[str, Any] = ...
    def save(self, path: PathLike, *, force: bool = ...) -> None: ...
    def comparison(self) -> Dict[str, np.ndarray]: ...
    def __getitem__(self, name: str) -> np.ndarray: ...
    def __getattr__(self, name: str) -> np.ndarray: ...

def study_alpha(
    *, method: str, n: Union[int, Sequence[int]], hurst: Union[str, float, Sequence[float]],
    samples: int, out: PathLike, rolloff: Optional[float] = ..., seed: Optional[int] = ...,
    min_contacts: Optional[int] = ..., max_fraction: Optional[float] = ..., levels: Optional[int] = ...,
    full_sweep: bool = ..., force: bool = ..., checkpoint_every: Optional[float] = ...,
    progress: ProgressArg = ...,
) -> StudyResult: ...
def study_curve(
    *, method: str, n: int, hurst: Union[str, float, Sequence[float]], samples: int,
    out: PathLike, rolloff: Optional[float] = ..., seed: Optional[int] = ...,
    min_contacts: Optional[int] = ..., max_fraction: Optional[float] = ..., levels: Optional[int] = ...,
    force: bool = ..., checkpoint_every: Optional[float] = ..., progress: ProgressArg = ...,
    poisson: Optional[float] = ..., resistivity: Optional[Sequence[float]] = ...,
    thermal_conductivity: Optional[Sequence[float]] = ..., tangential: Optional[str] = ...,
) -> StudyResult: ...
def study_file(
    path: PathLike, out: PathLike, *, force: bool = ..., checkpoint_every: Optional[float] = ...,
    progress: ProgressArg = ...,
) -> StudyResult: ...
def study_compare(
    folder: PathLike, *, force: bool = ...,
) -> Dict[str, npt.NDArray[Any]]: ...

def study_windows(out: PathLike) -> Dict[str, npt.NDArray[Any]]: ...
