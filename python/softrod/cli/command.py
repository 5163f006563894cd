"""``softrod inverse``: the minimum-norm actuation that puts the tip of a robot at a target.

``ROBOT`` is a robot file or the name of a shipped example. ``--target`` may be repeated: the
targets are then a path, each warm-started from the last one reached
(:func:`softrod.inverse_statics_path`). Every target is solved, printed and written; a target
that did not converge makes the exit status 3 after that.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from .._core import MAX_STARTS, ConvergenceError
from ._common import (
    _positive_int,
    add_data_outputs,
    bad,
    files,
    finite_float,
    write_csv,
    write_json,
)

_ROBOT_HELP = "robot description file (TOML), or the name of a shipped example"


def _upper_bound(text: str) -> float | None:
    """An argparse type: a finite number, or ``inf``/``none`` (unbounded)."""
    if text.strip().lower() in ("inf", "+inf", "none"):
        return None
    return finite_float(text)


def _bounds(args, dest: str):
    pair = getattr(args, dest)
    if pair is None:
        return None
    lo, hi = pair
    if lo is None:
        raise bad("--" + dest.replace("_", "-"), "inf", "the lower bound must be a finite number")
    return (lo, hi)


def _fmt(values, digits: int = 9) -> str:
    return "[" + ", ".join(f"{v:.{digits}g}" for v in values) + "]"


def _cmd_inverse(args) -> int:
    from ..inverse import inverse_statics_path
    from ..robot import load_robot

    robot = load_robot(args.robot)
    targets = np.array(args.target, dtype=float)
    rotations = None
    if args.rotation is not None:
        r = np.array(args.rotation, dtype=float).reshape(3, 3)
        rotations = np.repeat(r[None], len(targets), axis=0)
    kwargs = {}
    for dest, actuators, kind in (
        ("tension_bounds", robot.tendons, "tendons"),
        ("pressure_bounds", robot.chambers, "chambers"),
    ):
        if getattr(args, dest) is None:
            continue
        if not actuators:
            raise bad(
                "--" + dest.replace("_", "-"),
                " ".join(map(str, getattr(args, dest))),
                f"bounds no actuator: {robot.name} has no {kind}",
            )
        kwargs[dest] = _bounds(args, dest)
    path = inverse_statics_path(
        robot,
        targets,
        target_rotations=rotations,
        weights=args.weights,
        tolerance=args.tolerance,
        throw=False,
        starts=args.starts,
        **kwargs,
    )
    print(f"robot: {robot.name} ({args.robot})")
    print("objective: least norm of the actuator forces among the actuations reaching the target")
    for k, target in enumerate(targets):
        head = f"target {k + 1}" if len(targets) > 1 else "target"
        print(f"{head} (m): {_fmt(target)}")
        if path.tensions.shape[1]:
            print(f"  tensions (N):      {_fmt(path.tensions[k], 6)}")
        if path.pressures.shape[1]:
            print(f"  pressures (Pa):    {_fmt(path.pressures[k], 6)}")
        print(f"  tip position (m):  {_fmt(path.tip_position[k])}")
        rot = f", rotation error {path.rotation_error[k]:.2e} rad" if rotations is not None else ""
        print(
            f"  position error {path.position_error[k]:.2e} m{rot}, "
            f"iterations {path.iterations[k]}, converged {bool(path.converged[k])}"
            + _status(path, k)
        )
    nt, nc = path.tensions.shape[1], path.pressures.shape[1]
    if args.csv:
        header = ["target_x", "target_y", "target_z"]
        header += [f"tension_{i}" for i in range(nt)] + [f"pressure_{i}" for i in range(nc)]
        header += ["tip_x", "tip_y", "tip_z", "position_error", "rotation_error"]
        header += ["iterations", "converged", "reached"]
        rows = [
            [
                *map(float, targets[k]),
                *map(float, path.tensions[k]),
                *map(float, path.pressures[k]),
                *map(float, path.tip_position[k]),
                float(path.position_error[k]),
                float(path.rotation_error[k]),
                int(path.iterations[k]),
                bool(path.converged[k]),
                bool(path.reached[k]),
            ]
            for k in range(len(targets))
        ]
        write_csv(args.csv, header, rows)
    if args.json:
        write_json(
            args.json,
            {
                "robot": robot.name,
                "targets": targets,
                "target_rotation": None if rotations is None else rotations[0],
                "tensions": path.tensions,
                "pressures": path.pressures,
                "tip_position": path.tip_position,
                "position_error": path.position_error,
                "rotation_error": path.rotation_error,
                "iterations": path.iterations,
                "converged": path.converged,
                "reached": path.reached,
            },
        )
    return _verdict(path)


def _status(path, k: int) -> str:
    """What a target that did not converge got: reached without the least norm, or not."""
    if path.converged[k]:
        return ""
    if path.reached[k]:
        return " (target reached; the least norm is not certified)"
    return " (target not reached)"


def _verdict(path) -> int:
    """0 when every target converged; else (after the results were printed and written) a
    ConvergenceError naming the first target that did not (exit status 3)."""
    missed = np.flatnonzero(~path.converged)
    if not len(missed):
        return 0
    k = int(missed[0])
    what = (
        "was reached but the least-norm actuation is not certified"
        if path.reached[k]
        else "is not reached (out of reach, or the iterations stopped): remaining distance "
        f"{path.position_error[k]:.3e} m"
    )
    more = f" ({len(missed)} of {len(path)} targets did not converge)" if len(path) > 1 else ""
    raise ConvergenceError(f"target {k + 1} {what}{more}")


def _check_rotation(values: list[float]) -> None:
    r = np.array(values, dtype=float).reshape(3, 3)
    err = float(np.abs(r.T @ r - np.eye(3)).max())
    if err > 1e-6 or np.linalg.det(r) <= 0.0:
        raise bad(
            "--rotation",
            values,
            f"a rotation matrix, rows in order (R^T R = I to 1e-6, det > 0; off by {err:.1e})",
        )


def register(sub) -> None:
    """Adds ``inverse`` to the ``softrod`` parser."""
    inv = sub.add_parser(
        "inverse",
        help="inverse statics: the minimum-norm actuation putting the tip at a target",
        description=(
            "The minimum-norm actuation (least norm of the actuator forces, inside the bounds) "
            "that puts the tip of ROBOT at the target; the robot file's loads and gravity apply, "
            "its tensions and pressures are replaced. A repeated --target is a path, each target "
            "warm-started from the last. Every target's result is printed and written; if one "
            "did not converge (out of reach, or reached without the least norm certified) the "
            "exit status is 3, with the first such target and its remaining distance."
        ),
    )
    inv.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    inv.add_argument(
        "--target",
        type=finite_float,
        nargs=3,
        action="append",
        required=True,
        metavar=("X", "Y", "Z"),
        help="tip target position (m, world); repeat for a path",
    )
    inv.add_argument(
        "--rotation",
        type=finite_float,
        nargs=9,
        metavar="R",
        help="tip target rotation (body -> world), 9 numbers row by row (default: position only)",
    )
    inv.add_argument(
        "--tension-bounds",
        type=_upper_bound,
        nargs=2,
        metavar=("LO", "HI"),
        help="bounds of every tension (N; HI may be inf; default 0 inf)",
    )
    inv.add_argument(
        "--pressure-bounds",
        type=_upper_bound,
        nargs=2,
        metavar=("LO", "HI"),
        help="bounds of every chamber pressure (Pa; HI may be inf; default 0 inf)",
    )
    inv.add_argument(
        "--weights",
        type=finite_float,
        nargs="+",
        metavar="W",
        help="weights of the actuation norm, one per tendon then chamber (1/N^2, 1/Pa^2)",
    )
    inv.add_argument(
        "--tolerance", type=finite_float, help="tolerance on the distance to the target (m)"
    )
    inv.add_argument(
        "--starts",
        type=_positive_int,
        metavar="N",
        help=(
            "solve the (first) target from N starts and keep the best answer: the converged "
            "one of least norm (default 1: from rest; the iteration is local)"
        ),
    )
    add_data_outputs(inv, "the actuation per target", "one row per target")
    files(inv, inputs=("robot",), outputs=("csv", "json"))

    def run(args: argparse.Namespace) -> int:
        if args.rotation is not None:
            _check_rotation(args.rotation)
        if args.starts is not None and not 1 <= args.starts <= MAX_STARTS:
            raise bad("--starts", args.starts, f"must be in [1, {MAX_STARTS}]")
        if args.tolerance is not None and not (
            args.tolerance > 0 and math.isfinite(args.tolerance)
        ):
            raise bad("--tolerance", args.tolerance, "a positive number (m)")
        return _cmd_inverse(args)

    inv.set_defaults(func=run)
