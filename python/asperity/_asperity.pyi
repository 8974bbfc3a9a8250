"""The compiled core of asperity (PyO3). Use the functions of `asperity` instead: they
check and convert their arguments and document them."""

from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class ConvergenceError(RuntimeError):
    iterations: int
    residual: float

class BeyondFullContactError(ValueError):
    threshold: Optional[float]
    quantity: str
    requested: float

Progress = Optional[Callable[[int, int], Any]]
F64 = npt.NDArray[np.float64]

def generate_surface(
    n: int, m: Optional[int], hurst: float, rolloff: Optional[float], cutoff: Optional[float],
    short_cutoff: Optional[float], rms_height: Optional[float], rms_slope: Optional[float],
    size: float, seed: str,
) -> Tuple[F64, str]: ...
def generate_line(
    n: int, hurst: float, rolloff: Optional[float], cutoff: Optional[float],
    rms_height: Optional[float], rms_slope: Optional[float], size: float, seed: str,
) -> Tuple[F64, str]: ...
def save_heights(path: str, array: F64, metadata: str, force: bool) -> None: ...
def statistics(
    array: npt.NDArray[np.float64], size_x: float, size_y: Optional[float], measured: bool,
    metadata: Optional[str], fit_from: Optional[float], fit_to: Optional[float],
    window: str, convention: str,
) -> Dict[str, Any]: ...
def analyses(
    array: npt.NDArray[np.float64], size_x: float, size_y: Optional[float], measured: bool,
    metadata: Optional[str], names: List[str],
) -> List[List[Tuple[str, npt.NDArray[np.float64]]]]: ...
def analysis_names() -> List[str]: ...
def sweep_loads(
    forces: Optional[List[float]], pressures: Optional[List[float]],
    indentations: Optional[List[float]], nloads: Optional[int], pmin: Optional[float],
    pmax: Optional[float], fields: bool,
) -> Tuple[str, List[float]]: ...
def sweep_persson(
    persson: bool, gamma: Optional[float], kappa: Optional[float],
) -> Optional[Tuple[float, float]]: ...
def one_load(
    what: str, pressure: Optional[float], force: Optional[float], indentation: Optional[float],
) -> Tuple[str, float]: ...

def contact(
    heights: npt.NDArray[np.float64], size_x: float, size_y: Optional[float],
    pressures: List[float], modulus: Optional[float], young: Optional[List[float]],
    poisson: Optional[List[float]], boundary: str, tolerance: float, map: bool,
    resistivity: Optional[List[float]] = ..., thermal_conductivity: Optional[List[float]] = ...,
    hardness: Optional[float] = ..., tangential: bool = ...,
    directions: Optional[str] = ..., progress: Progress = ...,
    adhesion: Optional[Tuple[Optional[float], Optional[float], Optional[str], List[float],
                             Optional[float]]] = ...,
    load_path: bool = ...,
) -> Optional[Dict[str, Any]]: ...

class Solver:
    def __init__(
        self, heights: F64, size_x: float, size_y: Optional[float], modulus: float,
        boundary: str, tolerance: float, max_iterations: int, solver: str,
        hardness: Optional[float] = ...,
    ) -> None: ...
    shape: Tuple[int, int]
    nominal_area: float
    modulus: float
    boundary: str
    size: float
    tolerance: float
    max_iterations: int
    solver: str
    hardness: Optional[float]
    def reset(self) -> None: ...
    def permanent_displacement(self) -> F64: ...
    def load_path(self, quantity: str, values: List[float]) -> Dict[str, Any]: ...
    def full_contact_threshold(self) -> Tuple[float, Optional[float]]: ...
    def solve(self, quantity: str, value: float, fields: bool) -> Dict[str, Any]: ...
    def stiffness(self) -> Tuple[float, int, float]: ...
    def fd_stiffness(self, quantity: str, value: float, step: float) -> float: ...
    def sweep(
        self, quantity: str, values: List[float], stiffness: bool, fd_step: Optional[float],
        fields: bool, progress: Progress, poisson: Optional[float] = ...,
        resistivity: Optional[List[float]] = ...,
        thermal_conductivity: Optional[List[float]] = ...,
        persson: Optional[Tuple[float, float]] = ...,
        tangential: Optional[str] = ...,
        timing: bool = ...,
    ) -> Dict[str, Any]: ...

