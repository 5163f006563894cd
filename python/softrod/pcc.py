"""Piecewise-constant-curvature (PCC) kinematics, actuation maps and statics.

Conventions (see ``docs/pcc.md``): a segment is an arc with parameters ``(curvature,
plane_angle, length)`` (1/m, rad, m). Its base is at the origin with the tangent along +z; a
positive curvature bends the tip toward ``(cos plane_angle, sin plane_angle, 0)``. The frame at
arc length ``s`` is ``Rz(phi) Ry(kappa s) Rz(-phi)`` (no twist about the tangent). Poses are 4x4
homogeneous transforms (tip frame -> base frame); chains are ``(n, 3)`` arrays of arc rows, each
segment relative to the tip frame of the previous one. Jacobians map parameter rates to twists
``[translation; rotation]`` in the ``"spatial"``, ``"body"`` or ``"hybrid"`` frame, with respect
to ``"arc"`` coordinates ``(curvature, plane_angle, length)`` or ``"curvature_vector"``
coordinates ``(u_x, u_y, length)`` with ``u = curvature * (-sin phi, cos phi)`` (smooth when
straight).

Statics (:func:`solve`): stationary potential energy of the Cosserat rod restricted to arcs,
tendons passing through proximal segments, pneumatic chambers, and a world-frame tip force and
moment; Newton with the exact Jacobian. The integrated compliance along a solution is
:func:`softrod.compliance` ``(solution, rod)`` (the same computation as for a Cosserat solution;
``rod`` gives the section and material). Errors are :class:`softrod.ParameterError` naming the
parameter, and :class:`softrod.ConvergenceError`.

Example:
    >>> import numpy as np
    >>> from softrod import pcc
    >>> pcc.arc_pose(np.pi / 2 / 0.1, 0.0, 0.1)[:3, 3].round(4)  # quarter circle toward +x
    array([0.0637, 0.    , 0.0637])
"""

from __future__ import annotations

import numpy as np

from . import _core
from ._core import PccRobot, PccSolution
from ._core import pcc_arc_frames as arc_frames
from ._core import pcc_arc_from_pressures as arc_from_pressures
from ._core import pcc_arc_from_pressures_jacobian as arc_from_pressures_jacobian
from ._core import pcc_arc_from_tendon_displacements as arc_from_tendon_displacements
from ._core import (
    pcc_arc_from_tendon_displacements_jacobian as arc_from_tendon_displacements_jacobian,
)
from ._core import pcc_arc_from_tendon_tensions as arc_from_tendon_tensions
from ._core import pcc_arc_from_tendon_tensions_jacobian as arc_from_tendon_tensions_jacobian
from ._core import pcc_arc_from_tip as arc_from_tip
from ._core import pcc_arc_from_tip_with_length as arc_from_tip_with_length
from ._core import pcc_arc_jacobian as arc_jacobian
from ._core import pcc_arc_pose as arc_pose
from ._core import pcc_arc_poses as arc_poses
from ._core import pcc_chain_frames as chain_frames
from ._core import pcc_chain_jacobian as chain_jacobian
from ._core import pcc_chain_pose as chain_pose
from ._core import pcc_solve as solve
from ._core import pcc_tendon_displacement_jacobian as tendon_displacement_jacobian
from ._core import pcc_tendon_displacement_misfit as tendon_displacement_misfit
from ._core import pcc_tendon_displacements as tendon_displacements
from .inverse import _Deferred, _from_core, _warm_arguments


def inverse_statics(
    robot: PccRobot,
    target_position,
    *,
    target_rotation=None,
    weights=None,
    tension_bounds: tuple[float, float | None] = (0.0, None),
    pressure_bounds: tuple[float, float | None] | None = None,
    tip_force=None,
    tip_moment=None,
    warm_start=None,
    throw: bool = True,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    starts=None,
):
    """The minimum-norm actuation that puts the tip of the PCC ``robot`` at a target.

    The same objective and algorithm as :func:`softrod.inverse_statics` (least weighted norm
    of the actuation inside the bounds among those reaching the target; SQP on the exact PCC
    actuation Jacobian), on the PCC equilibrium (closed form without a tip wrench).

    Args:
        robot: The PCC robot.
        target_position: Tip position (m, base frame), shape (3,).
        target_rotation: Tip rotation (3x3, tip -> base), or None for a position target.
        weights, tension_bounds, pressure_bounds, throw, tolerance, max_iterations, starts: As
            :func:`softrod.inverse_statics`.
        tip_force: Tip force (N, world), shape (3,), or None.
        tip_moment: Tip moment (N m, world), shape (3,), or None.
        warm_start: A previous :class:`softrod.InverseSolution` or actuation (tensions then
            pressures).

    Returns:
        A :class:`softrod.InverseSolution` whose ``solution`` is the :class:`PccSolution`.

    Raises:
        ParameterError: A bad argument (named).
        TargetUnreachableError: The target is out of reach (``throw=True``).
        ConvergenceError: The iteration did not converge (``throw=True``).
    """
    if tip_force is None and tip_moment is None:
        key = robot
    else:
        key = (robot, (_loads_key(tip_force), _loads_key(tip_moment)))
    warm_start, state, same = _warm_arguments(warm_start, key)
    out = _core._pcc_inverse_statics(
        robot,
        target_position,
        target_rotation=target_rotation,
        weights=weights,
        tension_bounds=tension_bounds,
        pressure_bounds=pressure_bounds,
        tip_force=tip_force,
        tip_moment=tip_moment,
        warm_start=warm_start,
        throw=throw,
        tolerance=tolerance,
        max_iterations=max_iterations,
        warm_state=state,
        same_model=same,
        starts=starts,
    )
    tensions, pressures = out["tensions"], out["pressures"]
    # The PCC solution at the actuation found is solved when it is first read.
    solution = _Deferred(
        lambda: solve(
            robot,
            tensions.copy() if len(tensions) else None,
            pressures.copy() if len(pressures) else None,
            tip_force=tip_force,
            tip_moment=tip_moment,
        )
    )
    return _from_core(out, solution, out["warm_state"], key)


def _loads_key(v):
    return None if v is None else tuple(np.asarray(v, dtype=float).ravel())


# The names of the first release, kept: ``softrod.pcc.Robot`` is ``PccRobot``.
Robot = PccRobot
Solution = PccSolution

__all__ = [
    "PccRobot",
    "PccSolution",
    "Robot",
    "Solution",
    "arc_frames",
    "arc_from_pressures",
    "arc_from_pressures_jacobian",
    "arc_from_tendon_displacements",
    "arc_from_tendon_displacements_jacobian",
    "arc_from_tendon_tensions",
    "arc_from_tendon_tensions_jacobian",
    "arc_from_tip",
    "arc_from_tip_with_length",
    "arc_jacobian",
    "arc_pose",
    "arc_poses",
    "chain_frames",
    "chain_jacobian",
    "chain_pose",
    "inverse_statics",
    "solve",
    "tendon_displacement_jacobian",
    "tendon_displacement_misfit",
    "tendon_displacements",
]
