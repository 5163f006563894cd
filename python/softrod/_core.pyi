"""Type stubs of the compiled core ``softrod._core`` (checked against the module by the tests)."""

from collections.abc import Callable, Sequence
from typing import Any, Literal, final

import numpy as np
from numpy.typing import NDArray

__version__: str

_Floats = float | Sequence[float] | NDArray[np.float64]
_Method = Literal["closed-form", "ode"]

#: Limits on input sizes and magnitudes (``softrod::limits``; see docs/conventions.md).
MAX_SAMPLES: int
MAX_ITERATIONS: int
MAX_LOAD_NUMBER: float
MAX_LENGTH: float
MAX_MODULUS: float
MAX_BENDING_ANGLE: float
MAX_OFFSET_RATIO: float
MAX_STARTS: int
MAX_FRICTION: float
MAX_MODULUS: float

class ParameterError(ValueError):
    """A parameter is outside its valid range; ``parameter`` names it."""

    parameter: str

class ParameterTypeError(ParameterError, TypeError):
    """An argument of the wrong type or shape; ``parameter`` names it."""

class ConvergenceError(RuntimeError):
    """A solver or integrator did not converge."""

    iterations: int
    residual: float
    load_factor: float

class TargetUnreachableError(ConvergenceError):
    """Inverse statics: the target is out of reach within the actuation bounds."""

    distance: float
    rotation: float

class StabilityWarning(UserWarning):
    """The equilibrium returned is unstable (its tip tangent stiffness, in N/m and N m/rad,
    is not positive definite) and no stable one was found; see
    ``StaticsSolution.stability_margin`` and docs/stability.md."""

class StabilityError(RuntimeError):
    """The equilibrium reached is unstable (``on_unstable="raise"``); carries
    ``stability_margin`` (dimensionless: the tip tangent stiffness per EI(0)/L, EI in N m^2,
    L in m) and the unstable ``solution``."""

    stability_margin: float
    solution: StaticsSolution

class InternalError(RuntimeError):
    """A defect of softrod caught at the binding (never bad input); please report it."""

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
    """The planar cable-arm paper's tapered cable-driven arm (immutable, validated)."""

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
    def published_arm() -> PlanarCableArm: ...
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
    def sensitivities(self, tension: float, s: _Floats) -> dict[str, Any]: ...

def backbone_distance(
    a: NDArray[np.float64], b: NDArray[np.float64], n_index: int | None = None
) -> dict[str, object]: ...

# ----------------------------------------------------------------------------- statics

_Vec3 = Sequence[float] | NDArray[np.float64]
_VecFn = Callable[[float], _Vec3]

class Section:
    """A rod's cross-section along its length."""

    def properties(self, s: float, length: float) -> dict[str, float]: ...
    @property
    def parameters(self) -> dict[str, object]:
        """The constructor arguments by name, as given (what a writer needs)."""

@final
class CircularSection(Section):
    """Solid circle of constant radius (m)."""

    def __init__(self, radius: float) -> None: ...
    @property
    def radius(self) -> float: ...

@final
class TaperedCircularSection(Section):
    """Solid circle tapering linearly from base_radius to tip_radius (m)."""

    def __init__(self, base_radius: float, tip_radius: float) -> None: ...
    @property
    def base_radius(self) -> float: ...
    @property
    def tip_radius(self) -> float: ...

@final
class TubeSection(Section):
    """Circular tube (m)."""

    def __init__(self, outer_radius: float, inner_radius: float = 0.0) -> None: ...
    @property
    def outer_radius(self) -> float: ...
    @property
    def inner_radius(self) -> float: ...

@final
class TableSection(Section):
    """Section tables over s (m): area (m^2), ix, iy, j (m^4)."""

    def __init__(
        self,
        s: Sequence[float],
        area: Sequence[float],
        ix: Sequence[float],
        iy: Sequence[float],
        j: Sequence[float],
    ) -> None: ...

@final
class FunctionSection(Section):
    """Section from a function s -> (area, ix, iy, j)."""

    def __init__(self, function: Callable[[float], Sequence[float]]) -> None: ...

@final
class LinearElastic:
    """Linear elastic material: E (Pa) and Poisson's ratio, or the shear modulus (Pa)."""

    def __init__(
        self,
        youngs_modulus: float,
        poisson_ratio: float | None = None,
        *,
        shear_modulus: float | None = None,
    ) -> None: ...
    @property
    def youngs_modulus(self) -> float: ...
    @property
    def shear_modulus(self) -> float: ...
    @property
    def poisson_ratio(self) -> float: ...

