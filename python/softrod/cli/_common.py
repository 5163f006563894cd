"""Helpers shared by the command modules: robot arguments, output files, number formats.

Each subcommand declares its file arguments with :func:`files`: ``inputs`` (read; or
``input_paths``, a function finding the files an argument names, e.g. the FILE of each
TENSIONS:FILE), ``outputs`` (written) and, among them, ``figures`` (written by matplotlib).
:func:`check_files` runs on them before any work: an output equal to an input or to another
output, an existing file without ``--overwrite`` (every command with outputs has it), a figure
with an extension matplotlib cannot write, or an output in a folder that does not exist is
refused with a named error. The one exception is the figure of ``softrod demo``: a PNG that an
earlier demo wrote (it carries :data:`DEMO_MARK` in its metadata) is replaced, any other file
is not.
"""

from __future__ import annotations

import argparse
import math
import os
import sys

from .._core import ParameterError


class UsageError(Exception):
    """A command line that argparse rejects (exit status 2)."""


class NoResultError(Exception):
    """A computation that produced nothing to report (exit status 3): every sample failed."""


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line, raised instead of exiting."""

    def error(self, message: str):  # type: ignore[override]
        raise UsageError(f"{message} (see `{self.prog} --help`)")


def bad(option: str, value: object, expected: str) -> ParameterError:
    """A ParameterError naming a command-line option, worded like the core's."""
    exc = ParameterError(f"invalid option `{option}` = {value!r}: {expected}")
    exc.parameter = option
    return exc


def files(
    parser: argparse.ArgumentParser,
    *,
    inputs=(),
    outputs=(),
    figures=(),
    folders=("out",),
    input_paths=None,
    folder_files=None,
) -> None:
    """Declares which destinations of ``parser`` are input and output files (``folders``:
    the outputs that are folders, by default ``out``) and, for a command with output files,
    adds ``--overwrite`` (unless the command declared it already). ``input_paths``, a function
    of the parsed arguments, yields ``(option, path)`` for the input files that no destination
    holds as a plain path (checked like ``inputs``); ``folder_files``, a function of the parsed
    arguments, yields ``(dest, path)`` for the files a command writes into its folder output
    ``dest`` (checked like the other outputs)."""
    if any(d not in folders for d in outputs) and "--overwrite" not in getattr(
        parser, "_option_string_actions", {}
    ):
        parser.add_argument(
            "--overwrite", action="store_true", help="replace existing output files"
        )
    parser.set_defaults(
        _inputs=tuple(inputs),
        _outputs=tuple(outputs),
        _figures=tuple(figures),
        _folders=tuple(folders),
        _input_paths=input_paths,
        _folder_files=folder_files,
    )


def option_name(dest: str) -> str:
    """``gamma_plot`` -> ``--gamma-plot`` (``robot`` and ``file`` stay positional names)."""
    if dest in ("robot", "file"):
        return dest.upper()
    return "--" + dest.replace("_", "-")


def resolve_robot(arg: str) -> str:
    """A robot argument as a file path: an existing file, or the name of a shipped example.

    Raises:
        FileNotFoundError: A path (with a folder or ``.toml``) that does not exist.
        ParameterError: A bare name that is no example (with the closest one).
    """
    from .. import examples

    if os.path.exists(arg):
        return arg
    looks_like_path = os.sep in arg or "/" in arg or arg.endswith(".toml")
    if arg.removesuffix(".toml") in examples.names():
        return str(examples.path(arg))
    if looks_like_path:
        raise FileNotFoundError(2, "No such file or directory", arg)
    try:
        return str(examples.path(arg))  # an earlier name of an example
    except ParameterError as exc:
        raise bad("ROBOT", arg, f"no such file, and {str(exc).split(': ', 1)[1]}") from None


def referenced_inputs(args: argparse.Namespace, inputs) -> list[tuple[str, str]]:
    """The files the inputs read in turn, as ``(name, path)``: the mesh files of a robot
    file's obstacles (relative to the robot file) and a ``--style`` file."""
    out: list[tuple[str, str]] = []
    style = getattr(args, "style", None)
    if isinstance(style, str) and os.path.isfile(style):
        out.append(("--style", style))
    for name, path in inputs:
        path = os.fspath(path)
        if name != "ROBOT" or not path.endswith(".toml") or not os.path.isfile(path):
            continue
        try:
            from ..io.robot_file import read_robot_toml

            tables = read_robot_toml(path)
        except (OSError, ParameterError):
            continue  # (the command reports an unreadable robot file itself)
        obstacles = tables.get("obstacles", [])
        for k, o in enumerate(obstacles if isinstance(obstacles, list) else []):
            mesh = o.get("file") if isinstance(o, dict) else None
            if isinstance(mesh, str):
                where = os.path.join(os.path.dirname(os.path.abspath(path)), mesh)
                out.append((f"ROBOT's obstacles[{k}].file", where))
    return out


