"""Design studies: labelled sweeps of actuation and design parameters, on one core, all cores
or a Dask cluster (``docs/sweeps.md``).

:func:`sweep` solves a robot at every combination of design points (any robot-file
parameter: ``rod.section.tip_radius``, ``tendons[2].distance``, ...) and actuation samples
(``tendons[0].tension``, ``chambers[1].pressure``, ``loads.tip_force[1]``), builds each design's
model once and sweeps its actuation in the compiled core (warm-started in fixed blocks, so
the results are the same bit for bit whatever the scheduler and the chunking), and returns an
xarray ``Dataset`` with one dimension per grid axis (or a ``sample``/``design`` dimension for
tables), coordinates and units.

Summaries for design (workspace, stiffness statistics, the centre-to-periphery compliance
ratio) and a two-objective Pareto front are in :mod:`softrod.analysis.design`.
"""

from __future__ import annotations

import hashlib
import pickle
from collections.abc import Sequence
from typing import Any

import numpy as np

from .. import _args
from .._core import ParameterError, __version__
from . import _sweep_run as run
from ._sweep_axes import (
    Axes,
    SampleTable,
    actuation_axis,
    design_points,
    parse_axis_sets,
    samples,
    units_of,
)

__all__ = ["DEFAULT_BLOCK", "OUTPUTS", "STATUS", "SampleTable", "samples", "sweep"]

#: Rows per warm-started block (the determinism rule, see the module docs of the core).
DEFAULT_BLOCK = 32

#: Output names: those the core computes, plus "convergence" (iterations, residual, load
#: factor, load steps, evaluations) and "stability" (the solve's own verdict, `stable`).
OUTPUTS = (
    "tip_pose",
    "tendon_lengths",
    "backbone",
    "compliance",
    "stiffness",
    "gamma_c",
    "eigen_stiffness",
    "translational_compliance",
    "contacts",
    "convergence",
    "stability",
)

#: Values of the ``status`` variable.
STATUS = run.STATUS

_AT_ARCS = (
    "backbone",
    "compliance",
    "stiffness",
    "gamma_c",
    "eigen_stiffness",
    "translational_compliance",
)

WARM_START_RULE = (
    "samples of a design point are solved in boustrophedon order of the actuation grid (table "
    "order for a table) and cut into blocks of `block` samples aligned to that order; the first "
    "sample of a block starts cold, every other from the converged sample before it (cold if "
    "that one did not converge); with obstacles or a held tip every sample starts cold"
)

_TWIST = ["dx", "dy", "dz", "rx", "ry", "rz"]
_WRENCH = ["fx", "fy", "fz", "mx", "my", "mz"]


def _bad(name: str, value: Any, expected: str) -> ParameterError:
    exc = ParameterError(f"invalid parameter `{name}` = {value!r}: must be {expected}")
    exc.parameter = name
    return exc


def _outputs(outputs: Any) -> tuple[str, ...]:
    if isinstance(outputs, str):
        outputs = (outputs,)
    try:
        names = tuple(outputs)
    except TypeError:
        raise _bad("outputs", outputs, f"a sequence of output names from {OUTPUTS}") from None
    for i, o in enumerate(names):
        if o not in OUTPUTS:
            from ..io.robot_file import _suggest

            hint = _suggest(str(o), list(OUTPUTS))
            more = f"; did you mean {hint!r}?" if hint else f" (one of {', '.join(OUTPUTS)})"
            raise _bad(f"outputs[{i}]", o, f"an output name{more}")
    return tuple(dict.fromkeys(names))


