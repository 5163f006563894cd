"""Type stubs of the compiled core ``softrod._core`` (checked against the module by the tests)."""

from collections.abc import Sequence
from typing import Literal, final

import numpy as np
from numpy.typing import NDArray

__version__: str

_Floats = float | Sequence[float] | NDArray[np.float64]
_Method = Literal["closed-form", "ode"]

class ParameterError(ValueError):
    """A parameter is outside its valid range; ``parameter`` names it."""

    parameter: str

class ConvergenceError(RuntimeError):
    """A solver or integrator did not converge."""

    iterations: int
    residual: float

@final
class PlanarSolution:
    """Samples of one solved planar arm (SI units)."""

    @property
    def tension(self) -> float: ...
    @property
    def s(self) -> NDArray[np.float64]: ...
    @property
    def curvature(self) -> NDArray[np.float64]: ...
    @property
    def strain(self) -> NDArray[np.float64]: ...
    @property
    def angle(self) -> NDArray[np.float64]: ...
    @property
    def x(self) -> NDArray[np.float64]: ...
    @property
    def y(self) -> NDArray[np.float64]: ...
    @property
    def tip(self) -> NDArray[np.float64]: ...
    @property
    def tip_angle(self) -> float: ...
    @property
    def max_compressive_strain(self) -> float: ...
    @property
    def method(self) -> str: ...
    @property
    def stats(self) -> dict[str, int] | None: ...

@final
class PlanarBatch:
    """Many tensions on one set of samples; 2-D arrays are (n_tensions, n_samples)."""

    @property
    def tension(self) -> NDArray[np.float64]: ...
    @property
    def s(self) -> NDArray[np.float64]: ...
    @property
    def curvature(self) -> NDArray[np.float64]: ...
    @property
    def strain(self) -> NDArray[np.float64]: ...
    @property
    def angle(self) -> NDArray[np.float64]: ...
    @property
    def x(self) -> NDArray[np.float64]: ...
    @property
    def y(self) -> NDArray[np.float64]: ...
    @property
    def tip(self) -> NDArray[np.float64]: ...
    @property
    def tip_angle(self) -> NDArray[np.float64]: ...
    def __len__(self) -> int: ...

@final
class PlanarCableArm:
    """The seed-000 tapered cable-driven arm (immutable, validated)."""

    def __init__(
        self,
        length: float,
        base_radius: float,
        tip_radius: float,
        offset_ratio: float,
        youngs_modulus: float,
        anchor: float | None = None,
    ) -> None: ...
    @staticmethod
    def seed_arm() -> PlanarCableArm: ...
    @property
    def length(self) -> float: ...
    @property
    def base_radius(self) -> float: ...
    @property
    def tip_radius(self) -> float: ...
    @property
    def offset_ratio(self) -> float: ...
    @property
    def youngs_modulus(self) -> float: ...
    @property
    def anchor(self) -> float: ...
    @property
    def max_tension(self) -> float: ...
    def radius(self, s: _Floats) -> NDArray[np.float64]: ...
    def solve(
        self,
        tension: float,
        n_points: int = 201,
        *,
        s: _Floats | None = None,
        method: _Method = "closed-form",
        rtol: float = 1e-8,
        atol: float = 1e-10,
        max_steps: int = 100000,
    ) -> PlanarSolution: ...
    def solve_many(
        self,
        tensions: _Floats,
        n_points: int = 201,
        *,
        s: _Floats | None = None,
        method: _Method = "closed-form",
        rtol: float = 1e-8,
        atol: float = 1e-10,
        max_steps: int = 100000,
    ) -> PlanarBatch: ...

def backbone_distance(
    a: NDArray[np.float64], b: NDArray[np.float64], n_index: int | None = None
) -> dict[str, object]: ...
