"""The inverse statics from several starts on generated curled arms.

Tapered soft arms (0.1 to 0.5 m, base radius 3 to 10 mm, tip 0.3 to 1 times the base, E 0.1 to
10 MPa) with 2, 3 or 4 tendons at 0.8 times the tip radius, at random angles; one tendon pulled
to curl the tip 0.1 to 5 turns (at the tip's stiffness), its neighbour pulled by up to as much
in half of the arms. The target is the forward solve's tip at those tensions. Per number of
starts: targets missed (``TargetUnreachableError``), answers reached with a larger norm than the
known tensions (another local minimum), and the median time per arm.

    python benchmarks/inverse_starts.py [ARMS] [SEED]
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

import softrod

STARTS = (1, 4, 8, 16)


def arm(rng: np.random.Generator) -> tuple[softrod.Robot, np.ndarray]:
    """A random curled arm and its known tensions (N)."""
    length = rng.uniform(0.1, 0.5)
    base = rng.uniform(0.003, 0.01)
    tip = base * rng.uniform(0.3, 1.0)
    modulus = 10 ** rng.uniform(5, 7)
    rod = softrod.Rod(
        length, softrod.TaperedCircularSection(base, tip), softrod.LinearElastic(modulus, 0.5)
    )
    d = 0.8 * tip
    n = int(rng.choice([2, 3, 4]))
    angles = np.arange(n) * 2 * np.pi / n + rng.uniform(0, 2 * np.pi)
    tendons = [softrod.Tendon((d * np.cos(a), d * np.sin(a)), 0.0) for a in angles]
    robot = softrod.Robot(rod, tendons=tendons, name="curl")
    turns = rng.uniform(0.1, 5)
    tension = turns * 2 * np.pi * modulus * np.pi * tip**4 / 4 / (d * length)
    truth = np.zeros(n)
    k = int(rng.integers(n))
    truth[k] = tension
    truth[(k + 1) % n] = rng.uniform(0, 1) * tension * rng.integers(0, 2)
    return robot, truth


def main() -> None:
    arms = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    rng = np.random.default_rng(int(sys.argv[2]) if len(sys.argv) > 2 else 0)
    missed = dict.fromkeys(STARTS, 0)
    larger = dict.fromkeys(STARTS, 0)
    times: dict[int, list[float]] = {k: [] for k in STARTS}
    solved = 0
    for _ in range(arms):
        robot, truth = arm(rng)
        try:
            target = robot.solve(truth).tip_position
        except softrod.ParameterError:
            continue  # tensions the rod cannot take (its tendon's path turns back)
        solved += 1
        norm = 0.5 * float(truth @ truth)
        for k in STARTS:
            t0 = time.perf_counter()
            try:
                inv = softrod.inverse_statics(robot, target, starts=k)
            except softrod.TargetUnreachableError:
                missed[k] += 1
            else:
                back = robot.solve(inv.tensions).tip_position
                assert np.linalg.norm(back - target) <= 1e-9, "reported reached, is not"
                larger[k] += 0.5 * float(inv.tensions @ inv.tensions) > norm * (1 + 1e-6)
            times[k].append(time.perf_counter() - t0)
    print(f"{solved} curled arms (of {arms} generated; the others cannot take their tensions)")
    print(f"{'starts':>6} {'missed':>7} {'larger norm':>12} {'median time (s)':>16}")
    for k in STARTS:
        print(f"{k:>6} {missed[k]:>7} {larger[k]:>12} {statistics.median(times[k]):>16.4f}")


if __name__ == "__main__":
    main()
