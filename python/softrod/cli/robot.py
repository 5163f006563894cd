"""``softrod solve``, ``compliance``, ``workspace`` and ``schema``: robot description files.

``ROBOT`` is a robot file or the name of a shipped example (``softrod solve niti_two_segment``).
"""

from __future__ import annotations

import json
import math
import sys
import time

import numpy as np

from ..plot._figure import fmt_vector
from ._common import (
    NoResultError,
    _fmt6,
    _positive_int,
    add_actuation,
    add_data_outputs,
    add_figure_options,
    bad,
    figure_options,
    files,
    load_actuated,
    save_figure,
    use_agg,
    write_csv,
    write_json,
)

_ROBOT_HELP = "robot description file (TOML), or the name of a shipped example"


def _cmd_solve(args) -> int:
    robot = load_actuated(args)
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
    # Obstacles or a tip constraint: the contacts and reactions too (also in the files).
    touching = bool(robot.obstacles) or robot.tip_constraint is not None
    if touching:
        _print_contacts(robot, sol)
    print(
        f"solver: converged={st['converged']}, iterations={st['iterations']}, "
        f"residual={st['residual']:.2e}, evaluations={st['function_evaluations']}, "
        f"load steps={st['load_steps']}"
    )
    if args.csv:
        from ..io import write_statics_csv

        write_statics_csv(args.csv, sol, contacts=touching)
        print(f"wrote {args.csv}", file=sys.stderr)
    if args.json:
        from ..io import statics_to_dict

        solution = statics_to_dict(sol, contacts=touching)
        write_json(args.json, {"robot": robot.name, "solution": solution})
    if args.plot:
        use_agg()
        from ..plot import plot_robot

        fig = plot_robot(robot, sol, projections=args.projections, **figure_options(args))
        save_figure(fig, args.plot, args=args)
    return 0


def _print_contacts(robot, sol) -> None:
    """The active contacts of ``sol`` (a point ``s`` or a belt ``[a, b]``, the obstacle, the
    state, the forces and the touching point), the tip reaction and the stability verdict."""
    contacts = sol.contacts
    if contacts:
        print(f"contacts ({len(contacts)}):")
    elif robot.obstacles:
        print("contacts: none")
    for c in contacts:
        obstacle = robot.obstacles[c["obstacle"]]
        kind = obstacle.get("type") if isinstance(obstacle, dict) else type(obstacle).__name__
        kind = str(kind).lower()
        where = f"s = {c['s']:.6f} m"
        if c["length"] > 0:
            where = f"s = [{c['s']:.6f}, {c['s'] + c['length']:.6f}] m"
        tangential = fmt_vector(c["tangential_force"], digits=4, unit="N")
        point = fmt_vector(c["point"], scale=1e3, unit="mm", digits=4)
        print(
            f"  obstacle {c['obstacle']} ({kind}): {where}, {c['state']}, "
            f"normal force {c['normal_force']:.6g} N, tangential {tangential}, at {point}"
        )
    if sol.tip_reaction is not None:
        r = sol.tip_reaction
        print(
            f"tip reaction: force {fmt_vector(r[:3], digits=6, unit='N')}, "
            f"moment {fmt_vector(r[3:], digits=6, unit='N m')}"
        )
    print(f"stable: {sol.stable} (margin {sol.stability_margin:.4g})")


