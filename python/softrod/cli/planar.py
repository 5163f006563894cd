"""``softrod demo`` and ``softrod planar``: the planar tapered cable-driven arm."""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence

from .._core import PlanarCableArm, PlanarSolution
from ._common import _positive_int, add_figure_options, figure_options, files, save_figure

ARM = PlanarCableArm.published_arm()
DEMO_TENSIONS = (0.5, 1.0, 2.0, 3.0, 4.0)


def _table(arm: PlanarCableArm, sols: Sequence[PlanarSolution]) -> str:
    head = (
        f"{'tension (N)':>11}  {'tip x (mm)':>10}  {'tip y (mm)':>10}  "
        f"{'tip angle (deg)':>15}  {'max compr. strain (%)':>21}"
    )
    lines = [head, "-" * len(head)]
    for s in sols:
        lines.append(
            f"{s.tension:11.4g}  {s.tip[0] * 1e3:10.3f}  {s.tip[1] * 1e3:10.3f}  "
            f"{s.tip_angle * 180 / 3.141592653589793:15.3f}  "
            f"{s.max_compressive_strain * 100:21.4f}"
        )
    return "\n".join(lines)


def _describe(arm: PlanarCableArm) -> str:
    return (
        f"arm: L = {arm.length:g} m, R0 = {arm.base_radius:g} m, RL = {arm.tip_radius:g} m, "
        f"a = {arm.offset_ratio:.6g}, E = {arm.youngs_modulus:g} Pa, anchor = {arm.anchor:g} m"
    )


def _solve_all(arm: PlanarCableArm, tensions: Sequence[float], args) -> list[PlanarSolution]:
    return [
        arm.solve(t, args.n_points, method=args.method, rtol=args.rtol, atol=args.atol)
        for t in tensions
    ]


def _write_outputs(arm, sols, args) -> None:
    if getattr(args, "csv", None):
        from ..io import write_samples_csv

        write_samples_csv(args.csv, sols)
        print(f"wrote {args.csv}", file=sys.stderr)
    if getattr(args, "json", False):
        from ..io import solution_to_dict

        print(json.dumps({"arm": _arm_dict(arm), "solutions": [solution_to_dict(s) for s in sols]}))
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from ..plot import plot_planar

        fig = plot_planar(arm, sols, **figure_options(args))
        save_figure(fig, args.plot, args=args)


def _arm_dict(arm: PlanarCableArm) -> dict[str, float]:
    return {
        "length": arm.length,
        "base_radius": arm.base_radius,
        "tip_radius": arm.tip_radius,
        "offset_ratio": arm.offset_ratio,
        "youngs_modulus": arm.youngs_modulus,
        "anchor": arm.anchor,
    }


def _cmd_planar(args) -> int:
    arm = PlanarCableArm(
        args.length,
        args.base_radius,
        args.tip_radius,
        args.offset_ratio,
        args.youngs_modulus,
        args.anchor,
    )
    sols = _solve_all(arm, args.tension, args)
    if not args.json:
        print(_describe(arm))
        print(_table(arm, sols))
    _write_outputs(arm, sols, args)
    return 0


def _cmd_demo(args) -> int:
    arm = ARM
    args.method, args.rtol, args.atol, args.n_points = "closed-form", 1e-8, 1e-10, 201
    args.json, args.csv = False, None
    sols = _solve_all(arm, DEMO_TENSIONS, args)
    print(
        "softrod demo: the tapered cable-driven arm of the planar cable-arm paper, closed form, "
        "201 samples"
    )
    print(_describe(arm))
    print(_table(arm, sols))
    ode = arm.solve(DEMO_TENSIONS[-1], method="ode", rtol=1e-10, atol=1e-12)
    dk = abs(ode.curvature - sols[-1].curvature).max() / abs(sols[-1].curvature).max()
    print(
        f"final-value ODE (Bogacki-Shampine 3(2), rtol 1e-10) vs closed form at "
        f"T = {DEMO_TENSIONS[-1]:g} N: max |dk| / max k = {dk:.2e}"
    )
    _write_outputs(arm, sols, args)
    return 0


def register(sub) -> None:
    """Adds the subcommands of this module to the ``softrod`` parser."""
    d = sub.add_parser(
        "demo", help="the tapered cable-driven arm at several tensions: table and figure"
    )
    d.add_argument(
        "--plot",
        default="softrod-demo.png",
        metavar="FILE",
        help="figure of backbones and profiles (default: %(default)s)",
    )
    files(d, outputs=("plot",), figures=("plot",))
    d.set_defaults(func=_cmd_demo, _demo=True)
    add_figure_options(d, "plot")
    pl = sub.add_parser(
        "planar", help="planar tapered cable-driven arm (closed form or final-value ODE)"
    )
    pl.add_argument("--length", type=float, default=ARM.length, help="arm length L (m)")
    pl.add_argument("--base-radius", type=float, default=ARM.base_radius, help="R0 (m)")
    pl.add_argument("--tip-radius", type=float, default=ARM.tip_radius, help="RL (m)")
    pl.add_argument(
        "--offset-ratio",
        type=float,
        default=ARM.offset_ratio,
        help="cable offset ratio a in [0, 1)",
    )
    pl.add_argument("--youngs-modulus", type=float, default=ARM.youngs_modulus, help="E (Pa)")
    pl.add_argument(
        "--anchor", type=float, default=None, help="cable anchor arc length (m), default the tip"
    )
    pl.add_argument(
        "-t",
        "--tension",
        type=float,
        nargs="+",
        default=[1.0],
        metavar="T",
        help="one or more cable tensions (N)",
    )
    pl.add_argument(
        "-n",
        "--n-points",
        type=_positive_int,
        default=201,
        help="arc-length samples (default: %(default)s)",
    )
    pl.add_argument(
        "--method",
        choices=("closed-form", "ode"),
        default="closed-form",
        help="closed form (default) or the published final-value ODE",
    )
    pl.add_argument("--rtol", type=float, default=1e-8, help="ODE relative tolerance")
    pl.add_argument("--atol", type=float, default=1e-10, help="ODE absolute tolerance (1/m)")
    pl.add_argument("--plot", metavar="FILE", help="figure of backbones and profiles")
    pl.add_argument("--csv", metavar="FILE", help="write all samples to CSV")
    pl.add_argument("--json", action="store_true", help="print arm and samples as JSON")
    files(pl, outputs=("csv", "plot"), figures=("plot",))
    pl.set_defaults(func=_cmd_planar)
    add_figure_options(pl, "plot")