def mdr_curve(
    request: Dict[str, Any], line: Optional[F64], radial: Optional[F64],
) -> Dict[str, Any]: ...

def mdr_slip(
    request: Dict[str, Any], line: Optional[F64], radial: Optional[F64], tangential_force: float,
    friction: Optional[float], poisson: Optional[float], cycle_points: Optional[int],
) -> Dict[str, Any]: ...
def bem_adhesion(
    array: F64, size_x: float, size_y: Optional[float], modulus: float, boundary: str,
    work_of_adhesion: float, indentations: List[float], retract_step: Optional[float],
    adhesion_range: Optional[float] = ...,
    adhesion_model: Optional[str] = ...,
) -> Dict[str, Any]: ...
def persson_table(
    array: F64, size_x: float, size_y: Optional[float], modulus: float, gamma: float,
    kappa: float, pressures: Optional[List[float]], nloads: Optional[int],
    pmin: Optional[float], pmax: Optional[float],
) -> Dict[str, Any]: ...
def read_study_file(path: str) -> Dict[str, Any]: ...
def study_windows(dir: str) -> Dict[str, npt.NDArray[Any]]: ...
# A study's keywords: kind ("alpha"|"curve"), method, sizes, hursts, samples, rolloff,
# seed (its digits), min_contacts, max_fraction, levels, full_sweep, poisson, tangential.
StudyKeywords = Dict[str, Any]
def run_study(
    request: StudyKeywords, out: str, force: bool, checkpoint_every: Optional[float],
    progress: Progress, resistivity: Optional[List[float]] = ...,
    thermal_conductivity: Optional[List[float]] = ...,
    eta: Optional[Callable[["StudyEta"], Any]] = ...,
) -> str: ...
class StudyEta:
    """A study's ETA in samples (the CLI's arithmetic: samples read back from checkpoints
    do not count towards the rate; each sample weighs its cost)."""
    @property
    def total(self) -> int: ...
    def remaining(self, done: int, elapsed: float) -> Optional[float]: ...
    def line(self, name: str, done: int, elapsed: float) -> Optional[str]: ...
def hurst_range(text: str) -> List[float]: ...
def comparison_columns() -> List[Tuple[str, str]]: ...
def thread_count() -> int: ...
# ("assign", rank, task, indices, spec JSON or None) | ("stop", rank, 0, [], None) |
# ("end", 0, 0, [], None)
Action = Tuple[str, int, int, List[int], Optional[str]]
class StudyCoordinator:
    def __init__(self, size: int, lanes: int) -> None: ...
    def begin(
        self, request: StudyKeywords, out: str, force: bool,
        checkpoint_every: Optional[float], resistivity: Optional[List[float]] = ...,
        thermal_conductivity: Optional[List[float]] = ...,
    ) -> List[Action]: ...
    def on_ready(self, rank: int, lanes: int) -> List[Action]: ...
    def on_done(self, rank: int, curves: str) -> List[Action]: ...
    def on_failed(self, rank: int, reason: str) -> List[Action]: ...
    def halt(self, reason: str) -> List[Action]: ...
    def save_due(self) -> List[Action]: ...
    def progress(self) -> Tuple[int, int]: ...
    def busy(self) -> List[int]: ...
    def finish(self) -> str: ...
    def stop(self) -> List[Action]: ...
    def stopped(self) -> bool: ...
    def close(self) -> None: ...
class SampleComputer:
    def __init__(self, spec_json: str) -> None: ...
    def compute(self, t: int, indices: List[int]) -> str: ...