@final
class Rod:
    """A Cosserat rod (immutable)."""

    def __init__(
        self,
        length: float,
        section: Section,
        material: LinearElastic | UniaxialLaw,
        rest_strain: _Vec3 | _VecFn | None = None,
        rest_curvature: _Vec3 | _VecFn | None = None,
        inextensible: bool = False,
        density: float | None = None,
        base_pose: NDArray[np.float64]
        | Sequence[Sequence[float]]
        | tuple[_Vec3, object]
        | None = None,
        *,
        shear_coefficient: float | None = None,
    ) -> None: ...
    @property
    def length(self) -> float: ...
    @property
    def section(self) -> Section:
        """The section, as given."""
    @property
    def material(self) -> LinearElastic | UniaxialLaw:
        """The material, as given."""
    @property
    def rest_strain(self) -> _Vec3 | _VecFn | None:
        """The rest strain as given (None: (0, 0, 1))."""
    @property
    def rest_curvature(self) -> _Vec3 | _VecFn | None:
        """The rest curvature as given (None: zero)."""
    @property
    def inextensible(self) -> bool: ...
    @property
    def density(self) -> float | None: ...
    @property
    def shear_coefficient(self) -> float:
        """The shear coefficient in use (the one given, or Cowper's value)."""
    @property
    def shear_coefficient_given(self) -> float | None:
        """The shear coefficient as given (None: Cowper's value)."""
    @property
    def base_pose(self) -> NDArray[np.float64]:
        """Base pose, 4x4 homogeneous transform (body at s = 0 to world)."""

@final
class Tendon:
    """A tendon: body-frame offset (m), tension (N), end arc length (m)."""

    def __init__(
        self,
        offset: Sequence[float] | Callable[[float], Sequence[float]],
        tension: float,
        end: float | None = None,
        *,
        derivative: Callable[[float], Sequence[float]] | None = None,
        friction: float = 0.0,
        guides: Sequence[float] | None = None,
        guide_friction: float | Sequence[float] | None = None,
    ) -> None: ...
    @staticmethod
    def radius_proportional(
        ratio: float,
        angle: float,
        tension: float,
        end: float | None = None,
        *,
        friction: float = 0.0,
    ) -> Tendon: ...
    @staticmethod
    def helical(
        radius: float,
        pitch: float,
        tension: float,
        phase: float = 0.0,
        end: float | None = None,
        *,
        friction: float = 0.0,
    ) -> Tendon: ...
    def with_tension(self, tension: float) -> Tendon: ...
    @property
    def tension(self) -> float: ...
    @property
    def end(self) -> float | None: ...
    @property
    def friction(self) -> float:
        """Friction coefficient between the tendon and its channel (>= 0)."""
    @property
    def guides(self) -> list[float]:
        """Arc lengths (m) of the guides the tendon runs through; empty: a continuous channel."""
    @property
    def guide_friction(self) -> list[float]:
        """Capstan coefficient at each guide."""
    @property
    def routing(self) -> Literal["constant", "function", "radius_proportional", "helical"]: ...
    @property
    def parameters(self) -> dict[str, object]:
        """The routing's parameters as given (offset and derivative; ratio and angle; radius,
        pitch and phase), with tension and end."""

@final
class PointLoad:
    """A force (N) and moment (N m) at arc length s (m)."""

    def __init__(
        self,
        s: float,
        force: _Vec3 | None = None,
        moment: _Vec3 | None = None,
        frame: Literal["world", "body"] = "world",
    ) -> None: ...
    @property
    def s(self) -> float: ...
    @property
    def force(self) -> list[float]: ...
    @property
    def moment(self) -> list[float]: ...
    @property
    def frame(self) -> Literal["world", "body"]: ...

@final
class Loads:
    """External loads (world frame unless told otherwise)."""

    def __init__(
        self,
        tip_force: _Vec3 | None = None,
        tip_moment: _Vec3 | None = None,
        gravity: _Vec3 | None = None,
        *,
        tip_frame: Literal["world", "body"] = "world",
        point_loads: Sequence[PointLoad] = ...,
        distributed_force: _Vec3 | _VecFn | None = None,
        distributed_moment: _Vec3 | _VecFn | None = None,
    ) -> None: ...
    @property
    def tip_force(self) -> list[float]: ...
    @property
    def tip_moment(self) -> list[float]: ...
    @property
    def gravity(self) -> list[float]: ...
    @property
    def tip_frame(self) -> Literal["world", "body"]: ...
    @property
    def point_loads(self) -> list[PointLoad]: ...
    @property
    def distributed_force(self) -> _Vec3 | _VecFn | None: ...
    @property
    def distributed_moment(self) -> _Vec3 | _VecFn | None: ...

