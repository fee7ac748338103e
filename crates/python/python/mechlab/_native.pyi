"""Type stubs of the extension module (see the package's docstring)."""

from typing import Any, Iterator, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

Axis = Union[int, str]
Params = Optional[dict[str, float]]

class Refused(ValueError):
    """The analysis does not apply to this model (the message says why)."""

class IntegrationError(RuntimeError):
    """The integrator could not follow an orbit (the message says where)."""

class Derivation:
    key: str
    description: str
    text: str
    latex: str
    def _repr_latex_(self) -> str: ...

class Derivations(Sequence[Derivation]):
    def __len__(self) -> int: ...
    def __getitem__(self, index: int) -> Derivation: ...  # type: ignore[override]
    def __iter__(self) -> Iterator[Derivation]: ...
    def _repr_latex_(self) -> str: ...

class Model:
    name: str
    kind: str
    fast_phase: bool
    coordinates: list[str]
    state_names: list[str]
    constraints: list[str]
    parameters: dict[str, float]
    ranges: dict[str, str]
    descriptions: dict[str, str]
    amplitude: Optional[str]
    source: str
    source_file: str
    derivations: Derivations
    def values(self, params: Params = None) -> list[float]: ...
    def start(self, params: Params = None) -> NDArray[np.float64]: ...
    def energy(self, y: ArrayLike, t: float = 0.0, *, params: Params = None) -> float: ...
    def explore(self, y0: Optional[Sequence[float]] = None, *, t_end: float = 20.0,
                samples: int = 2000, periods: int = 300, method: str = "dop853",
                tol: float = 1e-10, params: Params = None) -> dict[str, Any]: ...
    def integrate(self, y0: ArrayLike, t: ArrayLike, *, method: str = "dop853",
                  tol: float = 1e-10, params: Params = None) -> NDArray[np.float64]: ...
    def integrate_many(self, y0: ArrayLike, t: ArrayLike, *, method: str = "dop853",
                       tol: float = 1e-10, params: Params = None) -> dict[str, Any]: ...
    def iterates(self, starts: ArrayLike, periods: int, *, transient: int = 0,
                 method: str = "taylor", tol: float = 1e-10,
                 params: Params = None) -> NDArray[np.float64]: ...
    def basins(self, *, axes: Optional[Tuple[Axis, Axis]] = None,
               ranges: Tuple[Tuple[float, float], Tuple[float, float]] = ((-2.0, 2.0), (-2.0, 2.0)),
               through: Optional[Sequence[float]] = None, pixels: int = 200,
               transient: int = 300, record: int = 16, cell: float = 0.05,
               stop_early: bool = True, method: str = "taylor", tol: float = 1e-10,
               params: Params = None, progress: bool = True) -> dict[str, Any]: ...
    def period_map(self, *, axes: Optional[Tuple[Axis, Axis]] = None,
                   seeds: Optional[Sequence[Sequence[float]]] = None, count: int = 24,
                   p_max: float = 2.5, periods: int = 500, method: str = "taylor",
                   tol: float = 1e-10, params: Params = None) -> dict[str, Any]: ...
    def chaos_map(self, *, pixels: int = 300, periods: int = 180,
                  axes: Optional[Tuple[Axis, Axis]] = None,
                  ranges: Optional[Tuple[Tuple[float, float], Tuple[float, float]]] = None,
                  through: Optional[Sequence[float]] = None, p_max: float = 3.0,
                  method: str = "taylor", tol: float = 1e-6, params: Params = None,
                  progress: bool = True) -> dict[str, Any]: ...
    def stability(self, *, amplitude: Optional[str] = None, samples: int = 40,
                  a_max: Optional[float] = None, edge_tolerance: float = 1e-9,
                  method: str = "dop853", tol: Optional[float] = None,
                  max_windows: Optional[int] = None, params: Params = None) -> dict[str, Any]: ...
    def attractor(self, *, start: Tuple[float, float] = (1.0, 0.0), transient: int = 500,
                  points: int = 200_000, lyapunov_periods: int = 16_000, pixels: int = 500,
                  method: str = "taylor", tol: float = 1e-10,
                  params: Params = None) -> dict[str, Any]: ...
    def continuation(self, *, parameter: Optional[str] = None, to: Optional[float] = None,
                     start: Optional[Sequence[float]] = None, period: int = 1,
                     max_period: int = 16, switch_branch_points: bool = True,
                     branches: int = 12, points: int = 3000, step: float = 0.005,
                     min_step: float = 1e-8, max_step: float = 0.02, diagram: int = 0,
                     transient: int = 300, iterates: int = 100,
                     chart: Optional[Sequence[int]] = None, method: str = "taylor",
                     tol: float = 1e-12, params: Params = None) -> dict[str, Any]: ...
    def separatrix_splitting(self, *, guess: Optional[Tuple[float, float]] = None,
                             spacing: float = 0.02, p_max: float = 4.0, iterates: int = 400,
                             max_points: int = 20_000, lobe_points: int = 400,
                             precision: str = "auto", method: str = "taylor",
                             tol: float = 1e-14, params: Params = None) -> dict[str, Any]: ...
    def averaging(self, *, parameter: Optional[str] = None,
                  values: Optional[Sequence[float]] = None,
                  y0: Optional[Sequence[float]] = None, t_obs: float = 2.0, order: int = 1,
                  method: str = "dop853", tol: float = 1e-11,
                  params: Params = None) -> dict[str, Any]: ...
    def megno_map(self, *, energy: float, plane: Optional[str] = None, value: float = 0.0,
                  rising: bool = True, pixels: int = 100, t_max: float = 2000.0,
                  extent: float = 2.0, tol: float = 1e-12,
                  params: Params = None) -> dict[str, Any]: ...
    def frequency_map(self, *, energy: float, plane: Optional[str] = None, value: float = 0.0,
                      rising: bool = True, pixels: int = 100, t_max: float = 2000.0,
                      samples: int = 4096, extent: float = 2.0, tol: float = 1e-12,
                      params: Params = None) -> dict[str, Any]: ...
    def period_map_frequencies(self, *, pixels: int = 100, periods: int = 1000,
                               axes: Optional[Tuple[Axis, Axis]] = None,
                               ranges: Optional[Tuple[Tuple[float, float], Tuple[float, float]]] = None,
                               through: Optional[Sequence[float]] = None, p_max: float = 3.0,
                               method: str = "taylor", tol: float = 1e-10, params: Params = None,
                               progress: bool = True) -> dict[str, Any]: ...
    def section(self, *, energy: float, plane: Optional[str] = None, value: float = 0.0,
                rising: bool = True, seeds: Optional[Sequence[Tuple[float, float]]] = None,
                orbits: int = 24, extent: float = 2.0, crossings: int = 400,
                t_max: float = 20000.0, tol: float = 1e-12,
                params: Params = None) -> dict[str, Any]: ...

def models() -> list[str]: ...
def model(name: str) -> Model: ...