def _floats(name: str, value: Any) -> np.ndarray:
    try:
        return np.atleast_1d(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        raise _bad(name, value, "a 1-D sequence of numbers") from None


def _shortest_rod(robot, points: list[dict[str, float]]) -> tuple[float, str]:
    """The shortest rod the sweep solves (m) and what it is: the robot's, or with ``rod.length``
    a design axis the shortest of its values > 0 (a length <= 0 is an infeasible design)."""
    lengths = [p["rod.length"] for p in points if p.get("rod.length", 0.0) > 0.0]
    if lengths:
        shortest = min(lengths)
        return shortest, f"the shortest rod of the design, rod.length = {shortest} m"
    return robot.rod.length, "the rod"


def _arcs(
    robot, arc_lengths, arm_index, shortest: tuple[float, str]
) -> tuple[tuple[float, ...] | None, tuple[float, ...]]:
    if arc_lengths is not None and arm_index is not None:
        exc = ParameterError(
            f"invalid parameters `arc_lengths` = {arc_lengths!r} and `arm_index` = "
            f"{arm_index!r}: give one or the other"
        )
        exc.parameter = "arc_lengths"
        raise exc
    if arc_lengths is not None:
        a = _floats("arc_lengths", arc_lengths)
        length, what = shortest
        if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)):
            raise _bad("arc_lengths", arc_lengths, "a non-empty 1-D sequence of finite m")
        if np.any(a < 0) or np.any(a > length):
            raise _bad("arc_lengths", arc_lengths, f"in [0, {length}] m ({what})")
        return tuple(float(x) for x in a), ()
    u = _floats("arm_index", 1.0 if arm_index is None else arm_index)
    if u.ndim != 1 or u.size == 0 or not np.all((u >= 0) & (u <= 1)):
        raise _bad("arm_index", arm_index, "fractions of the rod's length in [0, 1]")
    return None, tuple(float(x) for x in u)


#: Largest ``block`` and ``chunk`` accepted (samples).
MAX_SAMPLES_PER_TASK = 2**31 - 1


def _positive_int(name: str, value: Any) -> int:
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, np.integer))
        or not 1 <= value <= MAX_SAMPLES_PER_TASK
    ):
        raise _bad(name, value, f"an integer in [1, {MAX_SAMPLES_PER_TASK}]")
    return int(value)