@final
class StaticsSolution:
    """A solved rod sampled at the integration mesh (SI, world frame unless _body)."""

    @property
    def s(self) -> NDArray[np.float64]: ...
    @property
    def position(self) -> NDArray[np.float64]: ...
    @property
    def rotation(self) -> NDArray[np.float64]: ...
    @property
    def quaternion(self) -> NDArray[np.float64]: ...
    @property
    def force(self) -> NDArray[np.float64]: ...
    @property
    def moment(self) -> NDArray[np.float64]: ...
    @property
    def force_body(self) -> NDArray[np.float64]: ...
    @property
    def moment_body(self) -> NDArray[np.float64]: ...
    @property
    def v(self) -> NDArray[np.float64]: ...
    @property
    def u(self) -> NDArray[np.float64]: ...
    @property
    def tendon_lengths(self) -> NDArray[np.float64]: ...
    @property
    def tendon_tension(self) -> NDArray[np.float64]:
        """Tension (N) along each tendon at every sample, shape (N, n_tendons)."""
    @property
    def friction_force(self) -> NDArray[np.float64]:
        """Friction force on the rod (N/m, world), shape (N, n_tendons, 3)."""
    @property
    def slip(self) -> NDArray[np.int8]:
        """+1 sliding toward the base, -1 toward the tip, 0 sticking; (N, n_tendons)."""
    @property
    def frictional(self) -> bool: ...
    @property
    def guides(self) -> list[list[dict[str, Any]]]:
        """Per tendon through guides, the state at its anchors (base hole, guides, termination)."""
    @property
    def friction_iterations(self) -> int: ...
    @property
    def path_length(self) -> NDArray[np.float64] | None:
        """Path length (m) of each tendon from the base to every sample, (N, n_tendons);
        None without friction."""
    @property
    def contacts(self) -> list[dict[str, Any]]:
        """Active contacts: obstacle, s (m), length (m), point, normal, normal_force (N),
        tangential_force (N), state ("frictionless", "stick" or "slide")."""
    @property
    def contact_force(self) -> NDArray[np.float64]:
        """Contact force on the rod at every sample (N, world), shape (N, 3)."""
    @property
    def tip_reaction(self) -> NDArray[np.float64] | None:
        """Reaction wrench of the tip constraint (N, N m; world), shape (6,)."""
    @property
    def contact_compliance(self) -> NDArray[np.float64] | None:
        """Tip compliance with the active contacts and the tip constraint as constraints,
        [dp; dtheta] per [dF; dM] (world), shape (6, 6); None without obstacles and tip
        constraint, when not converged, or with a belt (not linearised)."""
    @property
    def tendon_tensions(self) -> NDArray[np.float64]: ...
    @property
    def tendon_displacements(self) -> NDArray[np.float64]: ...
    @property
    def base_wrench(self) -> NDArray[np.float64]: ...
    @property
    def stable(self) -> bool | None:
        """Whether the equilibrium is stable (tip tangent stiffness positive definite; with
        obstacles and a free tip, frictionless point contacts held); None: not assessed (a
        tendon pulling through disk guides)."""
    @property
    def stability_margin(self) -> float:
        """Smallest eigenvalue of the scaled tip tangent stiffness (> 0: stable; NaN: not
        converged or not assessed)."""
    @property
    def tensions(self) -> NDArray[np.float64]:
        """Tendon tensions it was solved for (N), shape (n_tendons,)."""
    @property
    def pressures(self) -> NDArray[np.float64]:
        """Chamber pressures it was solved for (Pa), shape (n_chambers,)."""
    @property
    def tip_position(self) -> NDArray[np.float64]: ...
    @property
    def tip_rotation(self) -> NDArray[np.float64]: ...
    @property
    def converged(self) -> bool: ...
    def sensitivities(
        self, parameters: Sequence[str], nodes: Sequence[int] | None = None
    ) -> dict[str, Any]:
        """Exact derivatives of the equilibrium (pose per unit of each parameter, world)."""
    @property
    def steps(self) -> int | None:
        """RK4 steps of the mesh solved on (a refined default solve: its finer mesh); None
        with the adaptive integrator."""
    @property
    def stats(self) -> dict[str, float | int | bool]: ...
    def __len__(self) -> int: ...

