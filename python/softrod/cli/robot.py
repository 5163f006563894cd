"""``softrod solve``, ``softrod compliance`` and ``softrod workspace``: robot description files."""

from __future__ import annotations

import json
import sys

import numpy as np

from .._core import ParameterError
from ..plot._figure import fmt_vector
from ._common import _fmt6, _positive_int, add_figure_options, figure_options, save_figure


def _cmd_solve(args) -> int:
    from ..robot import load_robot

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
        from ..io import write_statics_csv

        write_statics_csv(args.csv, sol)
        print(f"wrote {args.csv}", file=sys.stderr)
    if args.json:
        from ..io import statics_to_dict

        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump({"robot": robot.name, "solution": statics_to_dict(sol)}, fh)
        print(f"wrote {args.json}", file=sys.stderr)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from ..plot import plot_robot

        fig = plot_robot(robot, sol, projections=args.projections, **figure_options(args))
        save_figure(fig, args.plot, args=args)
    return 0


def _cmd_compliance(args) -> int:
    from .. import compliance, eigenscrews, tangent_compliance
    from ..robot import load_robot

    robot = load_robot(args.robot)
    if args.tensions is not None:
        robot = robot.with_tensions(args.tensions)
    sol = robot.solve()
    comp = compliance(sol)
    tip = fmt_vector(sol.tip_position, scale=1e3, unit="mm", digits=6)
    print(f"robot: {robot.name} ({args.robot}); tip at {tip}")
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
        from ..plot import plot_compliance_ellipsoids, plot_gamma_c

        if args.plot:
            fig = plot_compliance_ellipsoids(
                sol,
                comp,
                s=args.at,
                robot=robot,
                title=f"{robot.name}: translational compliance",
                **figure_options(args),
            )
            save_figure(fig, args.plot, args=args)
        if args.gamma_plot:
            fig = plot_gamma_c(
                comp,
                title=f"{robot.name}: dimensionless flexural compliance",
                **figure_options(args),
            )
            save_figure(fig, args.gamma_plot, args=args)
    return 0


def _cmd_workspace(args) -> int:
    import time

    from ..analysis.workspace import tension_grid, workspace_map
    from ..robot import load_robot

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
        from ..plot import plot_workspace_map

        measure = (
            "tangent_max_translational_compliance"
            if args.tangent
            else "max_translational_compliance"
        )
        fig = plot_workspace_map(
            wmap,
            measure=measure,
            title=f"{robot.name}: {len(grid)} configurations",
            **figure_options(args),
        )
        save_figure(fig, args.plot, args=args)
    return 0


def register(sub) -> None:
    """Adds the subcommands of this module to the ``softrod`` parser."""
    so = sub.add_parser("solve", help="Cosserat statics of a robot description file (TOML)")
    so.add_argument("robot", metavar="ROBOT.toml", help="robot description file")
    so.add_argument(
        "--tensions",
        type=float,
        nargs="+",
        metavar="T",
        help="override the tendon tensions (N), one per tendon",
    )
    so.add_argument(
        "--plot", metavar="FILE", help="figure of the robot: tube, tendons, disks, chambers"
    )
    so.add_argument(
        "--projections", action="store_true", help="add the top, front and side projections"
    )
    so.add_argument("--csv", metavar="FILE", help="write the solution samples to CSV")
    so.add_argument("--json", metavar="FILE", help="write the solution to JSON")
    so.set_defaults(func=_cmd_solve)
    add_figure_options(so, "plot")
    co = sub.add_parser(
        "compliance", help="tip compliance/stiffness of a robot file (integrated and tangent)"
    )
    co.add_argument("robot", help="robot description file (TOML)")
    co.add_argument("--tensions", type=float, nargs="+", help="override the tendon tensions (N)")
    co.add_argument("--plot", metavar="FILE", help="figure of compliance ellipsoids along the arm")
    co.add_argument(
        "--at",
        type=float,
        nargs="+",
        metavar="S",
        help="arc lengths (m) of the ellipsoids (default: six nodes along the arm)",
    )
    co.add_argument("--gamma-plot", metavar="FILE", help="figure of gamma_c(s) per body axis")
    co.set_defaults(func=_cmd_compliance)
    add_figure_options(co, "plot", "gamma_plot")
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
    ws.add_argument("--plot", metavar="FILE", help="figure of the map beside the tension space")
    ws.add_argument("--progress", action="store_true", help="progress bar on stderr")
    ws.add_argument(
        "--tangent",
        choices=("tension", "length"),
        help="also the exact tangent compliance (tendons at fixed tension or length)",
    )
    ws.set_defaults(func=_cmd_workspace)
    add_figure_options(ws, "plot")