def _cmd_compliance(args) -> int:
    from .. import compliance, eigenscrews, tangent_compliance

    if args.at is not None and not args.plot:
        raise bad("--at", args.at, "arc lengths of the ellipsoids: needs `--plot FILE`")
    robot = load_actuated(args)
    length = float(robot.rod.length)
    for s in args.at or ():
        if not 0.0 <= s <= length:
            raise bad("--at", s, f"must be an arc length in [0, {length:g}] m")
    sol = robot.solve()
    # Everything is computed before anything is printed: an error leaves no half report.
    comp = compliance(sol)
    modes = ("tension", "length") if len(robot.tendons) else ("tension",)
    tangents = {mode: tangent_compliance(sol, mode) for mode in modes}
    es = eigenscrews(comp.tip_stiffness_world)
    tip = fmt_vector(sol.tip_position, scale=1e3, unit="mm", digits=6)
    print(f"robot: {robot.name} ({args.robot}); tip at {tip}")
    print("twist [dp; dtheta] = C [f; m], wrench applied at the tip (SI units)")
    print("integrated tip compliance, world frame (compliance-methodology paper, eq. 6):")
    print(_fmt6(comp.tip_world))
    print("integrated tip compliance, body frame (compliance-methodology paper, eq. 7):")
    print(_fmt6(comp.tip_body))
    print(f"condition number (1-norm): {comp.tip_condition:.3e}")
    g = comp.gamma_c[-1]
    print(f"gamma_c at the tip (body x, y, z): [{g[0]:.4f}, {g[1]:.4f}, {g[2]:.4f}]")
    if len(robot.tendons):
        for mode, t in tangents.items():
            print(f"exact tangent tip compliance, tendons at fixed {mode}, world frame:")
            print(_fmt6(t.world))
    else:
        print("exact tangent tip compliance, world frame (no tendons: one tangent):")
        print(_fmt6(tangents["tension"].world))
    print(
        "eigenstiffnesses of the tip stiffness (world):", ", ".join(f"{v:.4e}" for v in es.values)
    )
    print("pitches (m/rad):", ", ".join(f"{v:.4e}" for v in es.pitches))
    if args.csv:
        s = np.asarray(comp.s)
        pos = np.asarray(sol.position)
        header = ["s", "x", "y", "z", "gamma_cx", "gamma_cy", "gamma_cz", "condition"]
        header += [f"c{i}{j}" for i in range(6) for j in range(6)]
        rows = []
        for k in range(len(s)):
            node = int(np.argmin(np.abs(np.asarray(sol.s) - s[k])))
            rows.append(
                [
                    float(s[k]),
                    *map(float, pos[node]),
                    *map(float, comp.gamma_c[k]),
                    float(comp.condition[k]),
                    *map(float, np.asarray(comp.world[k]).ravel()),
                ]
            )
        write_csv(args.csv, header, rows)
    if args.json:
        write_json(
            args.json,
            {
                "robot": robot.name,
                "tip_position": sol.tip_position,
                "s": comp.s,
                "gamma_c": comp.gamma_c,
                "condition": comp.condition,
                "world": comp.world,
                "body": comp.body,
                "tip_world": comp.tip_world,
                "tip_body": comp.tip_body,
                "tip_condition": comp.tip_condition,
                "tangent_world": {mode: t.world for mode, t in tangents.items()},
                "eigenstiffness": es.values,
                "pitches": es.pitches,
            },
        )
    if args.plot or args.gamma_plot:
        use_agg()
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


#: At most this many tendons are swept by ``softrod workspace`` (a 2-D map).
MAX_SWEPT_TENDONS = 2


def _sweep_axes(specs: list[str], n_tendons: int, n: int) -> dict[int, np.ndarray]:
    """``["0:4", "1:2"]`` -> {0: linspace(0, 4, n), 1: linspace(0, 2, n)}, checked."""
    if len(specs) > MAX_SWEPT_TENDONS:
        raise bad(
            "--sweep",
            " ".join(specs),
            f"given {len(specs)} times: a map sweeps one or two tendons",
        )
    axes: dict[int, np.ndarray] = {}
    for spec in specs:
        parts = spec.split(":")
        try:
            idx, top = int(parts[0]), float(parts[1])
            if len(parts) != 2:
                raise ValueError
        except (ValueError, IndexError):
            raise bad("--sweep", spec, "must be INDEX:MAX_TENSION, e.g. 0:4") from None
        if not 0 <= idx < n_tendons:
            raise bad(
                "--sweep", spec, f"tendon index must be in [0, {n_tendons}) (the robot's tendons)"
            )
        if not (math.isfinite(top) and top > 0):
            raise bad("--sweep", spec, "the largest tension must be finite and > 0 N")
        if idx in axes:
            raise bad("--sweep", spec, f"tendon {idx} is swept twice")
        axes[idx] = np.linspace(0.0, top, n)
    return axes


