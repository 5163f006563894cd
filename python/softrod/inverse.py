"""Inverse statics: the actuation that puts the tip of a robot at a target.

Objective (see ``docs/command.md``): among the actuations inside the bounds that reach the
target, the one of least weighted norm ``½ Σ w_i a_i²`` (default weights: 1/N² per tension and
A²/N² per chamber pressure of area A: the norm of the actuator forces), so that antagonistic
tendons do not pull against each other. Solved by sequential quadratic programming on the exact
actuation Jacobian; external loads and gravity are those of the robot. A robot with obstacles is
solved with the contact solve as the forward model and the actuation Jacobian with the active
contacts as constraints, so that a target may be reached with the arm resting on an obstacle
(tip targets, frictionless obstacles). A tip constraint, tendon friction or guides, and friction
at obstacles are refused (ParameterError naming ``robot``).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _args, _core
from .robot import Robot


@dataclass(frozen=True)
class InverseSolution:
    """The result of :func:`inverse_statics`.

    Attributes:
        tensions: Tendon tensions found (N), shape (n_tendons,).
        pressures: Chamber pressures found (Pa, gauge), shape (n_chambers,).
        solution: The forward statics solution at that actuation.
        position_error: Distance from the tip to the target (m; for a shape target, the
            largest distance of a backbone point to its target).
        rotation_error: Angle from the tip rotation to the target's (rad; 0 without one).
        iterations: Iterations of the SQP.
        converged: Whether the target was reached and the actuation is the minimum-norm one.
        reached: Whether the target was reached within the tolerance (with obstacles it may be
            reached without the minimum norm being certified: ``converged`` is then False).
        start: The start the answer came from (``starts``): 0 for the warm start or rest,
            ``k`` for the ``k``-th later one.
    """

    tensions: np.ndarray
    pressures: np.ndarray
    solution: Any
    position_error: float
    rotation_error: float
    iterations: int
    converged: bool
    reached: bool = False
    start: int = 0
    # What the next call warm-started from this one reuses (the last evaluation, with its
    # Jacobian, and the Lagrangian Hessian), and the model it belongs to.
    _warm_state: Any = field(default=None, repr=False, compare=False)
    _model_key: Any = field(default=None, repr=False, compare=False)

    @property
    def actuation(self) -> np.ndarray:
        """Tensions then pressures (N, Pa), the form ``warm_start`` takes."""
        return np.concatenate([self.tensions, self.pressures])

    def __getstate__(self) -> dict[str, Any]:
        # The reusable solver state lives in the extension and is not pickled: an unpickled
        # solution warm-starts from its actuation, as any other previous answer does.
        state = dict(self.__dict__)
        state["_solution"] = self.solution
        state["_warm_state"] = None
        state["_model_key"] = None
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        for k, v in state.items():
            object.__setattr__(self, k, v)


class _Deferred:
    """A forward solution made when it is first asked for (``InverseSolution.solution``)."""

    __slots__ = ("make",)

    def __init__(self, make: Any) -> None:
        self.make = make


def _get_solution(self: InverseSolution) -> Any:
    value = self.__dict__["_solution"]
    if isinstance(value, _Deferred):
        value = value.make()
        self.__dict__["_solution"] = value
    return value


def _set_solution(self: InverseSolution, value: Any) -> None:
    self.__dict__["_solution"] = value


# The forward solution at the actuation found is solved on first access (a tracking loop that
# reads only the actuation does not pay for it); it is the same solution either way.
InverseSolution.solution = property(  # type: ignore[assignment]
    _get_solution, _set_solution, doc="The forward statics solution at the actuation found."
)


def _warm_arguments(warm_start: Any, key: Any) -> tuple[Any, Any, bool]:
    """The actuation of a warm start, and for a previous :class:`InverseSolution` its state and
    whether it was made on the same model (``key``: the same object, or a tuple of the same
    objects, tuples among them equal)."""
    if not isinstance(warm_start, InverseSolution):
        return warm_start, None, False
    state = warm_start._warm_state
    if state is None:
        return warm_start.actuation, None, False
    # The state carries the actuation: the extension takes it from there.
    return None, state, _same_key(warm_start._model_key, key)


def _same_key(old: Any, key: Any) -> bool:
    if old is key:
        return True
    if not (isinstance(old, tuple) and isinstance(key, tuple) and len(old) == len(key)):
        return False
    for a, b in zip(old, key, strict=True):
        if not (a is b or (isinstance(a, tuple) and a == b)):
            return False
    return True


def _from_core(out: dict, solution: Any, warm_state: Any, key: Any) -> InverseSolution:
    """The :class:`InverseSolution` of an extension result ``out``, made without the
    dataclass initialiser (its values are already of the field types)."""
    obj = object.__new__(InverseSolution)
    obj.__dict__.update(
        tensions=out["tensions"],
        pressures=out["pressures"],
        _solution=solution,
        position_error=out["position_error"],
        rotation_error=out["rotation_error"],
        iterations=out["iterations"],
        converged=out["converged"],
        reached=out["reached"],
        start=out["start"],
        _warm_state=warm_state,
        _model_key=key,
    )
    return obj


def _model_key(robot: Robot) -> tuple:
    return (
        robot._rod,
        *robot._tendons,
        robot._loads,
        *robot._chambers,
        *robot._obstacles,
        tuple(sorted(robot.solver.items())),
    )


def _refuse_unsupported(robot: Robot, obstacles_supported: bool = False) -> None:
    """Raises ``ParameterError`` naming ``robot`` for what the inverse statics does not model
    (rather than solving without it and reporting the forward solution with it)."""
    why = None
    if robot.tip_constraint is not None:
        why = (
            f"a tip constraint ({type(robot.tip_constraint).__name__}): the inverse statics "
            "moves a free tip; solve the held robot with robot.solve"
        )
    elif any(t.friction > 0 or len(t.guides) > 0 for t in robot.tendons):
        i = next(k for k, t in enumerate(robot.tendons) if t.friction > 0 or len(t.guides))
        why = (
            f"tendon friction or disk guides (tendons[{i}]): the inverse statics is "
            "frictionless; give the tendons friction 0 and no guides"
        )
    elif robot.obstacles and not obstacles_supported:
        why = "obstacles with a shape target (target_s): the contact inverse aims at the tip"
    elif any(getattr(o, "friction", 0) for o in robot.obstacles):
        i = next(k for k, o in enumerate(robot.obstacles) if getattr(o, "friction", 0))
        why = (
            f"an obstacle with friction (obstacles[{i}]): the inverse statics with obstacles "
            "is frictionless; give the obstacles friction 0"
        )
    if why is not None:
        err = _core.ParameterError(f"invalid parameter `robot` = {robot.name!r}: {why}")
        err.parameter = "robot"
        raise err


def inverse_statics(
    robot: Robot,
    target_position: Sequence[float] | np.ndarray,
    *,
    target_rotation: Sequence[Sequence[float]] | np.ndarray | None = None,
    weights: Sequence[float] | np.ndarray | None = None,
    tension_bounds: tuple[float, float | None] = (0.0, None),
    pressure_bounds: tuple[float, float | None] | None = None,
    warm_start: InverseSolution | Sequence[float] | np.ndarray | None = None,
    throw: bool = True,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    target_s: Sequence[float] | np.ndarray | None = None,
    starts: int | Sequence[Sequence[float]] | np.ndarray | None = None,
) -> InverseSolution:
    """The minimum-norm actuation that puts the tip of ``robot`` at ``target_position``.

    Args:
        robot: The robot (:func:`softrod.load_robot` or built in code); its loads apply, and
            its obstacles (frictionless; tip targets only): the forward model is then the
            contact solve. A tip constraint, tendon friction or guides are refused.
        target_position: Tip position (m, world), shape (3,); with ``target_s``, a shape
            target: backbone points (m, world), shape (k, 3).
        target_rotation: Tip rotation (body -> world, 3x3), or None for a position target.
        weights: Weights of the actuation norm, one per tendon then chamber (1/N², 1/Pa²;
            only their ratios matter, within 1e15 of each other).
        tension_bounds: (lo, hi) of every tension (N; hi None: unbounded).
        pressure_bounds: (lo, hi) of every pressure (Pa; default (0, None)).
        warm_start: A previous :class:`InverseSolution` or actuation (tensions then pressures).
        throw: Raise :class:`softrod.TargetUnreachableError` (with the remaining distance) for
            a target out of reach; False: return the closest pose with ``converged=False``.
        tolerance: Tolerance on the distance to the target (m; default 1e-10).
        max_iterations: Cap on the iterations (default 60).
        target_s: Undeformed arc lengths (m, 0..length) of the backbone points that go to the
            rows of ``target_position`` (e.g. a measured backbone), shape (k,); None: the tip.
        starts: Run the iteration from several starts and keep the best answer (the
            converged one of least norm, else the closest): a count ``k`` (the warm start or
            rest, then ``k - 1`` actuations spread over those that turn the tip up to three
            turns, a third of the actuators slack in each), or actuations, shape
            (k, n_actuators), each a start after the first. None: one start. Each start costs
            one inverse.

    Returns:
        The actuation, its forward solution and the remaining errors.

    Warns:
        StabilityWarning: With obstacles, the target is reached on an unstable equilibrium
            (the contacts held; ``solution.stability_margin`` < 0).

    Raises:
        ParameterError: A bad argument (named); ``robot`` for what is not modelled (a tip
            constraint, tendon friction or guides, friction at an obstacle, a shape target
            with obstacles).
        TargetUnreachableError: The target is out of reach (``throw=True``).
        ConvergenceError: The iteration did not converge (``throw=True``).
    """
    if not isinstance(robot, Robot):
        err = _core.ParameterTypeError(
            f"robot = {robot!r:.60} ({type(robot).__name__}): expected a softrod.Robot"
        )
        err.parameter = "robot"
        raise err
    _refuse_unsupported(robot, obstacles_supported=target_s is None)
    key = _model_key(robot)
    warm_start, state, same = _warm_arguments(warm_start, key)
    extra = {} if target_s is not None else {"warm_state": state, "same_model": same}
    out = _core._inverse_statics(
        robot._rod,
        list(robot._tendons),
        robot._loads,
        list(robot._chambers),
        target_position,
        target_rotation=target_rotation,
        target_s=target_s,
        weights=weights,
        tension_bounds=tension_bounds,
        pressure_bounds=pressure_bounds,
        warm_start=warm_start,
        throw=throw,
        tolerance=tolerance,
        max_iterations=max_iterations,
        starts=starts,
        **{k: v for k, v in robot.solver.items() if k in ("integrator", "steps", "rtol", "atol")},
        **extra,
        **({"obstacles": list(robot.obstacles)} if robot.obstacles else {}),
    )
    if out.get("stable") is False and out["reached"]:
        warnings.warn(
            _core.StabilityWarning(
                "the actuation found reaches the target on an unstable contact equilibrium "
                f"(stability margin {out['stability_margin']:.4e} with the contacts held: the "
                "tip tangent stiffness is not positive definite); see docs/stability.md"
            ),
            stacklevel=2,
        )
    tensions, pressures = out["tensions"], out["pressures"]
    # Solved on the mesh of the answer: one the mesh control refined (the iteration passed
    # where the mesh asked was too coarse) is not the one a solve at the answer would choose.
    mesh = {} if out["refined_steps"] is None else {"steps": out["refined_steps"]}
    solution = _Deferred(
        lambda: robot.solve(
            tensions.copy() if len(tensions) else None,
            pressures.copy() if len(pressures) else None,
            on_unstable="ignore",
            **mesh,
        )
    )
    return _from_core(out, solution, None if target_s is not None else out["warm_state"], key)


@dataclass(frozen=True)
class InversePath:
    """The result of :func:`inverse_statics_path`: one row per target.

    Attributes:
        tensions: Tendon tensions (N), shape (n_targets, n_tendons).
        pressures: Chamber pressures (Pa, gauge), shape (n_targets, n_chambers).
        tip_position: Tip positions reached (m, world), shape (n_targets, 3).
        position_error: Distance from each tip to its target (m), shape (n_targets,).
        rotation_error: Angle to each target rotation (rad; 0 without one), shape (n_targets,).
        iterations: SQP iterations per target, shape (n_targets,).
        converged: Whether each target was reached with the minimum-norm actuation, shape
            (n_targets,).
        solutions: The forward statics solution of each target (a list of n_targets).
        reached: Whether each target was reached within the tolerance, shape (n_targets,).
    """

    tensions: np.ndarray
    pressures: np.ndarray
    tip_position: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    iterations: np.ndarray
    converged: np.ndarray
    solutions: list
    reached: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))

    def __len__(self) -> int:
        return len(self.position_error)

    @property
    def actuation(self) -> np.ndarray:
        """Tensions then pressures per target (N, Pa), shape (n_targets, n_actuators)."""
        return np.concatenate([self.tensions, self.pressures], axis=1)


def _parameter_error(name: str, value: object, expected: str) -> Exception:
    text = np.array2string(np.asarray(value, dtype=object), threshold=6)
    err = _core.ParameterError(f"invalid parameter `{name}` = {text:.80}: {expected}")
    err.parameter = name
    return err


def inverse_statics_path(
    robot: Robot,
    targets: Sequence[Sequence[float]] | np.ndarray,
    *,
    target_rotations: Sequence[Any] | np.ndarray | None = None,
    weights: Sequence[float] | np.ndarray | None = None,
    tension_bounds: tuple[float, float | None] = (0.0, None),
    pressure_bounds: tuple[float, float | None] | None = None,
    warm_start: InverseSolution | Sequence[float] | np.ndarray | None = None,
    throw: bool = True,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    starts: int | Sequence[Sequence[float]] | np.ndarray | None = None,
) -> InversePath:
    """Tracks a path of tip targets: :func:`inverse_statics` at each, warm-started from the last.

    Args:
        robot: The robot (its loads and gravity apply).
        targets: Tip positions (m, world), shape (n_targets, 3).
        target_rotations: Tip rotations (body -> world), shape (n_targets, 3, 3), or None.
        weights, tension_bounds, pressure_bounds, tolerance, max_iterations: As
            :func:`inverse_statics`.
        warm_start: Start of the first target (an :class:`InverseSolution` or an actuation).
        starts: Starts of the first target (as :func:`inverse_statics`); the others start
            from the last target reached.
        throw: Raise at the first target not reached; False: mark it ``converged=False`` and go
            on, the next target warm-started from the last one reached.

    Returns:
        An :class:`InversePath` (arrays, one row per target).

    Raises:
        ParameterError: Bad ``targets`` or ``target_rotations`` (named), or a bad argument of
            :func:`inverse_statics`.
        TargetUnreachableError, ConvergenceError: A target not reached (``throw=True``).
    """
    try:
        pts = np.asarray(targets, dtype=float)
    except (TypeError, ValueError):
        raise _parameter_error(
            "targets", targets, "an array (n_targets, 3) of numbers (m)"
        ) from None
    if pts.ndim != 2 or pts.shape[1] != 3 or pts.shape[0] == 0:
        raise _parameter_error(
            "targets", f"shape {pts.shape}", "an array (n_targets, 3) with n_targets >= 1 (m)"
        )
    if not np.all(np.isfinite(pts)) or np.abs(pts).max() > 1e6:
        raise _parameter_error("targets", pts, "finite numbers within ±1e6 m")
    rots = None
    if target_rotations is not None:
        try:
            rots = np.asarray(target_rotations, dtype=float)
        except (TypeError, ValueError):
            raise _parameter_error(
                "target_rotations", target_rotations, "an array (n_targets, 3, 3)"
            ) from None
        if rots.shape != (len(pts), 3, 3):
            raise _parameter_error(
                "target_rotations",
                f"shape {rots.shape}",
                f"an array ({len(pts)}, 3, 3): one rotation per target",
            )
    rows: list[InverseSolution] = []
    warm = warm_start
    for i, p in enumerate(pts):
        try:
            inv = inverse_statics(
                robot,
                p,
                target_rotation=None if rots is None else rots[i],
                weights=weights,
                tension_bounds=tension_bounds,
                pressure_bounds=pressure_bounds,
                warm_start=warm,
                throw=throw,
                tolerance=tolerance,
                max_iterations=max_iterations,
                starts=starts if i == 0 else None,
            )
        except _core.ParameterError as exc:
            # (The target's own arguments are rows of the path's: named so.)
            own = {"target_position": "targets", "target_rotation": "target_rotations"}
            name = getattr(exc, "parameter", None) or ""
            head = name.split("[")[0]
            if head not in own:
                raise
            renamed = f"{own[head]}[{i}]{name[len(head) :]}"
            raise _args.bad(str(exc).replace(f"`{name}`", f"`{renamed}`", 1)) from None
        rows.append(inv)
        if inv.converged:  # a miss does not seed the next target: the last reached one does
            warm = inv
    return InversePath(
        tensions=np.array([r.tensions for r in rows]).reshape(len(rows), -1),
        pressures=np.array([r.pressures for r in rows]).reshape(len(rows), -1),
        tip_position=np.array([np.asarray(r.solution.tip_position) for r in rows]),
        position_error=np.array([r.position_error for r in rows]),
        rotation_error=np.array([r.rotation_error for r in rows]),
        iterations=np.array([r.iterations for r in rows], dtype=int),
        converged=np.array([r.converged for r in rows], dtype=bool),
        solutions=[r.solution for r in rows],
        reached=np.array([r.reached for r in rows], dtype=bool),
    )
