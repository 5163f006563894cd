"""The ``softrod`` command line.

Subcommands (one module each family; :func:`build_parser` lists them all):
    demo, planar         the planar tapered cable-driven arm (:mod:`softrod.cli.planar`);
    solve, compliance, workspace
                         robot description files (:mod:`softrod.cli.robot`);
    inverse              the actuation reaching a target (:mod:`softrod.cli.command`);
    materials, fit       the silicone library and tensile-curve fits (:mod:`softrod.cli.materials`);
    compare, study       models side by side and the compliance study (:mod:`softrod.cli.models`);
    view                 the live 3-D view in the browser (:mod:`softrod.cli.view`);
    backbone             an arm's backbone from a photograph (:mod:`softrod.cli.backbone`);
    calibrate            parameters fitted to measured backbones (:mod:`softrod.cli.calibrate`);
    sweep                design studies over design and actuation grids (:mod:`softrod.cli.sweep`).

Bad input exits with status 2 and a one-line message naming the parameter; non-convergence
exits with status 3.
"""

from __future__ import annotations

import argparse
import itertools
import os
import sys
from collections.abc import Sequence

from .._core import ConvergenceError, ParameterError, __version__
from . import backbone, calibrate, command, materials, models, planar, robot, sweep, view
from ._common import NoResultError, Parser, UsageError, check_files, resolve_robot

#: The command modules, in the order their subcommands are listed in ``softrod --help``.
COMMAND_MODULES = (planar, robot, command, materials, models, view, backbone, calibrate, sweep)

#: Exit statuses: bad input (a parameter, a file's content, the command line), no convergence
#: (or no result at all), an unreadable or unwritable file, an unexpected error.
EXIT_BAD_INPUT, EXIT_NO_CONVERGENCE, EXIT_FILE, EXIT_INTERNAL = 2, 3, 1, 1


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``softrod`` command (also used to document the CLI)."""
    p = Parser(
        prog="softrod",
        description="Statics of soft and continuum robots (SI units: m, N, Pa, rad).",
        epilog="Exit status: 0 success, 2 bad input, 3 no convergence, 1 unreadable file.",
    )
    p.add_argument(
        "--version", action="version", version=f"softrod {__version__}", help="print the version"
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
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


def one_line(exc: BaseException) -> str:
    """An exception as one line: every located error of a robot file, joined by ``; ``."""
    errors = getattr(exc, "errors", None)
    if isinstance(errors, list) and len(errors) > 1:
        source = getattr(exc, "source", None)
        head = f"{source}: " if source else ""
        return f"{head}{len(errors)} invalid fields: " + "; ".join(str(e) for e in errors)
    text = str(exc) or type(exc).__name__
    return " ".join(text.split())


def _fail(message: str, status: int) -> int:
    print(f"softrod: error: {message}", file=sys.stderr)
    return status


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``softrod`` console script; returns the exit status.

    Every error is one line on stderr (``softrod: error: ...``), never a traceback, and every
    warning one line (``softrod: warning: ...``); set ``SOFTROD_DEBUG=1`` to see the traceback
    of an unexpected error.
    """
    import warnings

    with warnings.catch_warnings():
        warnings.showwarning = _show_warning
        return _main(argv)


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one line on stderr, without the source line that raised it."""
    text = " ".join(str(message).split())
    print(f"softrod: warning: {text} ({category.__name__})", file=sys.stderr)


def _dash_hint(exc: Exception, argv: Sequence[str] | None) -> str:
    """For an option that found no value where the value starts with ``-`` (argparse reads
    ``-1:1`` as an option), how to write it."""
    tokens = list(sys.argv[1:] if argv is None else argv)
    if "expected" not in str(exc):
        return ""
    for option, value in itertools.pairwise(tokens):
        if (
            option.startswith("--")
            and len(value) > 1
            and value[0] == "-"
            and value[1] in "0123456789."
        ):
            return f"; a value that starts with '-' is written {option}={value}"
    return ""


def _main(argv: Sequence[str] | None) -> int:
    try:
        args = build_parser().parse_args(argv)
        if "robot" in getattr(args, "_inputs", ()) and getattr(args, "robot", None):
            args.robot = resolve_robot(args.robot)
        check_files(args)
        return _run_closing_figures(args)
    except SystemExit as exc:  # --help and --version
        return exc.code if isinstance(exc.code, int) else 0
    except UsageError as exc:
        return _fail(one_line(exc) + _dash_hint(exc, argv), EXIT_BAD_INPUT)
    except ParameterError as exc:
        return _fail(one_line(exc), EXIT_BAD_INPUT)
    except (ConvergenceError, NoResultError) as exc:
        return _fail(one_line(exc), EXIT_NO_CONVERGENCE)
    except BrokenPipeError:  # e.g. `softrod planar --json | head`
        sys.stderr.close()
        return 0
    except OSError as exc:
        return _fail(one_line(exc), EXIT_FILE)
    except KeyboardInterrupt:
        return _fail("interrupted", 130)
    except Exception as exc:
        if os.environ.get("SOFTROD_DEBUG"):
            raise
        return _fail(f"internal error ({type(exc).__name__}: {one_line(exc)})", EXIT_INTERNAL)