def _why_not(robot, tensions, opts: dict) -> str:
    """The tensions (N) of a configuration a map did not converge at, and what a solve of it
    alone says."""
    shown = "[" + ", ".join(f"{t:.4g}" for t in tensions) + "] N"
    try:
        robot.solve(tensions=list(tensions), **opts)
    except Exception as exc:  # a named error or a ConvergenceError: shown as it is
        return f"tensions {shown}: {type(exc).__name__}: {' '.join(str(exc).split())}"
    return f"tensions {shown} (a solve of it alone converges)"


def _cmd_workspace(args) -> int:
    from ..analysis.workspace import tension_grid, workspace_map

    if args.n < 1:
        raise bad("--n", args.n, "must be >= 1")
    robot = load_actuated(args)
    if len(robot.tendons) == 0:
        why = "has no tendons to sweep"
        if robot.chambers:
            why += " (its chambers stay at the file's pressures; sweep them with `softrod study`)"
        raise bad("ROBOT", args.robot, why)
    axes = _sweep_axes(args.sweep, len(robot.tendons), args.n)
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
        progress=True if args.progress else None,
        tangent=args.tangent,
        chambers=list(robot.chambers),
        **opts,
    )
    dt = time.perf_counter() - t0
    ok = wmap.converged
    measures = [("integrated", "max_translational_compliance", wmap.max_translational_compliance)]
    if args.tangent:
        name = f"tangent, tendons at fixed {args.tangent}"
        measures.append(
            (
                name,
                "tangent_max_translational_compliance",
                wmap.tangent_max_translational_compliance,
            )
        )
    for name, _, c in measures:
        if not np.any(np.isfinite(c)):
            raise NoResultError(
                f"workspace map of {robot.name}: no configuration has a finite {name} compliance "
                f"({int(ok.sum())}/{len(grid)} converged); nothing written"
            )
    print(f"robot: {robot.name} ({args.robot}); {len(grid)} configurations in {dt:.3f} s")
    print(f"converged: {int(ok.sum())}/{len(grid)}")
    if not ok.all():
        print(f"  the first that did not: {_why_not(robot, grid[int(np.argmin(ok))], opts)}")
    # Centre: the tip closest to the rod's base axis; periphery: the farthest.
    r = np.linalg.norm(wmap.tip_position[:, :2], axis=1)
    r[~ok] = np.nan
    for name, _, c in measures:
        finite = np.isfinite(c) & np.isfinite(r)
        lo, hi = np.nanmin(c), np.nanmax(c)
        rr = np.where(finite, r, np.nan)
        print(f"largest translational tip compliance ({name}, m/N): min {lo:.4e}, max {hi:.4e}")
        inner, outer = np.nanargmin(rr), np.nanargmax(rr)
        if inner == outer:
            print("  centre and periphery: one configuration only (no ratio)")
            continue
        centre, edge = c[inner], c[outer]
        print(f"  centre of the workspace {centre:.4e}, periphery {edge:.4e}: x{edge / centre:.2f}")
    fields = ["max_translational_compliance", "min_translational_compliance", "condition"]
    if args.tangent:
        fields.append("tangent_max_translational_compliance")
    if args.csv:
        header = [f"tension_{i}" for i in range(len(robot.tendons))]
        header += ["converged", "x", "y", "z", *fields]
        header += [f"eigen_stiffness_{i}" for i in range(6)]
        rows = [
            [
                *map(float, wmap.tensions[k]),
                int(ok[k]),
                *map(float, wmap.tip_position[k]),
                *(float(getattr(wmap, f)[k]) for f in fields),
                *map(float, wmap.eigen_stiffness[k]),
            ]
            for k in range(len(grid))
        ]
        write_csv(args.csv, header, rows)
    if args.json:
        out = {
            "robot": robot.name,
            "tensions": wmap.tensions,
            "converged": ok,
            "tip_position": wmap.tip_position,
            "eigen_stiffness": wmap.eigen_stiffness,
        }
        out.update({f: getattr(wmap, f) for f in fields})
        write_json(args.json, out)
    if args.plot:
        use_agg()
        from ..plot import plot_workspace_map

        measure = measures[-1][1]
        fig = plot_workspace_map(
            wmap,
            measure=measure,
            title=f"{robot.name}: {len(grid)} configurations",
            **figure_options(args),
        )
        save_figure(fig, args.plot, args=args)
    return 0


