"""The ``softrod`` command line.

Subcommands:
    demo    the seed-000 arm at several tensions: a table and a PNG of the backbones;
    planar  the planar tapered cable arm with any parameters;
    solve   the Cosserat statics of a robot description file (TOML).
    materials  the silicone library: parameters and sources;
    fit     fit material laws to a uniaxial tensile curve (CSV), print parameters and errors.

Bad input exits with status 2 and a one-line message naming the parameter.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

import numpy as np

from ._core import ConvergenceError, ParameterError, PlanarCableArm, PlanarSolution

SEED = PlanarCableArm.seed_arm()
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
        from .io import write_samples_csv

        write_samples_csv(args.csv, sols)
        print(f"wrote {args.csv}", file=sys.stderr)
    if getattr(args, "json", False):
        from .io import solution_to_dict

        print(json.dumps({"arm": _arm_dict(arm), "solutions": [solution_to_dict(s) for s in sols]}))
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from .plot import plot_planar

        fig = plot_planar(arm, sols)
        fig.savefig(args.plot, dpi=130)
        print(f"wrote {args.plot}", file=sys.stderr)


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
    arm = SEED
    args.method, args.rtol, args.atol, args.n_points = "closed-form", 1e-8, 1e-10, 201
    args.json, args.csv = False, None
    sols = _solve_all(arm, DEMO_TENSIONS, args)
    print("softrod demo: seed-000 tapered cable-driven arm, closed form, 201 samples")
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


def _cmd_solve(args) -> int:
    from .robot import load_robot

    robot = load_robot(args.robot)
    if args.tensions is not None:
        robot = robot.with_tensions(args.tensions)
    sol = robot.solve()
    p, r = sol.tip_position, sol.tip_rotation
    q = sol.quaternion[-1]
    st = sol.stats
    print(f"robot: {robot.name} ({args.robot})")
    if robot.description:
        print(f"  {robot.description}")
    print(f"tip position (m):   [{p[0]: .9f}, {p[1]: .9f}, {p[2]: .9f}]")
    print("tip rotation (body -> world):")
    for row in r:
        print(f"  [{row[0]: .9f}, {row[1]: .9f}, {row[2]: .9f}]")
    print(f"tip quaternion [x, y, z, w]: [{q[0]: .9f}, {q[1]: .9f}, {q[2]: .9f}, {q[3]: .9f}]")
    if len(robot.tendons):
        lengths = ", ".join(f"{x:.9f}" for x in sol.tendon_lengths)
        print(f"tendon path lengths (m): [{lengths}]")
    print(
        f"solver: converged={st['converged']}, iterations={st['iterations']}, "
        f"residual={st['residual']:.2e}, evaluations={st['function_evaluations']}, "
        f"load steps={st['load_steps']}"
    )
    if args.csv:
        from .io import write_statics_csv

        write_statics_csv(args.csv, sol)
        print(f"wrote {args.csv}", file=sys.stderr)
    if args.json:
        from .io import statics_to_dict

        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump({"robot": robot.name, "solution": statics_to_dict(sol)}, fh)
        print(f"wrote {args.json}", file=sys.stderr)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from .plot import plot_rod

        fig = plot_rod(sol, title=f"{robot.name}: tip at {np.round(p * 1e3, 2)} mm")
        fig.savefig(args.plot, dpi=130)
        print(f"wrote {args.plot}", file=sys.stderr)
    return 0


def _fmt6(m) -> str:
    return "\n".join("  [" + ", ".join(f"{v: .4e}" for v in row) + "]" for row in m)


def _cmd_compliance(args) -> int:
    from . import compliance, eigenscrews, tangent_compliance
    from .robot import load_robot

    robot = load_robot(args.robot)
    if args.tensions is not None:
        robot = robot.with_tensions(args.tensions)
    sol = robot.solve()
    comp = compliance(sol)
    print(f"robot: {robot.name} ({args.robot}); tip at {np.round(sol.tip_position * 1e3, 3)} mm")
    print("twist [dp; dtheta] = C [f; m], wrench applied at the tip (SI units)")
    print("integrated tip compliance, world frame (seed eq. 6):")
    print(_fmt6(comp.tip_world))
    print("integrated tip compliance, body frame (seed eq. 7):")
    print(_fmt6(comp.tip_body))
    print(f"condition number (1-norm): {comp.tip_condition:.3e}")
    g = comp.gamma_c[-1]
    print(f"gamma_c at the tip (body x, y, z): [{g[0]:.4f}, {g[1]:.4f}, {g[2]:.4f}]")
    for mode in ("tension", "length"):
        t = tangent_compliance(sol, mode)
        print(f"exact tangent tip compliance, tendons at fixed {mode}, world frame:")
        print(_fmt6(t.world))
    es = eigenscrews(comp.tip_stiffness_world)
    print(
        "eigenstiffnesses of the tip stiffness (world):", ", ".join(f"{v:.4e}" for v in es.values)
    )
    print("pitches (m/rad):", ", ".join(f"{v:.4e}" for v in es.pitches))
    if args.plot or args.gamma_plot:
        import matplotlib

        matplotlib.use("Agg")
        from .plot import plot_compliance_ellipsoids, plot_gamma_c

        if args.plot:
            plot_compliance_ellipsoids(
                sol, comp, title=f"{robot.name}: translational compliance"
            ).savefig(args.plot, dpi=130)
            print(f"wrote {args.plot}", file=sys.stderr)
        if args.gamma_plot:
            plot_gamma_c(comp, title=f"{robot.name}: dimensionless flexural compliance").savefig(
                args.gamma_plot, dpi=130
            )
            print(f"wrote {args.gamma_plot}", file=sys.stderr)
    return 0


def _cmd_workspace(args) -> int:
    import time

    from .robot import load_robot
    from .workspace import tension_grid, workspace_map

    robot = load_robot(args.robot)
    axes = {}
    for spec in args.sweep:
        try:
            idx, top = spec.split(":")
            axes[int(idx)] = np.linspace(0.0, float(top), args.n)
        except ValueError:
            raise ParameterError(
                f"invalid parameter `--sweep` = {spec!r}: must be INDEX:MAX_TENSION"
            ) from None
        if not 0 <= int(idx) < len(robot.tendons):
            raise ParameterError(f"invalid parameter `--sweep` = {spec!r}: no tendon {idx}")
    grid = tension_grid(len(robot.tendons), axes)
    opts = {
        k: v
        for k, v in robot.solver.items()
        if k in ("integrator", "steps", "rtol", "atol", "tolerance")
    }
    t0 = time.perf_counter()
    wmap = workspace_map(
        robot.rod,
        robot.tendons,
        grid,
        robot.loads,
        progress=args.progress,
        tangent=args.tangent,
        **opts,
    )
    dt = time.perf_counter() - t0
    ok = wmap.converged
    print(f"robot: {robot.name} ({args.robot}); {len(grid)} configurations in {dt:.3f} s")
    print(f"converged: {int(ok.sum())}/{len(grid)}")
    # Centre: the tip closest to the rod's base axis; periphery: the farthest.
    r = np.linalg.norm(wmap.tip_position[:, :2], axis=1)
    r[~ok] = np.nan
    measures = [("integrated", wmap.max_translational_compliance)]
    if args.tangent:
        name = f"tangent, tendons at fixed {args.tangent}"
        measures.append((name, wmap.tangent_max_translational_compliance))
    for name, c in measures:
        lo, hi = np.nanmin(c), np.nanmax(c)
        centre, edge = c[np.nanargmin(r)], c[np.nanargmax(r)]
        print(f"largest translational tip compliance ({name}, m/N): min {lo:.4e}, max {hi:.4e}")
        print(f"  centre of the workspace {centre:.4e}, periphery {edge:.4e}: x{edge / centre:.2f}")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from .plot import plot_workspace_map

        measure = (
            "tangent_max_translational_compliance"
            if args.tangent
            else "max_translational_compliance"
        )
        plot_workspace_map(
            wmap, measure=measure, title=f"{robot.name}: {len(grid)} configurations"
        ).savefig(args.plot, dpi=130)
        print(f"wrote {args.plot}", file=sys.stderr)
    return 0


_TERMS_MODELS = ("yeoh", "ogden")


def _fmt_parameters(parameters: dict) -> str:
    """``c10 = 21589.8 Pa, ...``; Ogden exponents and reference strains are dimensionless."""
    parts = []
    for name, value in parameters.items():
        unit = "" if name in ("alpha", "reference_strain") else " Pa"
        if isinstance(value, list):
            parts.append(f"{name} = [{', '.join(f'{v:.6g}' for v in value)}]{unit}")
        else:
            parts.append(f"{name} = {value:.6g}{unit}")
    return ", ".join(parts)


def _cmd_materials(args) -> int:
    from ._core import SILICONES, silicone

    entries = [silicone(name) for name in SILICONES]
    if args.json:
        out = []
        for e in entries:
            mr = e.mooney_rivlin
            out.append(
                {
                    "name": e.name,
                    "neo_hookean": e.neo_hookean.parameters,
                    "mooney_rivlin": mr.parameters if mr is not None else None,
                    "yeoh": e.yeoh.parameters,
                    "fit_stretch_range": e.fit_stretch_range,
                    "source": e.source,
                }
            )
        print(json.dumps(out, indent=2))
        return 0
    import textwrap

    sources: list[str] = []
    cols = ("NH mu", "MR c10", "MR c01", "Yeoh c10", "Yeoh c20", "Yeoh c30", "E0 Yeoh")
    head = f"{'material':<15}" + "".join(f"  {c:>9}" for c in cols)
    head += f"  {'fitted stretch':>14}  source"
    print("softrod silicone library: parameters in kPa (E0 = small-strain Young's modulus)")
    print(head)
    print("-" * len(head))
    for e in entries:
        if e.source not in sources:
            sources.append(e.source)
        mr, y = e.mooney_rivlin, e.yeoh
        values = [e.neo_hookean.mu, None, None, y.c10, y.c20, y.c30, y.small_strain_modulus]
        if mr is not None:
            values[1:3] = [mr.c10, mr.c01]
        cells = "".join(f"  {v / 1e3:9.4g}" if v is not None else f"  {'-':>9}" for v in values)
        rng = e.fit_stretch_range
        rng_text = f"{rng[0]:g} to {rng[1]:g}" if rng is not None else "-"
        print(f"{e.name:<15}{cells}  {rng_text:>14}  [{sources.index(e.source) + 1}]")
    for i, text in enumerate(sources, start=1):
        print(textwrap.fill(text, width=100, initial_indent=f"[{i}] ", subsequent_indent="    "))
    return 0


def _cmd_fit(args) -> int:
    from pathlib import Path

    from .materials import _bad, read_tensile_csv

    if not Path(args.file).is_file():
        raise _bad("FILE", repr(args.file), "an existing file")
    curve = read_tensile_csv(
        args.file,
        columns=args.columns,
        strain_measure=args.strain_measure,
        stress_measure=args.stress_measure,
        strain_unit=args.strain_unit,
        stress_unit=args.stress_unit,
    )
    stretch = curve.stretch
    stretch_range = None
    if args.stretch_min is not None or args.stretch_max is not None:
        stretch_range = (
            args.stretch_min if args.stretch_min is not None else float(stretch.min()),
            args.stretch_max if args.stretch_max is not None else float(stretch.max()),
        )
    print(
        f"data: {args.file}: {len(curve)} points, {curve.strain_measure} strain, "
        f"{curve.stress_measure} stress, stretch {stretch.min():.4g} to {stretch.max():.4g}"
    )
    fits = []
    for model in args.model:
        key = model.lower().replace("_", "-")
        terms = args.terms if (len(args.model) == 1 or key in _TERMS_MODELS) else None
        fit = curve.fit(
            model, terms=terms, nonnegative=args.nonnegative, stretch_range=stretch_range
        )
        fits.append(fit)
        law = fit.model
        lo, hi = fit.stretch_range
        print(f"\n{law.model_name}: {_fmt_parameters(fit.parameters)}")
        print(f"  small-strain modulus E0 = {law.small_strain_modulus:.6g} Pa")
        print(f"  fitted points: {fit.points}, stretch {lo:.4g} to {hi:.4g}")
        print(
            f"  {fit.stress_measure} stress error: RMS {fit.rms / 1e3:.4g} kPa, "
            f"max |residual| {fit.max_abs_residual / 1e3:.4g} kPa, R^2 {fit.r_squared:.6f}"
        )
        try:
            law.check_stable(lo, hi)
            print("  stable on the fitted range (dP/dstretch > 0): yes")
        except ParameterError as exc:
            print(f"  stable on the fitted range (dP/dstretch > 0): no ({exc})")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from .plot import plot_fit

        fig = plot_fit(curve, fits)
        fig.savefig(args.plot, dpi=130)
        print(f"wrote {args.plot}", file=sys.stderr)
    return 0


def _cmd_study(args) -> int:
    from .study import seed001_study

    seed001_study(args.robot, levels=args.levels, max_pressure=args.max_pressure, out_dir=args.out)
    return 0


def _cmd_compare(args) -> int:
    from .models import compare_models

    comp = compare_models(args.robot, tensions=args.tensions, repeats=args.repeats)
    print(f"robot: {comp.robot} ({args.robot}); differences relative to Cosserat")
    print(comp.table())
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from .plot import plot_models

        plot_models(comp).savefig(args.plot, dpi=130)
        print(f"wrote {args.plot}", file=sys.stderr)
    return 0


def _positive_int(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``softrod`` command (also used to document the CLI)."""
    p = argparse.ArgumentParser(
        prog="softrod",
        description="Statics of soft and continuum robots (SI units: m, N, Pa, rad).",
    )
    sub = p.add_subparsers(dest="command", required=True)

    d = sub.add_parser("demo", help="seed-000 arm at several tensions: table and PNG")
    d.add_argument(
        "--plot",
        default="softrod-demo.png",
        metavar="FILE",
        help="PNG of backbones and profiles (default: %(default)s)",
    )
    d.set_defaults(func=_cmd_demo)

    pl = sub.add_parser("planar", help="planar tapered cable-driven arm (seed 000)")
    pl.add_argument("--length", type=float, default=SEED.length, help="arm length L (m)")
    pl.add_argument("--base-radius", type=float, default=SEED.base_radius, help="R0 (m)")
    pl.add_argument("--tip-radius", type=float, default=SEED.tip_radius, help="RL (m)")
    pl.add_argument(
        "--offset-ratio",
        type=float,
        default=SEED.offset_ratio,
        help="cable offset ratio a in [0, 1)",
    )
    pl.add_argument("--youngs-modulus", type=float, default=SEED.youngs_modulus, help="E (Pa)")
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
    pl.add_argument("--method", choices=("closed-form", "ode"), default="closed-form")
    pl.add_argument("--rtol", type=float, default=1e-8, help="ODE relative tolerance")
    pl.add_argument("--atol", type=float, default=1e-10, help="ODE absolute tolerance (1/m)")
    pl.add_argument("--plot", metavar="FILE", help="PNG of backbones and profiles")
    pl.add_argument("--csv", metavar="FILE", help="write all samples to CSV")
    pl.add_argument("--json", action="store_true", help="print arm and samples as JSON")
    pl.set_defaults(func=_cmd_planar)

    so = sub.add_parser("solve", help="Cosserat statics of a robot description file (TOML)")
    so.add_argument("robot", metavar="ROBOT.toml", help="robot description file")
    so.add_argument(
        "--tensions",
        type=float,
        nargs="+",
        metavar="T",
        help="override the tendon tensions (N), one per tendon",
    )
    so.add_argument("--plot", metavar="FILE", help="PNG of the 3-D backbone")
    so.add_argument("--csv", metavar="FILE", help="write the solution samples to CSV")
    so.add_argument("--json", metavar="FILE", help="write the solution to JSON")
    so.set_defaults(func=_cmd_solve)

    ma = sub.add_parser("materials", help="the silicone library: parameters and sources")
    ma.add_argument("--json", action="store_true", help="print the library as JSON")
    ma.set_defaults(func=_cmd_materials)

    fi = sub.add_parser("fit", help="fit material laws to a uniaxial tensile curve (CSV)")
    fi.add_argument(
        "file",
        metavar="FILE",
        help="Soft Robotics Materials Database CSV, or a plain two-column CSV (strain, stress)",
    )
    fi.add_argument(
        "-m",
        "--model",
        nargs="+",
        default=["yeoh"],
        metavar="MODEL",
        help="neo-hookean, mooney-rivlin, yeoh, ogden or linearised; several to compare "
        "(default: yeoh)",
    )
    fi.add_argument("--terms", type=int, help="Yeoh coefficients (1-3, default 3) or Ogden terms")
    fi.add_argument("--nonnegative", action="store_true", help="constrain coefficients >= 0")
    fi.add_argument("--stretch-min", type=float, help="fit only points with stretch >= this")
    fi.add_argument("--stretch-max", type=float, help="fit only points with stretch <= this")
    fi.add_argument(
        "--columns",
        default="engineering",
        help="database files: engineering (default) or true columns",
    )
    fi.add_argument(
        "--strain-measure",
        default="engineering",
        help="plain files: engineering (default), stretch or logarithmic",
    )
    fi.add_argument(
        "--stress-measure", default="nominal", help="plain files: nominal (default) or true"
    )
    fi.add_argument(
        "--strain-unit", default="fraction", help="plain files: fraction (default) or percent"
    )
    fi.add_argument(
        "--stress-unit", default="Pa", help="plain files: Pa (default), kPa, MPa or GPa"
    )
    fi.add_argument("--plot", metavar="FILE", help="PNG of data, fitted curves and residuals")
    fi.set_defaults(func=_cmd_fit)

    co = sub.add_parser(
        "compliance", help="tip compliance/stiffness of a robot file (integrated and tangent)"
    )
    co.add_argument("robot", help="robot description file (TOML)")
    co.add_argument("--tensions", type=float, nargs="+", help="override the tendon tensions (N)")
    co.add_argument("--plot", metavar="FILE", help="PNG of compliance ellipsoids along the arm")
    co.add_argument("--gamma-plot", metavar="FILE", help="PNG of gamma_c(s) per body axis")
    co.set_defaults(func=_cmd_compliance)

    cm = sub.add_parser(
        "compare", help="solve a robot file with every applicable model (Cosserat, PCC, planar)"
    )
    cm.add_argument("robot", metavar="ROBOT.toml", help="robot description file (TOML)")
    cm.add_argument("--tensions", type=float, nargs="+", help="override the tendon tensions (N)")
    cm.add_argument("--plot", metavar="FILE", help="PNG of the overlaid backbones")
    cm.add_argument(
        "--repeats",
        type=_positive_int,
        default=5,
        help="timed solves per model, median reported (default: %(default)s)",
    )
    cm.set_defaults(func=_cmd_compare)

    ws = sub.add_parser("workspace", help="workspace map: sweep tensions, tip stiffness measures")
    ws.add_argument("robot", help="robot description file (TOML)")
    ws.add_argument(
        "--sweep",
        action="append",
        required=True,
        metavar="INDEX:MAX",
        help="tendon index and largest tension (N), swept from 0; once or twice",
    )
    ws.add_argument("--n", type=_positive_int, default=100, help="grid points per swept tendon")
    ws.add_argument("--plot", metavar="FILE", help="PNG of the map")
    ws.add_argument("--progress", action="store_true", help="progress bar on stderr")
    ws.add_argument(
        "--tangent",
        choices=("tension", "length"),
        help="also the exact tangent compliance (tendons at fixed tension or length)",
    )
    ws.set_defaults(func=_cmd_workspace)
    st = sub.add_parser(
        "study",
        help="seed 001's study: workspace stiffness map and gamma_c vs pressure, "
        "hyperelastic vs linear",
    )
    st.add_argument(
        "robot",
        nargs="?",
        default="examples/robots/seed001_pneumatic_arm.toml",
        metavar="ROBOT.toml",
        help="robot with three chamber pairs (default: %(default)s)",
    )
    st.add_argument(
        "--levels",
        type=_positive_int,
        default=13,
        help="pressure levels per pair (default: %(default)s)",
    )
    st.add_argument(
        "--max-pressure",
        type=float,
        default=60e3,
        help="largest pair pressure, Pa (default: %(default)s)",
    )
    st.add_argument(
        "--out",
        default="softrod-study",
        metavar="DIR",
        help="folder for the figures (default: %(default)s)",
    )
    st.set_defaults(func=_cmd_study)
    return p


def _run_closing_figures(args) -> int:
    """Runs a command and closes the figures it opened (only those: an in-process caller keeps
    its own)."""
    plt = sys.modules.get("matplotlib.pyplot")
    before = set(plt.get_fignums()) if plt else set()
    try:
        return args.func(args)
    finally:
        plt = sys.modules.get("matplotlib.pyplot")
        if plt is not None:
            for num in set(plt.get_fignums()) - before:
                plt.close(num)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``softrod`` console script; returns the exit status."""
    args = build_parser().parse_args(argv)
    try:
        return _run_closing_figures(args)
    except ParameterError as exc:
        print(f"softrod: error: {exc}", file=sys.stderr)
        return 2
    except ConvergenceError as exc:
        print(f"softrod: error: {exc}", file=sys.stderr)
        return 3
    except BrokenPipeError:  # e.g. `softrod planar --json | head`
        sys.stderr.close()
        return 0
    except OSError as exc:
        print(f"softrod: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
