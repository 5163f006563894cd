"""Benchmark of the frictional solve against the frictionless one on the two-segment NiTi robot;
prints a table of medians and their ratio (both timed side by side in one run).

Run: ``python benchmarks/bench_friction.py`` (after ``pip install .``).
"""

from __future__ import annotations

import argparse

from _timing import median_time

import softrod


def robot(mu: float) -> softrod.Robot:
    base = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    spec = base.spec.model_dump(mode="python", exclude_none=True)
    for t in spec["tendons"]:
        t["friction"] = mu
    return softrod.Robot.from_dict(spec)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--calls", type=int, default=50)
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    plain = robot(0.0)
    base = median_time(plain.solve, calls=a.calls, repeats=a.repeats)
    print(f"{'case':<34} {'median (us)':>12} {'ratio':>7} {'rod solves':>11}")
    print(f"{'frictionless':<34} {base * 1e6:12.1f} {1.0:7.2f} {1:11d}")
    for mu in (0.05, 0.1, 0.2):
        r = robot(mu)
        t = median_time(r.solve, calls=a.calls, repeats=a.repeats)
        its = r.solve().friction_iterations
        print(f"{f'friction mu = {mu} (from rest)':<34} {t * 1e6:12.1f} {t / base:7.2f} {its:11d}")
        first = r.solve()
        unload = r.solve([3.0, 0, 0, 0, 2.0, 0], previous=first)
        t = median_time(
            lambda r=r, p=first: r.solve([3.0, 0, 0, 0, 2.0, 0], previous=p),
            calls=a.calls,
            repeats=a.repeats,
        )
        label = f"friction mu = {mu} (unloading step)"
        print(f"{label:<34} {t * 1e6:12.1f} {t / base:7.2f} {unload.friction_iterations:11d}")


if __name__ == "__main__":
    main()
