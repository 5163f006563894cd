"""Benchmark of softrod.calibrate; prints a table of medians.

Run: ``python benchmarks/calibrate.py`` (after ``pip install .``). Cases:

* the planar cable arm (the planar cable-arm paper's model): E and a from three noise-free
  backbones of 100 points, started 30 % off;
* the two-segment NiTi tendon robot (``examples/robots/niti_two_segment.toml``): Young's modulus
  and tendon 0's distance from five noise-free backbones of 30 points each at known arc lengths
  (markers), started 10 % and 9 % off.

Side by side, the same fits with SciPy's finite-difference Jacobian (``jac="2-point"`` on the
same residuals), the baseline the exact sensitivities replace.
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np
from _timing import median_time
from scipy.optimize import least_squares

import softrod
from softrod.analysis import calibration as cal


def planar_case():
    truth = softrod.PlanarCableArm(0.27, 0.015, 0.0074, 0.3, 140e3)
    start = softrod.PlanarCableArm(0.27, 0.015, 0.0074, 0.39, 100e3)
    data = []
    for t in (0.5, 1.0, 2.0):
        sol = truth.solve(t, 100)
        data.append((t, np.column_stack([sol.x, sol.y])))
    return start, data, ["youngs_modulus", "offset_ratio"], {"youngs_modulus": 140e3}


NITI_TENSIONS = [
    [4.0, 0.0, 0.0, 0.0, 2.0, 0.0],
    [0.0, 3.0, 0.0, 0.0, 0.0, 1.0],
    [0.0, 0.0, 3.0, 1.5, 0.0, 0.0],
    [2.0, 2.0, 0.0, 0.0, 1.0, 1.0],
    [1.0, 0.0, 2.0, 2.0, 0.0, 0.5],
]


def niti_case():
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    truth = robot.with_parameters(
        {"rod.material.youngs_modulus": 50e9, "tendons[0].distance": 0.011}
    )
    s = np.linspace(0.0, 0.4, 30)
    data = [(t, np.asarray(truth.solve(t, s_out=s).position), s) for t in NITI_TENSIONS]
    start = robot.with_parameters(
        {"rod.material.youngs_modulus": 55e9, "tendons[0].distance": 0.01}
    )
    return (
        start,
        data,
        ["rod.material.youngs_modulus", "tendons[0].distance"],
        {"rod.material.youngs_modulus": 50e9},
    )


def finite_difference_fit(robot, data, names):
    """The same residuals, Jacobian by SciPy's forward differences."""
    model = cal._model_for(robot)
    meas = cal._measurements(data, None, model.dim, model.check_actuation)
    p0 = np.array([model.initial(n) for n in names])

    def fun(z):
        values = dict(zip(names, (z * p0).tolist(), strict=True))
        return cal._stack(model, values, names, meas, "arm-index")[0]

    res = least_squares(
        fun,
        np.ones(len(names)),
        jac="2-point",
        method="trf",
        xtol=1e-14,
        ftol=1e-14,
        gtol=1e-14,
        max_nfev=200,
    )
    return dict(zip(names, (res.x * p0).tolist(), strict=True)), res.nfev


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=15)
    args = ap.parse_args()
    rows = []
    for label, case in (
        ("planar arm, E + a, 3 shapes", planar_case),
        ("NiTi 2-segment, E + d0, 5 shapes", niti_case),
    ):
        robot, data, names, truth = case()
        key, want = next(iter(truth.items()))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            c = softrod.calibrate(robot, data, names)
            t_exact = median_time(
                lambda r=robot, d=data, n=names: softrod.calibrate(r, d, n),
                calls=1,
                repeats=args.repeats,
            )
            fd_values, fd_nfev = finite_difference_fit(robot, data, names)
            t_fd = median_time(
                lambda r=robot, d=data, n=names: finite_difference_fit(r, d, n),
                calls=1,
                repeats=max(3, args.repeats // 3),
            )
        rows.append(
            (
                label,
                t_exact,
                c.evaluations,
                abs(c.values[key] / want - 1),
                t_fd,
                fd_nfev,
                abs(fd_values[key] / want - 1),
            )
        )
    print(
        f"{'case':36s} {'exact ms':>9s} {'evals':>6s} {'E rel err':>10s} "
        f"{'FD ms':>8s} {'evals':>6s} {'E rel err':>10s} {'ratio':>6s}"
    )
    for label, te, ne, ee, tf, nf, ef in rows:
        print(
            f"{label:36s} {te * 1e3:9.2f} {ne:6d} {ee:10.1e} {tf * 1e3:8.2f} {nf:6d} {ef:10.1e} "
            f"{tf / te:6.1f}"
        )


if __name__ == "__main__":
    main()
