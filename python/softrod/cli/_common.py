"""Helpers shared by the command modules."""

from __future__ import annotations

import argparse
import sys

#: Resolution of figures written by the command line unless ``--dpi`` says otherwise.
DEFAULT_DPI = 130


def save_figure(fig, path: str, dpi: float | None = DEFAULT_DPI, args=None) -> None:
    """Writes ``fig`` to ``path`` (format from the extension: png, pdf, svg) and says so on
    stderr; ``args`` with ``--dpi`` overrides ``dpi``."""
    from ..plot import save_figure as _save

    if args is not None and getattr(args, "dpi", None) is not None:
        dpi = args.dpi
    _save(fig, path, dpi=dpi)
    print(f"wrote {path}", file=sys.stderr)


def figure_options(args) -> dict:
    """``size``, ``dpi`` and ``style`` keyword arguments of the plot functions from the
    options added by :func:`add_figure_options`."""
    size = getattr(args, "size", None)
    return {
        "size": tuple(size) if size else None,
        "dpi": getattr(args, "dpi", None),
        "style": getattr(args, "style", None),
    }


def add_figure_options(parser: argparse.ArgumentParser, *dests: str) -> None:
    """Adds ``--dpi``, ``--size W H`` and ``--style`` to a subcommand, and checks them and the
    figure paths in ``dests`` (format from the extension: png, pdf, svg) before the command
    does any work. Call it after ``set_defaults(func=...)``."""
    from ..plot._figure import FIGURE_FORMATS

    g = parser.add_argument_group(
        "figure options", f"figure formats from the file extension: {', '.join(FIGURE_FORMATS)}"
    )
    g.add_argument("--dpi", type=float, help="resolution of PNG figures (default: 130)")
    g.add_argument("--size", type=float, nargs=2, metavar=("W", "H"), help="figure size in inches")
    g.add_argument("--style", help="matplotlib style name or .mplstyle file (e.g. seaborn-v0_8)")
    run = parser.get_default("func")

    def checked(args):
        from ..plot._figure import check_dpi, check_figure_path, check_size, check_style

        for dest in dests:
            path = getattr(args, dest, None)
            if path:
                check_figure_path(path, "--" + dest.replace("_", "-"))
        check_size(args.size)
        check_dpi(args.dpi)
        check_style(args.style)
        return run(args)

    parser.set_defaults(func=checked)


def use_agg() -> None:
    """Selects matplotlib's non-interactive backend (the CLI only writes files)."""
    import matplotlib

    matplotlib.use("Agg")


def _positive_int(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None


def _fmt6(m) -> str:
    return "\n".join("  [" + ", ".join(f"{v: .4e}" for v in row) + "]" for row in m)