def solve_statics(
    rod: Rod,
    tendons: Sequence[Tendon] = ...,
    loads: Loads | None = None,
    *,
    integrator: Literal["rk4", "adaptive"] | None = None,
    steps: int | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    continuation: bool | None = None,
    max_load_steps: int | None = None,
    warm_start: StaticsSolution | Sequence[float] | None = None,
    throw: bool | None = None,
    chambers: Sequence[Chamber] = ...,
    s_out: Sequence[float] | NDArray[np.float64] | None = None,
    seek_stable: bool | None = None,
    on_unstable: Literal["warn", "raise", "ignore"] | None = None,
    previous: StaticsSolution | None = None,
    displacements: Sequence[float | None] | NDArray[np.float64] | None = None,
    tendon_stiffness: float | Sequence[float] | NDArray[np.float64] | None = None,
    obstacles: Sequence[Any] | None = None,
    tip_constraint: Any = None,
) -> StaticsSolution:
    """Options not given keep the core's defaults: integrator "rk4" with 40 steps (rtol 1e-8,
    atol 1e-10 for "adaptive"), tolerance 1e-10, max_iterations 30, continuation True,
    max_load_steps 64, throw True, seek_stable True, on_unstable "warn". ``s_out`` (m) adds
    nodes at those arc lengths. ``displacements`` (m, one per tendon, None: tension control)
    holds tendons at a shortening of their path; ``tendon_stiffness`` (N/m) their stiffness.
    ``obstacles`` (``softrod.Plane``, ``Sphere``, ``Capsule``, ``Cylinder``, ``Mesh``) are touched
    by the rod's surface, with the Coulomb coefficient ``friction`` of each at point contacts
    (at the tip or inside the rod; a plane with friction the rod lies along raises a
    ``ValueError`` naming ``friction``); ``tip_constraint`` (``softrod.Clamp(pose)``,
    ``Pin(point)``, ``Slide(point, normal)``) holds the tip."""

@final
class _RobotModel:
    """The validated core model of a robot's objects, built once by ``softrod.Robot`` and
    shared by its solves; the objects' tensions and pressures are its default actuation."""

    def __init__(
        self,
        rod: Rod,
        tendons: Sequence[Tendon] = ...,
        loads: Loads | None = None,
        chambers: Sequence[Chamber] = ...,
    ) -> None: ...

def _solve_robot(
    model: _RobotModel,
    tensions: _Floats | None = None,
    pressures: _Floats | None = None,
    *,
    integrator: Literal["rk4", "adaptive"] | None = None,
    steps: int | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    continuation: bool | None = None,
    max_load_steps: int | None = None,
    warm_start: StaticsSolution | Sequence[float] | None = None,
    throw: bool | None = None,
    s_out: Sequence[float] | NDArray[np.float64] | None = None,
    seek_stable: bool | None = None,
    on_unstable: Literal["warn", "raise", "ignore"] | None = None,
    previous: StaticsSolution | None = None,
    displacements: Sequence[float | None] | NDArray[np.float64] | None = None,
    tendon_stiffness: float | Sequence[float] | NDArray[np.float64] | None = None,
    obstacles: Sequence[Any] | None = None,
    tip_constraint: Any = None,
) -> StaticsSolution:
    """``solve_statics`` of a robot's model under tensions (N) and pressures (Pa), default
    its objects' (``Robot.solve`` wraps it)."""

def _inverse_statics(
    rod: Rod,
    tendons: Sequence[Tendon],
    loads: Loads | None,
    chambers: Sequence[Chamber],
    target_position: _Vec3,
    *,
    target_rotation: Sequence[Sequence[float]] | NDArray[np.float64] | None = None,
    target_s: Sequence[float] | NDArray[np.float64] | None = None,
    weights: Sequence[float] | NDArray[np.float64] | None = None,
    tension_bounds: tuple[float, float | None] | None = None,
    pressure_bounds: tuple[float, float | None] | None = None,
    warm_start: Sequence[float] | NDArray[np.float64] | None = None,
    throw: bool = True,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    integrator: Literal["rk4", "adaptive"] | None = None,
    steps: int | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    warm_state: _InverseWarmState | None = None,
    same_model: bool = False,
    obstacles: Sequence[Any] | None = None,
    starts: int | Sequence[Sequence[float]] | NDArray[np.float64] | None = None,
) -> dict[str, Any]:
    """Inverse statics of a tip target (softrod.inverse_statics wraps it)."""

class _InverseWarmState:
    """What an inverse result hands to the next call (opaque): its actuation, last evaluation
    and Lagrangian Hessian."""

def _pcc_inverse_statics(
    robot: PccRobot,
    target_position: _Vec3,
    *,
    target_rotation: Sequence[Sequence[float]] | NDArray[np.float64] | None = None,
    weights: Sequence[float] | NDArray[np.float64] | None = None,
    tension_bounds: tuple[float, float | None] | None = None,
    pressure_bounds: tuple[float, float | None] | None = None,
    tip_force: _Vec3 | None = None,
    tip_moment: _Vec3 | None = None,
    warm_start: Sequence[float] | NDArray[np.float64] | None = None,
    throw: bool = True,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    warm_state: _InverseWarmState | None = None,
    same_model: bool = False,
    starts: int | Sequence[Sequence[float]] | NDArray[np.float64] | None = None,
) -> dict[str, Any]:
    """Inverse statics of a PCC robot (softrod.pcc.inverse_statics wraps it)."""

