"""Inverse statics and actuation Jacobians on the two-segment NiTi robot: medians (µs).

Rows: the forward solve; the exact actuation Jacobian of a solution; softrod's inverse statics
cold (from zero actuation) and warm (the previous target's solution, target moved by 1 mm);
and, on the same targets, SciPy ``least_squares`` over softrod's forward solve (bounded
tensions, finite-difference Jacobian: what a user writes without the inverse), once with its
default tolerances (it stops about 1e-6 m from the target, on ``gtol``) and once with
``ftol = gtol = xtol = 1e-15`` so that it reaches the target to 1e-9 m as the inverse does (the
ratio is taken against that one); a 41-point
circle of radius 10 mm tracked with ``inverse_statics_path`` (time per target); and the PCC
inverse (``softrod.pcc.inverse_statics``) of the same robot as two constant-curvature
segments, cold and warm. Every method runs in this one process, side by side.

Each call is repeated ``--repeats`` times on its target (the same work every time) and
timed on its own; a target's time is the median of its repeats, and a row the median over
targets.

    python benchmarks/bench_inverse.py [--targets N] [--repeats R]
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np
from _timing import admissible_tensions, repeated, timed
from scipy.optimize import least_squares

import softrod
from softrod import pcc

TIGHT = ("ftol", "gtol", "xtol")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--targets", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=5, help="timed calls per target")
    args = ap.parse_args()
    n, reps = args.targets, args.repeats
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    rng = np.random.default_rng(7)
    targets = [robot.solve(admissible_tensions(rng)).tip_position for _ in range(n)]
    timed_keys = ("cold", "warm", "scipy_default", "scipy", "path", "pcc_cold", "pcc_warm")
    keys = ("forward", "jacobian", *timed_keys)
    rows: dict[str, list[float]] = {k: [] for k in keys}
    solves: list[int] = []  # forward solves per SciPy call (2-point Jacobian: 6 per Jacobian)
    misses = dict.fromkeys(timed_keys, 0)
    angles = [np.pi / 2, -np.pi / 6, 7 * np.pi / 6]
    probot = (
        pcc.Robot.solid_circle([0.2, 0.2], 0.7e-3, 54e9)
        .with_tendons(0, [0.01] * 3, angles)
        .with_tendons(1, [0.01] * 3, angles)
    )
    sol = robot.solve([1.0, 0.5, 0.0, 0.0, 0.3, 0.0])
    for _ in range(200):
        rows["forward"].append(timed(lambda: robot.solve([1.0, 0.5, 0.0, 0.0, 0.3, 0.0]))[0])
        rows["jacobian"].append(timed(lambda: softrod.actuation_jacobian(sol))[0])
    for target in targets:
        dt, cold = repeated(lambda t=target: softrod.inverse_statics(robot, t, throw=False), reps)
        rows["cold"].append(dt)
        misses["cold"] += not cold.converged
        moved = target + np.array([1e-3, 0.0, 0.0])
        dt, warm = repeated(
            lambda m=moved, c=cold: softrod.inverse_statics(robot, m, warm_start=c, throw=False),
            reps,
        )
        rows["warm"].append(dt)
        misses["warm"] += not warm.converged

        def residual(t, target=target):
            return robot.solve(t).tip_position - target

        for key, tol in (("scipy_default", {}), ("scipy", dict.fromkeys(TIGHT, 1e-15))):
            dt, ls = repeated(
                lambda tol=tol: least_squares(
                    residual, np.full(6, 0.5), bounds=(0.0, np.inf), **tol
                ),
                reps,
            )
            rows[key].append(dt)
            misses[key] += not np.linalg.norm(ls.fun) <= 1e-9
        solves.append(ls.nfev + ls.njev * 6)
    centre = robot.solve([2.0, 0.0, 0.0, 0.0, 2.0, 0.0]).tip_position - [0.0, 0.0, 0.005]
    th = np.linspace(0.0, 2.0 * np.pi, 41)
    circle = centre + 0.01 * np.stack([np.cos(th), np.sin(th), 0.0 * th], axis=1)
    for _ in range(3):
        dt, path = timed(lambda: softrod.inverse_statics_path(robot, circle, throw=False))
        rows["path"].append(dt / len(circle))
    misses["path"] = int(np.sum(~path.converged))
    prng = np.random.default_rng(8)
    for _ in range(n):
        target = np.asarray(pcc.solve(probot, admissible_tensions(prng)).tip_pose)[:3, 3]
        dt, cold = repeated(lambda t=target: pcc.inverse_statics(probot, t, throw=False), reps)
        rows["pcc_cold"].append(dt)
        misses["pcc_cold"] += not cold.converged
        moved = target + np.array([1e-3, 0.0, 0.0])
        dt, warm = repeated(
            lambda m=moved, c=cold: pcc.inverse_statics(probot, m, warm_start=c, throw=False),
            reps,
        )
        rows["pcc_warm"].append(dt)
        misses["pcc_warm"] += not warm.converged
    med = {k: statistics.median(v) * 1e6 for k, v in rows.items()}
    print(f"two-segment NiTi robot, {n} targets from forward solves at admissible tensions")
    print(f"{'method':<44}{'median (µs)':>14}{'not reached':>14}")
    names = {
        "forward": "forward solve (robot.solve)",
        "jacobian": "actuation_jacobian",
        "cold": "inverse_statics, cold",
        "warm": "inverse_statics, warm (target moved 1 mm)",
        "scipy_default": "scipy least_squares, default tolerances",
        "scipy": "scipy least_squares, tolerances 1e-15",
        "path": "inverse_statics_path, per target (circle)",
        "pcc_cold": "pcc.inverse_statics, cold",
        "pcc_warm": "pcc.inverse_statics, warm (moved 1 mm)",
    }
    for k, name in names.items():
        total = len(circle) if k == "path" else n
        miss = f"{misses[k]}/{total}" if k in misses else ""
        print(f"{name:<44}{med[k]:>14.1f}{miss:>14}")
    print(f"scipy (tolerances 1e-15) / cold: {med['scipy'] / med['cold']:.0f}x")
    print(
        f"scipy (tolerances 1e-15): {statistics.median(solves):.0f} forward solves per target "
        "(median); "
        f"cold inverse = {med['cold'] / med['forward']:.1f} forward solves, "
        f"warm = {med['warm'] / med['forward']:.1f}"
    )


if __name__ == "__main__":
    main()
