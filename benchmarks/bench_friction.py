"""Benchmark of the frictional solve against the frictionless one on the two-segment NiTi robot;
prints a table of medians and their ratio (both timed side by side in one run). With
``--jacobian``: the actuation Jacobian of the frictional equilibrium (pull and release) against
the frictionless one instead. With ``--guides``: the two-segment NiTi robot with its tendons
through 8 disks per segment at working tensions against the same tendons in continuous
channels.

Run: ``python benchmarks/bench_friction.py`` (after ``pip install .``).
"""

from __future__ import annotations

import argparse
import statistics
import time

from _timing import median_time

import softrod

TIP_FORCE = [0.05, -0.02, 0.0]  # N, world: the loaded cases


def robot(mu: float, tip_force: list[float] | None = None) -> softrod.Robot:
    base = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    spec = base.spec.model_dump(mode="python", exclude_none=True)
    for t in spec["tendons"]:
        t["friction"] = mu
    if tip_force is not None:
        spec["loads"] = {"tip_force": tip_force}
    return softrod.Robot.from_dict(spec)


def median_cpu_time(fn, *, calls: int, repeats: int) -> float:
    """Median CPU time of the process over ``calls * repeats`` individually timed calls (s):
    on an oversubscribed machine a call of a few ms is pre-empted more often than not, and
    the CPU clock does not count the time it waits."""
    fn()  # warm up
    samples = []
    for _ in range(calls * repeats):
        t0 = time.process_time()
        fn()
        samples.append(time.process_time() - t0)
    return statistics.median(samples)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--calls", type=int, default=50)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument(
        "--clock", choices=("wall", "cpu"), default="wall", help="wall time or process CPU time"
    )
    ap.add_argument("--jacobian", action="store_true", help="time the actuation Jacobians")
    ap.add_argument("--guides", action="store_true", help="time disk-guided tendons")
    a = ap.parse_args()
    timer = median_time if a.clock == "wall" else median_cpu_time
    if a.guides:
        guides(timer, a.calls, a.repeats)
        return
    if a.jacobian:
        jacobians(timer, a.calls, a.repeats)
        return
    release = [3.0, 0, 0, 0, 2.0, 0]
    head = f"{'case':<40} {'frictionless (us)':>18} {'frictional (us)':>16}"
    print(f"{head} {'ratio':>6} {'marches':>8}")
    for tip, mu in [(None, m) for m in (0.05, 0.1, 0.2)] + [(TIP_FORCE, m) for m in (0.1, 0.2)]:
        plain = robot(0.0, tip)
        r = robot(mu, tip)
        first = r.solve()
        load = "" if tip is None else " tip force,"
        cases = [
            (f"mu = {mu},{load} from rest", plain.solve, r.solve, first),
            (
                f"mu = {mu},{load} unloading step",
                lambda plain=plain: plain.solve(release),
                lambda r=r, p=first: r.solve(release, previous=p),
                r.solve(release, previous=first),
            ),
        ]
        for label, base_fn, fn, sol in cases:
            # Side by side: the frictionless and the frictional solve timed in turn.
            base = timer(base_fn, calls=a.calls, repeats=a.repeats)
            t = timer(fn, calls=a.calls, repeats=a.repeats)
            print(
                f"{label:<40} {base * 1e6:18.1f} {t * 1e6:16.1f} {t / base:6.2f} "
                f"{sol.friction_iterations:8d}"
            )


def jacobians(timer, calls: int, repeats: int) -> None:
    """The actuation Jacobian at [3, 0, 0, 0, 1, 0] N loaded from rest: frictionless, and
    frictional (pull, release) with the frictional solve beside it."""
    tensions = [3.0, 0, 0, 0, 1.0, 0]
    head = f"{'case':<28} {'frictionless J (us)':>20} {'pull J (us)':>12} {'release J (us)':>15}"
    print(f"{head} {'frictional solve (us)':>22}")
    for tip in (None, TIP_FORCE):
        plain = robot(0.0, tip).solve(tensions)
        r = robot(0.2, tip)
        sol = r.solve(tensions)
        times = [
            timer(lambda s=plain: softrod.actuation_jacobian(s), calls=calls, repeats=repeats),
            timer(lambda s=sol: softrod.actuation_jacobian(s), calls=calls, repeats=repeats),
            timer(
                lambda s=sol: softrod.actuation_jacobian(s, direction=-1),
                calls=calls,
                repeats=repeats,
            ),
            timer(lambda r=r: r.solve(tensions), calls=calls, repeats=repeats),
        ]
        label = "mu = 0.2, " + ("unloaded" if tip is None else "tip force")
        t = [x * 1e6 for x in times]
        print(f"{label:<28} {t[0]:20.1f} {t[1]:12.1f} {t[2]:15.1f} {t[3]:22.1f}")


def guided(mu: float, per_segment: int = 8) -> softrod.Robot:
    """The NiTi robot with its tendons through equally spaced disks (coefficient ``mu``)."""
    base = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    return base.with_disk_guides(0.2 / per_segment, friction=mu)


def guides(timer, calls: int, repeats: int) -> None:
    """Disk-guided tendons (8 disks per segment) at tensions ``tau * [1, 0, 0.3, 0, 0.5, 0.1]``
    from rest, against the same tendons in continuous channels (coefficient ``mu``)."""
    head = f"{'case':<28} {'channel (us)':>14} {'guided (us)':>14}"
    print(f"{head} {'ratio':>7} {'marches':>8}")
    for mu in (0.0, 0.2):
        chan, disk = robot(mu), guided(mu)
        for tau in (0.02, 0.3, 1.0, 2.0, 4.0):
            act = [tau, 0, 0.3 * tau, 0, 0.5 * tau, 0.1 * tau]
            sol = disk.solve(act)
            base = timer(lambda r=chan, a=act: r.solve(a), calls=calls, repeats=repeats)
            t = timer(lambda r=disk, a=act: r.solve(a), calls=calls, repeats=repeats)
            label = f"mu = {mu}, tau = {tau} N"
            print(
                f"{label:<28} {base * 1e6:14.1f} {t * 1e6:14.1f} {t / base:7.1f} "
                f"{sol.friction_iterations:8d}"
            )


if __name__ == "__main__":
    main()
