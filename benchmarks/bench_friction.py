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
    release = [3.0, 0, 0, 0, 2.0, 0]
    print(
        f"{'case':<30} {'frictionless (us)':>18} {'frictional (us)':>16} {'ratio':>6} {'solves':>7}"
    )
    for mu in (0.05, 0.1, 0.2):
        r = robot(mu)
        first = r.solve()
        cases = [
            (f"mu = {mu}, from rest", plain.solve, r.solve, first),
            (
                f"mu = {mu}, unloading step",
                lambda: plain.solve(release),
                lambda r=r, p=first: r.solve(release, previous=p),
                r.solve(release, previous=first),
            ),
        ]
        for label, base_fn, fn, sol in cases:
            # Side by side: the frictionless and the frictional solve timed in turn.
            base = median_time(base_fn, calls=a.calls, repeats=a.repeats)
            t = median_time(fn, calls=a.calls, repeats=a.repeats)
            print(
                f"{label:<30} {base * 1e6:18.1f} {t * 1e6:16.1f} {t / base:6.2f} "
                f"{sol.friction_iterations:7d}"
            )


if __name__ == "__main__":
    main()