def read_topography(
    path: str, channel: Optional[str], size_x: Optional[float], size_y: Optional[float],
    detrend: Optional[str], fill: Optional[str],
) -> Tuple[npt.NDArray[np.float64], List[float], str, List[Tuple[str, str]]]: ...
def import_topography(
    path: str, out: str, channel: Optional[str], size_x: Optional[float],
    size_y: Optional[float], detrend: Optional[str], fill: Optional[str], force: bool,
) -> Tuple[npt.NDArray[np.float64], List[float], str, List[Tuple[str, str]]]: ...
def save_topography(
    path: str, array: F64, sizes: List[float], provenance: str, force: bool,
) -> None: ...
def save_files(files: List[Tuple[str, bytes]], force: bool) -> None: ...
def saved_sidecar(path: str) -> Optional[str]: ...
def sizes(values: List[float]) -> Tuple[Optional[float], Optional[float]]: ...
def write_fields(
    path: str, grid: Optional[Tuple[Tuple[int, int], Tuple[float, float]]],
    units: Tuple[bool, bool], title: str, record: str,
    variables: List[Tuple[str, str, np.ndarray]], force: bool,
) -> None: ...
def read_fields(path: str) -> Tuple[
    List[Tuple[str, str]], Optional[Tuple[int, int, float, float, Optional[str]]],
    List[Tuple[str, List[str], str, Optional[str], Optional[str], np.ndarray]],
]: ...
def effective_modulus(
    modulus: Optional[float], young: Optional[List[float]], poisson: Optional[List[float]],
) -> float: ...
def label_patches(
    set: npt.NDArray[np.bool_], pixel_area: float,
) -> Tuple[npt.NDArray[np.uint32], npt.NDArray[np.uint64], F64]: ...
def reference(
    model: str, params: List[float], method: str, scalars: List[float], x: F64,
) -> F64: ...
def cli(argv: List[str]) -> int:
    """The `asperity` command line (argv with the program's name first) in this process; the
    exit status. For the package's console script: it installs the command's own Ctrl-C
    handling in the calling process."""
    ...
def defaults() -> Dict[str, Any]:
    """The defaults shared with the CLI (modulus, boundary, solver, tolerance,
    max_iterations, fd_step, gamma, kappa, size, seed, window, convention), from the
    front-end layer."""
    ...
def sweep_figure(
    force: List[float], stiffness: List[float], stiffness_fd: Optional[List[float]],
    area_fraction: List[float], name: str, modulus: float, physical: bool, boundary: str,
) -> str: ...
def path_figure(
    values: List[float], indentation: List[float], force: List[float],
    area_fraction: List[float], stiffness: List[float], name: str, boundary: str,
    hardness: Optional[float],
) -> str: ...
def adhesion_loop_figure(
    indentation: List[float], force: List[float], retract: List[bool],
    pull_off: Optional[Tuple[Tuple[float, float], Tuple[float, float]]], title: str,
    x_label: str, y_label: str, force_unit: str,
    theory: Optional[Tuple[str, List[Tuple[float, float]]]] = ...,
) -> str: ...
def mdr_figure(
    indentation: List[float], force: List[float], stiffness: List[float], description: str,
    law: str, modulus: float,
) -> str: ...
def surface_figure(
    heights: npt.NDArray[np.float64], size_x: float, size_y: float, metres: bool, name: str,
) -> str: ...
def contact_map_figure(
    set: npt.NDArray[np.bool_], size_x: float, size_y: float, metres: bool, name: str,
) -> str: ...
def psd_figure(
    q: List[float], psd: List[float], size: float, ndim: int,
    range: Optional[Tuple[float, float]], fit: Optional[Tuple[float, float]],
    hurst: Optional[float], name: str,
) -> str: ...
def compare_study(dir: str, force: bool) -> List[str]: ...
def analysis_figure(
    analysis: str, x: List[float], y: List[float], metres: bool, name: str,
) -> str: ...
def contact_figure(
    force: List[float], stiffness: List[float], area: List[float], mean_gap: List[float],
    modulus: float, name: str,
) -> str: ...