def _same(a: str, b: str) -> bool:
    try:
        if os.path.exists(a) and os.path.exists(b):
            return os.path.samefile(a, b)
    except OSError:
        pass
    return os.path.realpath(a) == os.path.realpath(b)


#: PNG metadata (key ``Source``) of the figure ``softrod demo`` writes: the demo replaces a
#: file carrying it, and refuses any other existing file without ``--overwrite``.
DEMO_MARK = "softrod demo figure"


def written_by_demo(path: str) -> bool:
    """Whether ``path`` is a PNG that ``softrod demo`` wrote (its ``Source`` metadata)."""
    try:
        from PIL import Image

        with Image.open(path) as im:
            return im.format == "PNG" and im.info.get("Source") == DEMO_MARK
    except Exception:  # not an image, unreadable, or no Pillow: not the demo's
        return False


def check_files(args: argparse.Namespace) -> None:
    """Refuses, before any work, outputs that would destroy an input, another output or an
    existing file.

    Raises:
        ParameterError: Naming the option: an output equal to an input file or to another
            output, an existing file without ``--overwrite`` (except the demo's own figure),
            a figure extension matplotlib cannot write, an output that is a folder or whose
            folder does not exist.
    """
    for d in (*getattr(args, "_inputs", ()), *getattr(args, "_outputs", ())):
        if getattr(args, d, None) == "":
            raise bad(option_name(d), "", "is an empty file name")
    inputs = [
        (option_name(d), getattr(args, d))
        for d in getattr(args, "_inputs", ())
        if getattr(args, d, None)
    ]
    more = getattr(args, "_input_paths", None)
    if more is not None:
        inputs += list(more(args))
    inputs += referenced_inputs(args, inputs)
    # (dest, path, whether the path is a folder): the outputs, then the files a command
    # writes into its folder output (checked as files, named by the folder's option).
    folders = set(getattr(args, "_folders", ("out",)))
    outputs = [
        (d, getattr(args, d), d in folders)
        for d in getattr(args, "_outputs", ())
        if getattr(args, d, None)
    ]
    inside = getattr(args, "_folder_files", None)
    if inside is not None:
        outputs += [(dest, path, False) for dest, path in inside(args)]
    figures = set(getattr(args, "_figures", ()))
    seen: list[tuple[str, str]] = []
    for dest, path, is_folder in outputs:
        name = option_name(dest)
        path = os.fspath(path)
        for in_name, in_path in inputs:
            if _same(path, os.fspath(in_path)):
                raise bad(name, path, f"is the input {in_name}; refusing to overwrite it")
        for other, other_path in seen:
            if _same(path, other_path):
                raise bad(name, path, f"is also the output of {option_name(other)}")
        if is_folder:
            if os.path.exists(path) and not os.path.isdir(path):
                raise bad(name, path, "is a file (give a folder)")
            seen.append((dest, path))
            continue
        if os.path.isdir(path):
            raise bad(name, path, "is a folder (give a file name)")
        if path.endswith(("/", os.sep)):
            raise bad(name, path, "names a folder (give a file name)")
        if (
            os.path.exists(path)
            and not getattr(args, "overwrite", False)
            and not (getattr(args, "_demo", False) and written_by_demo(path))
        ):
            raise bad(name, path, "exists (pass --overwrite to replace it)")
        folder = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(folder):
            if dest not in folders:  # (a folder output is made by its command)
                raise bad(name, path, f"the folder {folder!r} does not exist")
        elif not os.access(folder, os.W_OK):
            raise bad(name, path, f"the folder {folder!r} is not writable")
        if dest in figures:
            from ..plot._figure import check_figure_path

            check_figure_path(path, name)
        seen.append((dest, path))


#: Resolution of figures written by the command line unless ``--dpi`` says otherwise.
DEFAULT_DPI = 130