def actuation_jacobian(
    solution: StaticsSolution | PccSolution,
    node: int = ...,
    direction: int | Literal["pull", "load", "release", "unload"] | None = ...,
) -> NDArray[np.float64]:
    """d[δp; δθ] (world; m, rad) of node ``node`` / d(tensions (N), pressures (Pa)),
    shape (6, n_tendons + n_chambers); exact (linearised boundary-value problem).

    For a frictional equilibrium the derivative is one-sided: ``direction=1`` ("pull" or
    "load", default) for increasing inputs continued from the solution (``previous=solution``),
    ``-1`` ("release" or "unload") for decreasing ones, the column ``(f(a) - f(a - h e)) / h``; the
    release column of a slack tendon is zero. Other solutions: both directions agree.

    For a solution with active contacts or a tip constraint, the active contacts and the held
    tip directions are constraints (their reactions move with the actuation; the active set
    held): frictionless contacts keep their gap, the held directions hold; derivative at the
    node's undeformed arc length. A solution with a sticking or sliding contact raises
    ParameterError naming ``solution``."""

# ----------------------------------------------------------------------------- materials

_Values = float | Sequence[float] | NDArray[np.float64]
_Out = float | NDArray[np.float64]

SILICONES: tuple[str, ...]

class UniaxialLaw:
    """Incompressible uniaxial law: stress (Pa) from stretch; 0-d in -> float, array -> array."""

    def nominal_stress(self, stretch: _Values) -> _Out: ...
    def true_stress(self, stretch: _Values) -> _Out: ...
    def tangent_modulus(self, strain: _Values) -> _Out: ...
    def nominal_tangent(self, stretch: _Values) -> _Out: ...
    def stretch_from_nominal_stress(self, nominal_stress: _Values) -> _Out: ...
    def check_stable(self, stretch_min: float, stretch_max: float) -> None: ...
    @property
    def small_strain_modulus(self) -> float: ...
    @property
    def model_name(self) -> str: ...
    @property
    def parameters(self) -> dict[str, float | list[float]]: ...

@final
class Hookean(UniaxialLaw):
    """Linear law P = E (stretch - 1), E in Pa."""

    def __init__(self, youngs_modulus: float) -> None: ...
    @property
    def youngs_modulus(self) -> float: ...

@final
class Linearised(UniaxialLaw):
    """Linear law through the origin with a secant modulus (Pa) taken at reference_strain."""

    def __init__(self, secant_modulus: float, reference_strain: float) -> None: ...
    @staticmethod
    def from_secant_point(nominal_stress: float, strain: float) -> Linearised: ...
    @property
    def secant_modulus(self) -> float: ...
    @property
    def reference_strain(self) -> float: ...

@final
class NeoHookean(UniaxialLaw):
    """Neo-Hookean law with initial shear modulus mu (Pa)."""

    def __init__(self, mu: float) -> None: ...
    @property
    def mu(self) -> float: ...

@final
class MooneyRivlin(UniaxialLaw):
    """Two-parameter Mooney-Rivlin law, c10 and c01 in Pa."""

    def __init__(self, c10: float, c01: float) -> None: ...
    @property
    def c10(self) -> float: ...
    @property
    def c01(self) -> float: ...

@final
class Yeoh(UniaxialLaw):
    """Yeoh law, c10 > 0, c20, c30 in Pa."""

    def __init__(self, c10: float, c20: float = 0.0, c30: float = 0.0) -> None: ...
    @property
    def c10(self) -> float: ...
    @property
    def c20(self) -> float: ...
    @property
    def c30(self) -> float: ...

@final
class Ogden(UniaxialLaw):
    """N-term Ogden law: moduli mu (Pa) and exponents alpha, shape (N,) each."""

    def __init__(
        self,
        mu: Sequence[float] | NDArray[np.float64],
        alpha: Sequence[float] | NDArray[np.float64],
    ) -> None: ...
    @property
    def mu(self) -> list[float]: ...
    @property
    def alpha(self) -> list[float]: ...

@final
class UniaxialFit:
    """A fitted law and its error on the fitted points (Pa, in the data's stress measure)."""

    @property
    def model(self) -> UniaxialLaw: ...
    @property
    def parameters(self) -> dict[str, float | list[float]]: ...
    @property
    def rms(self) -> float: ...
    @property
    def r_squared(self) -> float: ...
    @property
    def max_abs_residual(self) -> float: ...
    @property
    def points(self) -> int: ...
    @property
    def iterations(self) -> int: ...
    @property
    def stress_measure(self) -> Literal["nominal", "true"]: ...
    @property
    def stretch_range(self) -> tuple[float, float]: ...

