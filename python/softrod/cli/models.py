"""``softrod compare`` and ``softrod study``: models side by side and the compliance study."""

from __future__ import annotations

import numpy as np

from .._core import ParameterError
from ._common import (
    _positive_int,
    add_actuation,
    add_data_outputs,
    add_figure_options,
    bad,
    figure_options,
    files,
    finite_float,
    load_actuated,
    save_figure,
    use_agg,
    write_csv,
    write_json,
)


def _study_figures(args):
    """The figures ``softrod study`` writes into ``--out``."""
    from ..analysis.study import _figure_paths

    return [("out", path) for path in _figure_paths(args.out)]


def _cmd_study(args) -> int:
    from ..analysis.study import compliance_study, levels_beyond_limit
    from ..robot import load_robot

    if args.levels < 2:
        raise bad("--levels", args.levels, "must be >= 2")
    too_many = levels_beyond_limit(args.levels)
    if too_many is not None:  # before the levels**3 grid is built
        raise bad("--levels", args.levels, too_many)

    robot = load_robot(args.robot)
    try:
        results = compliance_study(
            robot,
            levels=args.levels,
            max_pressure=args.max_pressure,
            out_dir=args.out,
            progress=True if args.progress else None,
            overwrite=args.overwrite,
        )
    except ParameterError as exc:
        prefix = f"invalid parameter `robot_path` = {robot.name!r}: "
        if not str(exc).startswith(prefix):
            raise
        raise bad("ROBOT", args.robot, str(exc).removeprefix(prefix)) from None
    if args.csv:
        header = ["material", "p1", "p2", "p3", "x", "y", "z", "max_translational_compliance"]
        rows = [
            [material, *map(float, p), *map(float, tip), float(c), int(st), err]
            for material, res in results.items()
            for p, tip, c, st, err in zip(
                res.pressures,
                res.tip_position,
                res.max_compliance,
                res.status,
                res.error,
                strict=True,
            )
        ]
        write_csv(args.csv, [*header, "status", "error"], rows)
    if args.json:
        write_json(
            args.json,
            {
                material: {
                    "pressures": res.pressures,
                    "tip_position": res.tip_position,
                    "max_translational_compliance": res.max_compliance,
                    "centre_periphery_ratio": res.centre_periphery_ratio,
                    "gamma_c_pressures": res.gamma_c_pressures,
                    "gamma_c_tip": res.gamma_c_tip,
                    "elongation": res.elongation,
                    "status": res.status,
                    "error": res.error,
                }
                for material, res in results.items()
            },
        )
    return 0


def _cmd_compare(args) -> int:
    from ..analysis.models import compare_models

    if args.repeats < 1:
        raise bad("--repeats", args.repeats, "must be >= 1")
    robot = load_actuated(args)
    comp = compare_models(robot, repeats=args.repeats)
    print(f"robot: {comp.robot} ({args.robot}); differences relative to Cosserat")
    print(comp.table())
    fields = ("tip_error", "angle_error", "backbone_max", "backbone_mean", "solve_time")
    if args.csv:
        header = ["model", "applies", "tip_x", "tip_y", "tip_z", *fields, "note"]
        rows = []
        for r in comp.results:
            tip = r.tip_position if r.tip_position is not None else np.full(3, np.nan)
            values = [float(getattr(r, f)) for f in fields]
            rows.append([r.model, int(r.applies), *map(float, tip), *values, r.note])
        write_csv(args.csv, header, rows)
    if args.json:
        write_json(
            args.json,
            {
                "robot": comp.robot,
                "models": [
                    {
                        "model": r.model,
                        "applies": r.applies,
                        "note": r.note,
                        "tip_position": r.tip_position,
                        "positions": r.positions,
                        **{f: getattr(r, f) for f in fields},
                    }
                    for r in comp.results
                ],
            },
        )
    if args.plot:
        use_agg()
        from ..plot import plot_models

        save_figure(plot_models(comp, **figure_options(args)), args.plot, args=args)
    return 0


def register(sub) -> None:
    """Adds the subcommands of this module to the ``softrod`` parser."""
    cm = sub.add_parser(
        "compare", help="solve a robot file with every applicable model (Cosserat, PCC, planar)"
    )
    cm.add_argument(
        "robot", metavar="ROBOT", help="robot description file (TOML) or a shipped example's name"
    )
    add_actuation(cm)
    cm.add_argument("--plot", metavar="FILE", help="figure of the overlaid backbones")
    cm.add_argument(
        "--repeats",
        type=_positive_int,
        default=5,
        help="timed solves per model, median reported (default: %(default)s)",
    )
    add_data_outputs(cm, "one row per model (tip, differences, time)")
    files(cm, inputs=("robot",), outputs=("csv", "json", "plot"), figures=("plot",))
    cm.set_defaults(func=_cmd_compare)
    add_figure_options(cm, "plot")
    st = sub.add_parser(
        "study",
        help="the configuration-based compliance study: workspace stiffness map and gamma_c "
        "vs pressure, hyperelastic vs linear",
    )
    st.add_argument(
        "robot",
        nargs="?",
        default="pneumatic_arm",
        metavar="ROBOT",
        help="robot with three chamber pairs, a file or a shipped example (default: %(default)s)",
    )
    st.add_argument(
        "--levels",
        type=_positive_int,
        default=13,
        help="pressure levels per pair, 2 to 215: levels**3 pressure sets per material, at "
        "most 10,000,000 (default: %(default)s)",
    )
    st.add_argument(
        "--max-pressure",
        type=finite_float,
        default=60e3,
        help="largest pair pressure, Pa (default: %(default)s)",
    )
    st.add_argument(
        "--out",
        default="softrod-study",
        metavar="DIR",
        help="folder for the figures (default: %(default)s)",
    )
    st.add_argument(
        "--progress",
        action="store_true",
        help="progress bar on stderr (default: only when stderr is a terminal)",
    )
    add_data_outputs(st, "every pressure set of both materials (pressures, tip, compliance)")
    files(st, inputs=("robot",), outputs=("csv", "json", "out"), folder_files=_study_figures)
    st.set_defaults(func=_cmd_study)