def _cmd_schema(args) -> int:
    from ..io import robot_file_json_schema

    text = json.dumps(robot_file_json_schema(), indent=2) + "\n"
    if args.output:
        with open(args.output, "w", encoding="utf-8") as fh:
            fh.write(text)
        print(f"wrote {args.output}", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0


def register(sub) -> None:
    """Adds the subcommands of this module to the ``softrod`` parser."""
    so = sub.add_parser("solve", help="Cosserat statics of a robot description file (TOML)")
    so.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    add_actuation(so)
    so.add_argument(
        "--plot", metavar="FILE", help="figure of the robot: tube, tendons, disks, chambers"
    )
    so.add_argument(
        "--projections", action="store_true", help="add the top, front and side projections"
    )
    add_data_outputs(so, "the solution", "one row per mesh node")
    files(so, inputs=("robot",), outputs=("csv", "json", "plot"), figures=("plot",))
    so.set_defaults(func=_cmd_solve)
    add_figure_options(so, "plot")

    co = sub.add_parser(
        "compliance", help="tip compliance/stiffness of a robot file (integrated and tangent)"
    )
    co.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    add_actuation(co)
    co.add_argument("--plot", metavar="FILE", help="figure of compliance ellipsoids along the arm")
    co.add_argument(
        "--at",
        type=float,
        nargs="+",
        metavar="S",
        help="arc lengths (m) of the ellipsoids (default: six nodes along the arm)",
    )
    co.add_argument("--gamma-plot", metavar="FILE", help="figure of gamma_c(s) per body axis")
    add_data_outputs(co, "the compliance along the arm", "one row per node, C in world")
    files(
        co,
        inputs=("robot",),
        outputs=("csv", "json", "plot", "gamma_plot"),
        figures=("plot", "gamma_plot"),
    )
    co.set_defaults(func=_cmd_compliance)
    add_figure_options(co, "plot", "gamma_plot")

    ws = sub.add_parser("workspace", help="workspace map: sweep tensions, tip stiffness measures")
    ws.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    ws.add_argument(
        "--sweep",
        action="append",
        required=True,
        metavar="INDEX:MAX",
        help="tendon index and largest tension (N), swept from 0; once or twice",
    )
    ws.add_argument(
        "--n", type=_positive_int, default=100, help="grid points per swept tendon (default 100)"
    )
    ws.add_argument("--plot", metavar="FILE", help="figure of the map beside the tension space")
    ws.add_argument(
        "--progress",
        action="store_true",
        help="progress bar on stderr (default: only when stderr is a terminal)",
    )
    ws.add_argument(
        "--tangent",
        choices=("tension", "length"),
        help="also the exact tangent compliance (tendons at fixed tension or length)",
    )
    add_data_outputs(ws, "every configuration (tensions, tip, compliance measures)")
    files(ws, inputs=("robot",), outputs=("csv", "json", "plot"), figures=("plot",))
    ws.set_defaults(func=_cmd_workspace)
    add_figure_options(ws, "plot")

    sc = sub.add_parser("schema", help="the JSON Schema of robot description files")
    sc.add_argument("-o", "--output", metavar="FILE", help="write it to FILE (default: stdout)")
    files(sc, outputs=("output",))
    sc.set_defaults(func=_cmd_schema)
