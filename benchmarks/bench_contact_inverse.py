"""Commanding the two-segment NiTi robot among obstacles: medians (ms), side by side in one run.

Rows: the forward solve without and with the obstacle; the actuation Jacobian of each (the
contact one with the active contacts as constraints); the inverse statics to targets made by
forward contact solves at random admissible tensions that touch the obstacle, cold (from zero
actuation) and warm (the previous answer, target moved by 1 mm), and, on the robot without
the obstacle, the contact-free inverse to the same targets. Counts of targets not reached.

    python benchmarks/bench_contact_inverse.py [--targets N] [--obstacle plane|sphere]
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np
from _timing import admissible_tensions, timed

import softrod


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--targets", type=int, default=20)
    ap.add_argument("--obstacle", choices=("plane", "sphere"), default="plane")
    args = ap.parse_args()
    base = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    obstacle = (
        softrod.Plane((0.05, 0.0, 0.0), (-1.0, 0.0, 0.0))
        if args.obstacle == "plane"
        else softrod.Sphere((0.06, 0.0, 0.3), 0.04)
    )
    free = softrod.Robot(base.rod, base.tendons, solver=base.solver)
    robot = softrod.Robot(base.rod, base.tendons, solver=base.solver, obstacles=[obstacle])
    rng = np.random.default_rng(7)
    targets = []
    while len(targets) < args.targets:
        sol = robot.solve(admissible_tensions(rng))
        if sol.contacts:
            targets.append((sol.tensions, sol.tip_position))
    keys = ("forward", "forward_contact", "jacobian", "jacobian_contact", "free_cold")
    keys += ("cold", "warm")
    rows: dict[str, list[float]] = {k: [] for k in keys}
    misses = {"free_cold": 0, "cold": 0, "warm": 0}
    for t, target in targets:
        dt, s_free = timed(lambda t=t: free.solve(t))
        rows["forward"].append(dt)
        dt, s_contact = timed(lambda t=t: robot.solve(t))
        rows["forward_contact"].append(dt)
        rows["jacobian"].append(timed(lambda s=s_free: softrod.actuation_jacobian(s))[0])
        rows["jacobian_contact"].append(timed(lambda s=s_contact: softrod.actuation_jacobian(s))[0])
        dt, inv = timed(lambda p=target: softrod.inverse_statics(free, p, throw=False))
        rows["free_cold"].append(dt)
        misses["free_cold"] += not inv.converged
        dt, cold = timed(lambda p=target: softrod.inverse_statics(robot, p, throw=False))
        rows["cold"].append(dt)
        misses["cold"] += not cold.converged
        moved = target + np.array([0.0, 0.0, 1e-3])
        dt, warm = timed(
            lambda m=moved, c=cold: softrod.inverse_statics(robot, m, warm_start=c, throw=False)
        )
        rows["warm"].append(dt)
        misses["warm"] += not warm.converged
    labels = {
        "forward": "forward solve, no obstacle",
        "forward_contact": f"forward solve, {args.obstacle}",
        "jacobian": "actuation_jacobian, no obstacle",
        "jacobian_contact": f"actuation_jacobian, {args.obstacle} (contacts held)",
        "free_cold": "inverse_statics, no obstacle, cold",
        "cold": f"inverse_statics, {args.obstacle}, cold",
        "warm": f"inverse_statics, {args.obstacle}, warm (1 mm)",
    }
    print(f"{len(targets)} targets touching the {args.obstacle}; medians (ms)")
    for k in keys:
        miss = f"  not converged {misses[k]}/{len(targets)}" if k in misses else ""
        print(f"{labels[k]:<52} {1e3 * statistics.median(rows[k]):9.3f}{miss}")


if __name__ == "__main__":
    main()