@final
class Silicone:
    """A named silicone with sourced parameters."""

    @property
    def name(self) -> str: ...
    @property
    def neo_hookean(self) -> NeoHookean: ...
    @property
    def mooney_rivlin(self) -> MooneyRivlin | None: ...
    @property
    def yeoh(self) -> Yeoh: ...
    @property
    def fit_stretch_range(self) -> tuple[float, float] | None: ...
    @property
    def source(self) -> str: ...

def fit_uniaxial(
    strain: Sequence[float] | NDArray[np.float64],
    stress: Sequence[float] | NDArray[np.float64],
    model: Literal["neo-hookean", "mooney-rivlin", "yeoh", "ogden", "linearised"] = "neo-hookean",
    *,
    strain_measure: Literal["engineering", "stretch", "logarithmic"] = "engineering",
    stress_measure: Literal["nominal", "engineering", "true"] = "nominal",
    terms: int | None = None,
    nonnegative: bool = False,
    stretch_range: tuple[float, float] | None = None,
    max_iterations: int | None = None,
    tolerance: float | None = None,
) -> UniaxialFit: ...
def silicone(name: str) -> Silicone: ...

# ----------------------------------------------------------------------------- PCC (softrod.pcc)

_Frame = Literal["spatial", "body", "hybrid"]
_Coordinates = Literal["arc", "curvature_vector"]
_Rows = Sequence[Sequence[float]] | NDArray[np.float64]

@final
class PccRobot:
    """A PCC robot (immutable): elastic segments base to tip, routed tendons, chambers."""

    def __new__(
        cls,
        rest_lengths: _Floats,
        bending_stiffness: _Floats,
        axial_stiffness: _Floats | None = None,
    ) -> PccRobot: ...
    @staticmethod
    def solid_circle(
        rest_lengths: _Floats, radius: float, youngs_modulus: float, *, extensible: bool = True
    ) -> PccRobot: ...
    def with_tendons(self, segment: int, distances: _Floats, angles: _Floats) -> PccRobot: ...
    def with_chambers(
        self, segment: int, areas: _Floats, distances: _Floats, angles: _Floats
    ) -> PccRobot: ...
    @property
    def n_segments(self) -> int: ...
    @property
    def n_tendons(self) -> int: ...
    @property
    def n_chambers(self) -> int: ...
    @property
    def rest_lengths(self) -> NDArray[np.float64]: ...
    @property
    def bending_stiffness(self) -> NDArray[np.float64]: ...
    @property
    def axial_stiffness(self) -> list[float | None]: ...
    @property
    def tendons(self) -> NDArray[np.float64]: ...
    @property
    def chambers(self) -> list[tuple[int, list[float], list[float], list[float]]]:
        """Chamber groups as (segment, areas, distances, angles)."""

@final
class PccSolution:
    """A solved PCC robot: arcs, tip pose, backbone frames (SI units)."""

    @property
    def arcs(self) -> NDArray[np.float64]: ...
    @property
    def coordinates(self) -> NDArray[np.float64]: ...
    @property
    def tip_pose(self) -> NDArray[np.float64]: ...
    @property
    def tip_position(self) -> NDArray[np.float64]: ...
    @property
    def s(self) -> NDArray[np.float64]: ...
    @property
    def frames(self) -> NDArray[np.float64]: ...
    @property
    def positions(self) -> NDArray[np.float64]: ...
    @property
    def tendon_lengths(self) -> NDArray[np.float64]: ...
    @property
    def iterations(self) -> int: ...
    @property
    def residual(self) -> float: ...
    @property
    def converged(self) -> bool: ...
    @property
    def load_steps(self) -> int: ...
    @property
    def load_factor(self) -> float: ...
    @property
    def stats(self) -> dict[str, float | int | bool]: ...
    def frames_at(self, s: _Floats) -> NDArray[np.float64]: ...

def pcc_solve(
    robot: PccRobot,
    tensions: _Floats | None = None,
    pressures: _Floats | None = None,
    *,
    tip_force: _Floats | None = None,
    tip_moment: _Floats | None = None,
    s: _Floats | None = None,
    n_points: int | None = None,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    continuation: bool | None = None,
    max_load_steps: int | None = None,
    warm_start: PccSolution | _Rows | None = None,
    throw: bool | None = None,
) -> PccSolution:
    """Options not given keep the core's defaults: 50 frames, tolerance 1e-12,
    max_iterations 50, continuation True, max_load_steps 64, throw True."""

