"""The ``softrod`` command line.

Subcommands (one module each family; :func:`build_parser` lists them all):
    demo, planar         the planar tapered cable-driven arm (:mod:`softrod.cli.planar`);
    solve, compliance, workspace
                         robot description files (:mod:`softrod.cli.robot`);
    materials, fit       the silicone library and tensile-curve fits (:mod:`softrod.cli.materials`);
    compare, study       models side by side and the compliance study (:mod:`softrod.cli.models`);
    view                 the live 3-D view in the browser (:mod:`softrod.cli.view`).

Bad input exits with status 2 and a one-line message naming the parameter; non-convergence
exits with status 3.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from .._core import ConvergenceError, ParameterError
from . import materials, models, planar, robot, view

#: The command modules, in the order their subcommands are listed in ``softrod --help``.
COMMAND_MODULES = (planar, robot, materials, models, view)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``softrod`` command (also used to document the CLI)."""
    p = argparse.ArgumentParser(
        prog="softrod",
        description="Statics of soft and continuum robots (SI units: m, N, Pa, rad).",
    )
    sub = p.add_subparsers(dest="command", required=True)
    for module in COMMAND_MODULES:
        module.register(sub)
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
