"""Design sweeps in this process (rayon, all cores) against a Dask LocalCluster of worker
processes: equality bit for bit and throughput per core, in the same run.

Run: ``python benchmarks/bench_sweep.py`` (after ``pip install .``). Default: the two-segment
NiTi robot, 10 Young's moduli x 10 tendon distances (100 design points) x 100 x 100 tensions
of tendons 0 and 4 (10^4 actuations) = 10^6 configurations, tip pose and convergence, three
alternating repeats of each scheduler. The cluster (``--workers`` processes, one thread each)
is started before the timings; each timing is one whole ``softrod.sweep`` call. Throughput
per core: configurations / (wall time x cores used): ``os.cpu_count()`` cores in process
(limited by ``--workers`` too when given), one per worker thread on the cluster. The load
average of the machine is printed before and after (it is shared).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np
import xarray as xr

import softrod


def study(n_design_side: int, n_grid: int) -> dict:
    return dict(
        design={
            "rod.material.youngs_modulus": np.linspace(40e9, 70e9, n_design_side),
            "tendons[0].distance": np.linspace(0.006, 0.012, n_design_side),
        },
        actuation={
            "tendons[0].tension": np.linspace(0.0, 4.0, n_grid),
            "tendons[4].tension": np.linspace(0.0, 4.0, n_grid),
        },
        outputs=("tip_pose", "convergence"),
        progress=False,
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=10, help="design values per axis (2 axes)")
    ap.add_argument("--grid", type=int, default=100, help="tensions per axis (2 axes)")
    ap.add_argument("--workers", type=int, default=2, help="Dask worker processes")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    from distributed import LocalCluster

    robot = softrod.examples.load("niti_two_segment")
    kw = study(args.designs, args.grid)
    n = args.designs**2 * args.grid**2
    cores_local = os.cpu_count() or 1  # the rayon pool of this process
    print(f"robot {robot.name}; {n} configurations per sweep; {os.cpu_count()} cores")
    print(f"load average before: {os.getloadavg()}")
    # Warm up (imports, the first rayon pool) on a small sweep.
    softrod.sweep(robot, **study(2, 4))
    times = {"in process": [], "dask": []}
    results = {}
    with LocalCluster(
        n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster:
        softrod.sweep(robot, scheduler=cluster, **study(2, 4))
        for _ in range(args.repeats):
            for name, sched in (("in process", None), ("dask", cluster)):
                t0 = time.perf_counter()
                ds = softrod.sweep(robot, scheduler=sched, **kw)
                times[name].append(time.perf_counter() - t0)
                results[name] = ds
                del ds
    print(f"load average after:  {os.getloadavg()}")
    a, b = results["in process"], results["dask"]
    identical = a.identical(b)
    xr.testing.assert_identical(a, b)
    converged = int((a["status"] == 0).sum())
    print(f"results identical bit for bit: {identical}; converged {converged} of {n}")
    cores = {"in process": cores_local, "dask": args.workers}
    per_core = {}
    print(
        f"{'scheduler':<12} {'cores':>5} {'median (s)':>11} {'runs (s)':<28} {'per core (1/s)':>15}"
    )
    for name, ts in times.items():
        med = statistics.median(ts)
        per_core[name] = n / (med * cores[name])
        runs = ", ".join(f"{t:.2f}" for t in ts)
        print(f"{name:<12} {cores[name]:>5} {med:>11.2f} {runs:<28} {per_core[name]:>15.0f}")
    ratio = per_core["dask"] / per_core["in process"]
    print(f"throughput per core, dask / in process: {ratio:.3f}")


if __name__ == "__main__":
    main()