def pcc_arc_pose(curvature: float, plane_angle: float, length: float) -> NDArray[np.float64]: ...
def pcc_arc_poses(curvature: _Floats, plane_angle: _Floats, length: _Floats) -> NDArray[np.float64]:
    """Tip poses (N, 4, 4) of N arcs in one call (a number is repeated)."""

def pcc_arc_frames(
    curvature: float, plane_angle: float, length: float, s: _Floats
) -> NDArray[np.float64]: ...
def pcc_arc_jacobian(
    curvature: float,
    plane_angle: float,
    length: float,
    *,
    frame: _Frame = "spatial",
    coordinates: _Coordinates = "arc",
) -> NDArray[np.float64]: ...
def pcc_chain_pose(segments: _Rows) -> NDArray[np.float64]: ...
def pcc_chain_frames(segments: _Rows, s: _Floats) -> NDArray[np.float64]: ...
def pcc_chain_jacobian(
    segments: _Rows, *, frame: _Frame = "spatial", coordinates: _Coordinates = "arc"
) -> NDArray[np.float64]: ...
def pcc_arc_from_tip(position: _Floats) -> NDArray[np.float64]: ...
def pcc_arc_from_tip_with_length(
    position: _Floats, length: float
) -> tuple[NDArray[np.float64], float]: ...
def pcc_tendon_displacements(
    arc: _Floats, distances: _Floats, angles: _Floats, rest_length: float | None = None
) -> NDArray[np.float64]: ...
def pcc_tendon_displacement_jacobian(
    arc: _Floats, distances: _Floats, angles: _Floats, *, coordinates: _Coordinates = "arc"
) -> NDArray[np.float64]: ...
def pcc_arc_from_tendon_displacements(
    displacements: _Floats,
    distances: _Floats,
    angles: _Floats,
    rest_length: float,
    *,
    extensible: bool = True,
) -> NDArray[np.float64]: ...
def pcc_tendon_displacement_misfit(
    displacements: _Floats,
    distances: _Floats,
    angles: _Floats,
    rest_length: float,
    *,
    extensible: bool = True,
) -> NDArray[np.float64]: ...
def pcc_arc_from_tendon_displacements_jacobian(
    displacements: _Floats,
    distances: _Floats,
    angles: _Floats,
    rest_length: float,
    *,
    extensible: bool = True,
    coordinates: _Coordinates = "arc",
) -> NDArray[np.float64]: ...
def pcc_arc_from_tendon_tensions(
    tensions: _Floats,
    distances: _Floats,
    angles: _Floats,
    rest_length: float,
    bending_stiffness: float,
    axial_stiffness: float | None = None,
) -> NDArray[np.float64]: ...
def pcc_arc_from_tendon_tensions_jacobian(
    tensions: _Floats,
    distances: _Floats,
    angles: _Floats,
    rest_length: float,
    bending_stiffness: float,
    axial_stiffness: float | None = None,
    *,
    coordinates: _Coordinates = "arc",
) -> NDArray[np.float64]: ...
def pcc_arc_from_pressures(
    pressures: _Floats,
    areas: _Floats,
    distances: _Floats,
    angles: _Floats,
    rest_length: float,
    bending_stiffness: float,
    axial_stiffness: float | None = None,
) -> NDArray[np.float64]: ...
def pcc_arc_from_pressures_jacobian(
    pressures: _Floats,
    areas: _Floats,
    distances: _Floats,
    angles: _Floats,
    rest_length: float,
    bending_stiffness: float,
    axial_stiffness: float | None = None,
    *,
    coordinates: _Coordinates = "arc",
) -> NDArray[np.float64]: ...

# ------------------------------------------------------------------ compliance (issue 4)

@final
class Compliance:
    """Integrated compliance and stiffness at every node (twists [translation; rotation],
    wrenches [force; moment], wrench applied at the node)."""

    @property
    def s(self) -> NDArray[np.float64]: ...
    @property
    def element(self) -> NDArray[np.float64]: ...
    @property
    def world(self) -> NDArray[np.float64]: ...
    @property
    def body(self) -> NDArray[np.float64]: ...
    @property
    def stiffness_world(self) -> NDArray[np.float64]: ...
    @property
    def stiffness_body(self) -> NDArray[np.float64]: ...
    @property
    def condition(self) -> NDArray[np.float64]: ...
    @property
    def gamma_c(self) -> NDArray[np.float64]: ...
    @property
    def tip_world(self) -> NDArray[np.float64]: ...
    @property
    def tip_body(self) -> NDArray[np.float64]: ...
    @property
    def tip_stiffness_world(self) -> NDArray[np.float64]: ...
    @property
    def tip_stiffness_body(self) -> NDArray[np.float64]: ...
    @property
    def tip_condition(self) -> float: ...
    def __len__(self) -> int: ...