def save_figure(fig, path: str, dpi: float | None = DEFAULT_DPI, args=None) -> None:
    """Writes ``fig`` to ``path`` (format from the extension: png, pdf, svg) and says so on
    stderr; ``args`` with ``--dpi`` overrides ``dpi``; the demo's PNG carries
    :data:`DEMO_MARK`. An existing file is replaced only with the command's ``--overwrite``
    (which :func:`check_files` has checked, before any work, against the same file)."""
    from ..plot import save_figure as _save

    if args is not None and getattr(args, "dpi", None) is not None:
        dpi = args.dpi
    demo = args is not None and getattr(args, "_demo", False)
    if demo and os.fspath(path).lower().endswith(".png"):
        fig.savefig(path, format="png", dpi=dpi, metadata={"Source": DEMO_MARK})
    else:
        _save(fig, path, dpi=dpi, overwrite=bool(getattr(args, "overwrite", False)))
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
    """Adds ``--dpi``, ``--size W H`` and ``--style`` to a subcommand and checks them before
    the command does any work (the figure paths ``dests`` are checked with the other files,
    see :func:`files`). Call it after ``set_defaults(func=...)``."""
    from ..plot._figure import FIGURE_FORMATS

    g = parser.add_argument_group(
        "figure options", f"figure formats from the file extension: {', '.join(FIGURE_FORMATS)}"
    )
    g.add_argument("--dpi", type=float, help="resolution of PNG figures (default: 130)")
    g.add_argument("--size", type=float, nargs=2, metavar=("W", "H"), help="figure size in inches")
    g.add_argument("--style", help="matplotlib style name or .mplstyle file (e.g. seaborn-v0_8)")
    run = parser.get_default("func")

    def checked(args):
        from ..plot._figure import check_dpi, check_pixels, check_size, check_style

        check_size(args.size)
        check_dpi(args.dpi)
        check_pixels(args.size, args.dpi)
        check_style(args.style)
        return run(args)

    parser.set_defaults(func=checked)


def use_agg() -> None:
    """Selects matplotlib's non-interactive backend (the CLI only writes files)."""
    import matplotlib

    matplotlib.use("Agg")


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    return value


def finite_float(text: str) -> float:
    """An argparse type: a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


def add_actuation(parser: argparse.ArgumentParser) -> None:
    """``--tensions`` and ``--pressures``: the robot's actuation, overriding the file's."""
    parser.add_argument(
        "--tensions",
        type=finite_float,
        nargs="+",
        metavar="T",
        help="tendon tensions (N), one per tendon, instead of the file's",
    )
    parser.add_argument(
        "--pressures",
        type=finite_float,
        nargs="+",
        metavar="P",
        help="chamber pressures (Pa, gauge), one per chamber, instead of the file's",
    )


def add_data_outputs(parser: argparse.ArgumentParser, what: str, rows: str | None = None) -> None:
    """``--csv FILE`` and ``--json FILE``; ``rows`` says what a CSV row is."""
    csv = f"write {what} to CSV" + (f" ({rows})" if rows else "")
    parser.add_argument("--csv", metavar="FILE", help=csv)
    parser.add_argument("--json", metavar="FILE", help=f"write {what} to JSON")


def load_actuated(args: argparse.Namespace):
    """The robot of ``args.robot`` with ``--tensions`` / ``--pressures`` applied."""
    from ..robot import load_robot

    robot = load_robot(args.robot)
    if getattr(args, "tensions", None) is not None:
        robot = robot.with_tensions(args.tensions)
    if getattr(args, "pressures", None) is not None:
        robot = robot.with_pressures(args.pressures)
    return robot


def write_json(path: str, data: object) -> None:
    """Writes JSON (NaN as null) and says so on stderr."""
    import json

    with open(path, "w", encoding="utf-8") as fh:
        json.dump(_json_safe(data), fh, allow_nan=False)
    print(f"wrote {path}", file=sys.stderr)


def _json_safe(x: object) -> object:
    import numpy as np

    if isinstance(x, dict):
        return {str(k): _json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_json_safe(v) for v in x]
    if isinstance(x, np.ndarray):
        return _json_safe(x.tolist())
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def write_csv(path: str, header: list[str], rows) -> None:
    """Writes a CSV table (numbers with full precision) and says so on stderr."""
    import csv

    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for row in rows:
            w.writerow([repr(float(v)) if isinstance(v, float) else v for v in row])
    print(f"wrote {path}", file=sys.stderr)


def _fmt6(m) -> str:
    return "\n".join("  [" + ", ".join(f"{v: .4e}" for v in row) + "]" for row in m)
