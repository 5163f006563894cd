"""``softrod compare`` and ``softrod study``: models side by side and the compliance study."""

from __future__ import annotations

from ._common import _positive_int, add_figure_options, figure_options, save_figure


def _cmd_study(args) -> int:
    from ..analysis.study import seed001_study

    seed001_study(args.robot, levels=args.levels, max_pressure=args.max_pressure, out_dir=args.out)
    return 0


def _cmd_compare(args) -> int:
    from ..analysis.models import compare_models

    comp = compare_models(args.robot, tensions=args.tensions, repeats=args.repeats)
    print(f"robot: {comp.robot} ({args.robot}); differences relative to Cosserat")
    print(comp.table())
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from ..plot import plot_models

        save_figure(plot_models(comp, **figure_options(args)), args.plot, args=args)
    return 0


def register(sub) -> None:
    """Adds the subcommands of this module to the ``softrod`` parser."""
    cm = sub.add_parser(
        "compare", help="solve a robot file with every applicable model (Cosserat, PCC, planar)"
    )
    cm.add_argument("robot", metavar="ROBOT.toml", help="robot description file (TOML)")
    cm.add_argument("--tensions", type=float, nargs="+", help="override the tendon tensions (N)")
    cm.add_argument("--plot", metavar="FILE", help="figure of the overlaid backbones")
    cm.add_argument(
        "--repeats",
        type=_positive_int,
        default=5,
        help="timed solves per model, median reported (default: %(default)s)",
    )
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