@final
class TangentCompliance:
    """Exact tangent compliance of a loaded, actuated equilibrium at one node."""

    @property
    def node(self) -> int: ...
    @property
    def s(self) -> float: ...
    @property
    def world(self) -> NDArray[np.float64]: ...
    @property
    def body(self) -> NDArray[np.float64]: ...
    @property
    def stiffness_world(self) -> NDArray[np.float64]: ...
    @property
    def stiffness_body(self) -> NDArray[np.float64]: ...
    @property
    def condition(self) -> float: ...
    @property
    def symmetric(self) -> bool: ...
    @property
    def tension_rate(self) -> NDArray[np.float64]: ...
    @property
    def tendons(self) -> str: ...

@final
class Eigenscrews:
    """Eigenscrew decomposition of a 6x6 stiffness or compliance, with compliance ellipsoids."""

    @property
    def values(self) -> NDArray[np.float64]: ...
    @property
    def vectors(self) -> NDArray[np.float64]: ...
    @property
    def directions(self) -> NDArray[np.float64]: ...
    @property
    def points(self) -> NDArray[np.float64]: ...
    @property
    def pitches(self) -> NDArray[np.float64]: ...
    @property
    def translational_axes(self) -> NDArray[np.float64]: ...
    @property
    def translational_directions(self) -> NDArray[np.float64]: ...
    @property
    def rotational_axes(self) -> NDArray[np.float64]: ...
    @property
    def rotational_directions(self) -> NDArray[np.float64]: ...
    @property
    def kind(self) -> str: ...

def compliance(
    solution: StaticsSolution | PccSolution,
    rod: Rod | None = None,
    *,
    panels: int | None = None,
    s_out: Sequence[float] | NDArray[np.float64] | None = None,
) -> Compliance: ...
def tangent_compliance(
    solution: StaticsSolution,
    tendons: Literal["tension", "length"] = "tension",
    *,
    held: Sequence[int] | None = None,
    node: int | None = None,
    direction: int | Literal["pull", "load", "release", "unload"] | None = None,
) -> TangentCompliance:
    """d[δp; δθ]/d[f; m] at ``node`` (default the tip), tendons at fixed "tension" or "length".

    For a frictional equilibrium the tip compliance at fixed base tensions is one-sided, the
    tension profile following the stick/slip rule continued from the solution:
    ``direction=1`` ("pull" or "load", default) for each wrench component increasing, ``-1``
    ("release" or "unload") for each decreasing, the column ``(f(0) - f(-h e_k)) / h``. At
    another node or with tendons="length" the profile is held fixed, on a disk-guided
    solution the guide forces (``direction`` must be None there). Frictionless solutions:
    both directions agree."""

def eigenscrews(
    matrix: NDArray[np.float64], kind: Literal["stiffness", "compliance"] = "stiffness"
) -> Eigenscrews: ...
def _workspace_map(
    rod: Rod,
    tendons: Sequence[Tendon],
    tensions: NDArray[np.float64],
    loads: Loads | None = None,
    *,
    integrator: Literal["rk4", "adaptive"] | None = None,
    steps: int | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    tolerance: float | None = None,
    chunk: int = 64,
    tangent: Literal["tension", "length"] | None = None,
    chambers: Sequence[Chamber] = ...,
) -> dict[str, NDArray[np.float64]]: ...
def _sweep(
    jobs: Sequence[dict[str, Any]],
    *,
    outputs: Sequence[str],
    block: int = 32,
    parallel: bool = True,
) -> list[dict[str, Any]]:
    """Actuation sweeps of design points (used by ``softrod.sweep``): one dict of arrays per
    job (``status``: 0 converged, 1 not converged, 2 failed; ``error`` per sample)."""

# ----------------------------------------------------------------------------- chambers

@final
class Chamber:
    """A pneumatic chamber: gauge pressure (Pa), area (m^2), centroid offset (m), extent (m)."""

    def __init__(
        self,
        pressure: float,
        area: float | Callable[[float], float],
        offset: tuple[float, float] | Sequence[float],
        start: float = 0.0,
        end: float | None = None,
    ) -> None: ...
    def with_pressure(self, pressure: float) -> Chamber: ...
    @property
    def pressure(self) -> float: ...
    @property
    def area(self) -> float | Callable[[float], float]:
        """The area as given."""
    def area_at(self, s: float) -> float: ...
    @property
    def offset(self) -> tuple[float, float]: ...
    @property
    def start(self) -> float: ...
    @property
    def end(self) -> float | None: ...