def sweep(
    robot,
    *,
    actuation: Any = None,
    design: Any = None,
    outputs: Sequence[str] = ("tip_pose", "convergence"),
    arc_lengths: Sequence[float] | None = None,
    arm_index: Sequence[float] | None = None,
    scheduler: Any = None,
    chunk: int | None = None,
    block: int = DEFAULT_BLOCK,
    progress: bool | None = None,
):
    """Solves a robot over actuation and design axes and returns a labelled ``Dataset``.

    Every design point (the outer product of ``design``'s grids, or each row of a design
    table) is combined with every actuation sample (the outer product of ``actuation``'s
    grids, or each row of a table); the actuation varies fastest. Each design's model is
    built once and its samples are solved in the compiled core, warm-started within blocks
    of ``block`` samples (the first of a block starts cold), so results are identical bit
    for bit for any ``scheduler`` and ``chunk``.

    Args:
        robot: A :class:`softrod.Robot` (its tensions, pressures and loads are the values of
            the actuation not swept; pickled to the workers of a cluster).
        actuation: Actuation axes named by robot-file path: ``tendons[i].tension`` (N),
            ``chambers[i].pressure`` (Pa), ``loads.tip_force[k]`` (N), ``loads.tip_moment[k]``
            (N m; in the robot's ``tip_frame``). A dict of 1-D grids (outer product, one
            dimension each) or a table (:func:`softrod.samples`, a pandas ``DataFrame``: one
            ``sample`` dimension). None: the robot's own actuation.
        design: Design axes: any robot-file path (``rod.section.tip_radius``,
            ``tendons[2].distance``, ``rod.material.youngs_modulus``, ...), as grids or a table
            (one ``design`` dimension). A design the robot file rejects (a tip radius <= 0, a
            tendon outside the section) is marked infeasible, not raised. Paths are labelled
            in their canonical spelling (``tendons[02].distance`` is ``tendons[2].distance``);
            two axes may not name one parameter (in two spellings, or one inside the other),
            in ``design`` and ``actuation`` alike. At most
            :data:`softrod._args.MAX_GRID_VALUES` (10,000,000) points in all: design points x
            actuation samples.
        outputs: What to record, from :data:`OUTPUTS`: ``tip_pose`` (tip position and
            quaternion), ``tendon_lengths``, and at the chosen arc lengths ``backbone``
            (position, quaternion), ``compliance`` and ``stiffness`` (6x6, world frame, the
            integrated compliance), ``gamma_c``, ``eigen_stiffness``,
            ``translational_compliance`` (principal values of the force-to-translation block);
            ``contacts`` (``contact_count``, the total ``contact_force`` on the rod and the tip
            constraint's ``tip_reaction``, for a robot with obstacles or a held tip);
            ``convergence`` (iterations, residual, load factor, load steps, evaluations).
            ``status`` and ``error`` are always recorded.
        arc_lengths: Arc lengths (m, in [0, L]) of the per-arc-length outputs (dimension
            ``s``); with ``rod.length`` a design axis, L is its shortest value. A design point
            whose rod is shorter than an arc length all the same fails (status 2, error
            ``ParameterError: arc_lengths ...``).
        arm_index: Instead, fractions of each design's length (dimension ``arm_index``;
            default ``[1.0]``, the tip).
        scheduler: None: this process, all cores. A ``distributed.Client``, a cluster (e.g.
            ``LocalCluster``) or an address ``"tcp://host:port"``: Dask tasks (the robot and
            the task's samples are pickled; failed tasks are retried and a lost worker's
            tasks rescheduled).
        chunk: Samples per task (rounded up to a multiple of ``block``); default 4096 in
            process, about 16 tasks per worker thread on a cluster (at most 16384 samples each).
        block: Samples per warm-started block (>= 1); part of the result's definition.
        progress: Show a progress bar (tqdm) on stderr; None: only on a terminal. On a
            cluster the dashboard link is printed unless False.

    Returns:
        An ``xarray.Dataset``: the output variables (units in ``attrs``), ``status`` (0
        converged, 1 not converged, 2 failed, 3 infeasible design; NaN outputs unless 0),
        ``error`` (the error class per sample, "" if none), ``design_status`` and
        ``design_error`` (the message) per design point; ``attrs``: the robot file
        (``robot``), ``softrod_version``, ``design_dims`` and ``actuation_dims`` (names
        separated by spaces), ``outputs``, ``block`` and the ``warm_start_rule``.

    Raises:
        ParameterError: An unknown path or output, an actuation path in the wrong place, a
            grid that is not 1-D or not finite, a bad tension or pressure (named by its path),
            an arc length beyond the rod (the shortest design rod with ``rod.length`` a design
            axis), two axes naming one parameter (both named), more points than the limit
            (the number of points and the limit named; refused before any allocation).
        ParameterTypeError: ``robot`` is not a :class:`softrod.Robot`.
    """
    import xarray as xr

    from ..robot import Robot

    if not isinstance(robot, Robot):
        raise _args.type_error("robot", robot, "a softrod.Robot")
    names = _outputs(outputs)
    block = _positive_int("block", block)
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise _bad("progress", progress, "True, False or None")
    if chunk is not None:
        chunk = _positive_int("chunk", chunk)
    act, des = parse_axis_sets(actuation, design)
    axes = [actuation_axis(p, len(robot.tendons), len(robot.chambers)) for p in act.paths]
    if any(a.kind == "displacement" for a in axes):
        raise _bad(
            "actuation",
            next(a.path for a in axes if a.kind == "displacement"),
            "a tension, pressure or tip load: tendon displacement control is not swept yet"
            + (
                ""
                if "displacements" in _solve_parameters(robot)
                else " (and not in this build: Robot.solve has no `displacements=`)"
            ),
        )
    _check_actuation_values(act, axes)
    if des.paths:
        try:
            _ = robot.spec  # design points are built from the description
        except ParameterError as exc:
            raise _bad(
                "design",
                list(des.paths),
                "axes of a robot a robot file describes (design points are built with "
                f"Robot.with_parameters); this one is not: {' '.join(str(exc).split())}",
            ) from None
    _same_parameter_in_both(act, des)
    for i, p in enumerate(des.paths):
        spelt = des.spelling(p)
        try:
            robot.parameter(p)  # an unknown path is the user's error, raised here
        except ParameterError as exc:
            raise _bad(f"design[{spelt!r}]", spelt, str(exc).split(": must be ", 1)[-1]) from None
        if des.kind == "grid" and not np.all(np.isfinite(des.values[i])):
            raise _bad(f"design[{spelt!r}]", des.values[i], "finite")
    points = design_points(des)
    arcs, arm = _arcs(robot, arc_lengths, arm_index, _shortest_rod(robot, points))
    core_outputs = tuple(o for o in names if o not in ("convergence", "stability"))
    spec = run.TaskSpec(
        axes=tuple((a.kind, a.index) for a in axes),
        outputs=core_outputs,
        arc_lengths=arcs,
        arm_index=arm,
        block=block,
    )
    n_design, n_act = len(points), act.size
    client = owned = None
    if scheduler is not None:
        client, owned = run.client_of(scheduler)
    try:
        if chunk is None:
            if client is None:
                chunk = run.LOCAL_CHUNK
            else:
                per = run.CLUSTER_TASKS_PER_THREAD * run.cluster_threads(client)
                chunk = min(run.CLUSTER_MAX_CHUNK, max(block, -(-n_design * n_act // per)))
        tasks = run.plan(n_design, n_act, chunk, block)

        def pieces_of(task):
            return [run.Piece(d, points[d], a0, a1, act.rows[a0:a1]) for (d, a0, a1) in task]

        store = _Store(n_design, n_act, robot, spec, names)
        if client is None:
            results = run.run_local(robot, spec, tasks, pieces_of, progress)
        else:
            token = hashlib.sha1(pickle.dumps((robot.source, act.rows, points, spec))).hexdigest()[
                :12
            ]
            results = run.run_dask(client, robot, spec, tasks, pieces_of, progress, token)
        for task, parts in results:
            for (d, a0, a1), part in zip(task, parts, strict=True):
                store.put(d, a0, a1, part)
    finally:
        if owned:
            client.close()
    return store.dataset(xr, act, des, robot, arcs, arm, names, block)


def _same_parameter_in_both(act: Axes, des: Axes) -> None:
    """Refuses a design axis naming a parameter an actuation axis also names (in any
    spelling, or one inside the other), naming both."""
    from ..robot import path_conflict

    for p in des.paths:
        for q in act.paths:
            why = path_conflict(q, p) if p != q else f"both name `{p}`"
            if why is not None:
                raise _bad(
                    f"design[{des.spelling(p)!r}]",
                    [act.spelling(q), des.spelling(p)],
                    f"a path not also swept in `actuation` (`actuation` has "
                    f"{act.spelling(q)!r}; {why})",
                )


def _solve_parameters(robot) -> set[str]:
    import inspect

    return set(inspect.signature(robot.solve).parameters)


def _check_actuation_values(act: Axes, axes) -> None:
    for col, a in enumerate(axes):
        v = act.rows[:, col]
        if a.kind == "tension" and np.any(v < 0):
            raise _bad(f"actuation[{a.path!r}]", float(v[v < 0][0]), "tensions >= 0 N")
        if a.kind == "pressure" and np.any(v < -101325.0):
            raise _bad(
                f"actuation[{a.path!r}]",
                float(v[v < -101325.0][0]),
                "gauge pressures >= -101325 Pa (vacuum)",
            )


class _Store:
    """The result arrays, (n_design, n_act, ...) in solve order, filled piece by piece."""

    def __init__(self, n_design, n_act, robot, spec, names):
        self.n_design, self.n_act = n_design, n_act
        self.names = names
        self.arrays: dict[str, np.ndarray] = {}
        self.status = np.full((n_design, n_act), -1, dtype=np.int8)
        self.error = np.full((n_design, n_act), "", dtype=object)
        self.design_error = np.full(n_design, "", dtype=object)
        self.n_tendons = len(robot.tendons)
        self.n_arcs = len(spec.arc_lengths) if spec.arc_lengths is not None else len(spec.arm_index)
        self.lengths = np.full(n_design, np.nan)

    def _array(self, key: str, tail: tuple[int, ...], dtype) -> np.ndarray:
        if key not in self.arrays:
            fill = np.nan if dtype is float else -1
            self.arrays[key] = np.full((self.n_design, self.n_act, *tail), fill, dtype=dtype)
        return self.arrays[key]

    def put(self, d: int, a0: int, a1: int, part: dict) -> None:
        if "infeasible" in part:
            self.status[d, a0:a1] = STATUS["infeasible_design"]
            self.error[d, a0:a1] = "ParameterError: infeasible design"
            self.design_error[d] = part["infeasible"]
            return
        self.status[d, a0:a1] = part["status"]
        self.error[d, a0:a1] = np.asarray(part["error"], dtype=object)
        for key, value in part.items():
            if (
                key in ("status", "error")
                or (key in _CONVERGENCE and "convergence" not in self.names)
                or (key == "stable" and "stability" not in self.names)
            ):
                continue
            v = np.asarray(value)
            dtype = float if v.dtype.kind == "f" else np.int64
            self._array(key, v.shape[1:], dtype)[d, a0:a1] = v

    def dataset(self, xr, act: Axes, des: Axes, robot, arcs, arm, names, block):
        if np.any(self.status < 0):  # pragma: no cover - every piece is stored
            raise RuntimeError("sweep: samples without a result")
        prefix_dims = (*des.dims, *act.dims)
        prefix_shape = (*des.shape, *act.shape)

        def grid_order(a: np.ndarray) -> np.ndarray:
            # Solve order -> C order of both grids, then the grid shape.
            out = np.empty_like(a)
            out[np.ix_(des.order, act.order)] = a
            return out.reshape(prefix_shape + a.shape[2:])

        coords: dict[str, Any] = {}
        for axes in (des, act):
            if axes.kind == "grid":
                for p, v in zip(axes.paths, axes.values, strict=True):
                    units, long_name = units_of(p)
                    coords[p] = xr.Variable((p,), v, {"units": units, "long_name": long_name})
            elif axes.kind == "table":
                (dim,) = axes.dims
                coords[dim] = xr.Variable((dim,), np.arange(axes.size), {"long_name": f"{dim} row"})
                for p, v in zip(axes.paths, axes.values, strict=True):
                    units, long_name = units_of(p)
                    coords[p] = xr.Variable((dim,), v, {"units": units, "long_name": long_name})
        arc_dim = "s" if arcs is not None else "arm_index"
        arc_values = np.asarray(arcs if arcs is not None else arm, float)
        coords.update(
            xyz=("xyz", ["x", "y", "z"]),
            xyzw=("xyzw", ["x", "y", "z", "w"]),
        )
        if any(n in _AT_ARCS for n in names):
            coords[arc_dim] = xr.Variable(
                (arc_dim,),
                arc_values,
                {"units": "m", "long_name": "arc length"}
                if arcs is not None
                else {"units": "1", "long_name": "arc length / rod length (arm index)"},
            )
        data: dict[str, Any] = {}
        meta = _VARIABLES
        data["status"] = None  # placeholders: status and error come first
        data["error"] = None
        for key, a in self.arrays.items():
            dims, attrs = meta[key]
            dims = tuple(arc_dim if x == "ARC" else x for x in dims)
            data[key] = xr.Variable((*prefix_dims, *dims), grid_order(a), dict(attrs))
        data["status"] = xr.Variable(
            prefix_dims,
            grid_order(self.status),
            {
                "long_name": "how the solve of the sample ended",
                "flag_values": np.array(list(STATUS.values()), dtype=np.int8),
                "flag_meanings": " ".join(STATUS),
            },
        )
        data["error"] = xr.Variable(
            prefix_dims,
            grid_order(self.error),
            {"long_name": "error class of a failed sample (empty if none)"},
        )
        design_status = (self.design_error != "").astype(np.int8)
        d_order = des.order
        ds_err = np.empty_like(self.design_error)
        ds_err[d_order] = self.design_error
        ds_stat = np.empty_like(design_status)
        ds_stat[d_order] = design_status
        data["design_status"] = xr.Variable(
            des.dims,
            ds_stat.reshape(des.shape),
            {
                "long_name": "feasibility of the design point",
                "flag_values": np.array([0, 1], dtype=np.int8),
                "flag_meanings": "feasible infeasible",
            },
        )
        data["design_error"] = xr.Variable(
            des.dims,
            ds_err.reshape(des.shape),
            {"long_name": "why the design point is infeasible (empty if feasible)"},
        )
        if "tendon_lengths" in names:
            coords["tendon"] = ("tendon", np.arange(self.n_tendons))
        if "compliance" in names or "stiffness" in names:
            coords["twist"] = ("twist", _TWIST)
        if "compliance" in names or "stiffness" in names or "contacts" in names:
            coords["wrench"] = ("wrench", _WRENCH)
        if "eigen_stiffness" in names:
            coords["screw"] = ("screw", np.arange(6))
        if "translational_compliance" in names:
            coords["principal"] = ("principal", np.arange(3))
        if "gamma_c" in names:
            coords["axis"] = ("axis", ["x", "y", "z"])
        try:
            description = robot.to_toml()
        except ParameterError:
            description = repr(robot)
        attrs = {
            "title": f"softrod sweep of {robot.name}",
            "robot_name": robot.name,
            "robot": description,
            "softrod_version": __version__,
            "design_dims": " ".join(des.dims),
            "actuation_dims": " ".join(act.dims),
            "outputs": " ".join(names),
            "block": block,
            "warm_start_rule": WARM_START_RULE,
        }
        ds = xr.Dataset(data, coords=coords, attrs=attrs)
        used = set()
        for v in ds.variables.values():
            used.update(v.dims)
        return ds.drop_vars([c for c in ("xyz", "xyzw") if c not in used])


_CONVERGENCE = ("iterations", "residual", "load_factor", "load_steps", "function_evaluations")
_MIXED = "mixed SI (m/N, 1/N, rad/(N m) blocks)"
_VARIABLES: dict[str, tuple[tuple[str, ...], dict[str, str]]] = {
    "tip_position": (("xyz",), {"units": "m", "long_name": "tip position (world)"}),
    "tip_quaternion": (
        ("xyzw",),
        {"units": "1", "long_name": "tip orientation, body -> world quaternion [x, y, z, w]"},
    ),
    "tendon_lengths": (("tendon",), {"units": "m", "long_name": "tendon path length"}),
    "backbone_position": (("ARC", "xyz"), {"units": "m", "long_name": "backbone position"}),
    "backbone_quaternion": (
        ("ARC", "xyzw"),
        {"units": "1", "long_name": "backbone orientation quaternion [x, y, z, w]"},
    ),
    "compliance": (
        ("ARC", "twist", "wrench"),
        {
            "units": _MIXED,
            "long_name": "integrated compliance C_world (twist [dp; dtheta] = C [f; m])",
        },
    ),
    "stiffness": (
        ("ARC", "wrench", "twist"),
        {"units": "mixed SI (N/m, N, N m/rad blocks)", "long_name": "stiffness K_world = C^-1"},
    ),
    "gamma_c": (("ARC", "axis"), {"units": "1", "long_name": "flexural compliance gamma_c"}),
    "eigen_stiffness": (
        ("ARC", "screw"),
        {"units": "N/rad", "long_name": "eigenstiffnesses of K_world, decreasing"},
    ),
    "translational_compliance": (
        ("ARC", "principal"),
        {"units": "m/N", "long_name": "principal translational compliances, decreasing"},
    ),
    "contact_count": ((), {"units": "1", "long_name": "active contacts"}),
    "contact_force": (
        ("xyz",),
        {"units": "N", "long_name": "total contact force on the rod (world)"},
    ),
    "tip_reaction": (
        ("wrench",),
        {"units": "N, N m", "long_name": "reaction [f; m] of the tip constraint (world)"},
    ),
    "iterations": ((), {"units": "1", "long_name": "Newton iterations"}),
    "residual": ((), {"units": "1", "long_name": "final scaled residual"}),
    "load_factor": ((), {"units": "1", "long_name": "load factor reached"}),
    "load_steps": ((), {"units": "1", "long_name": "continuation load steps"}),
    "function_evaluations": ((), {"units": "1", "long_name": "right-hand-side evaluations"}),
    "stable": (
        (),
        {
            "units": "1",
            "long_name": "stable equilibrium (1), unstable (0), not converged (-1)",
            "flag_values": np.array([-1, 0, 1], dtype=np.int8),
            "flag_meanings": "not_converged unstable stable",
        },
    ),
}
