"""Figure options shared by every plot: size, DPI, style, output format, titles, 3-D limits."""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .. import _args
from .._core import ParameterError

#: Output formats of :func:`save_figure`, chosen from the file's extension.
FIGURE_FORMATS = ("png", "pdf", "svg")


def _bad(parameter: str, value: object, valid: str) -> ParameterError:
    err = ParameterError(f"invalid parameter `{parameter}` = {value!r}: {valid}")
    err.parameter = parameter
    return err


def check_figure_path(
    path: str | os.PathLike[str], parameter: str = "path", formats: Sequence[str] = FIGURE_FORMATS
) -> str:
    """Checks that a figure can be written to ``path`` before any work is done.

    Args:
        path: The output file; its extension picks the format.
        parameter: The name reported in the error (e.g. ``--plot``).
        formats: Accepted extensions, without the dot.

    Returns:
        The format (the lower-case extension without the dot).

    Raises:
        ParameterError: The extension is not one of ``formats``, or the folder does not exist.
    """
    ext = Path(path).suffix.lower().lstrip(".")
    if ext not in formats:
        raise _bad(
            parameter,
            os.fspath(path),
            f"the extension picks the format and must be one of {', '.join(formats)}",
        )
    folder = Path(path).resolve().parent
    if not folder.is_dir():
        raise _bad(parameter, os.fspath(path), f"the folder {str(folder)!r} does not exist")
    return ext


def check_size(size) -> tuple[float, float] | None:
    """Validates a figure size ``(width, height)`` in inches (``None`` keeps the default)."""
    if size is None:
        return None
    try:
        w, h = (float(x) for x in size)
    except (TypeError, ValueError):
        raise _bad("size", size, "must be two numbers (width, height) in inches") from None
    if not (0.5 <= w <= 100 and 0.5 <= h <= 100):
        raise _bad("size", size, "width and height must be in [0.5, 100] inches")
    return (w, h)


#: Largest side of a figure in pixels (`size` times `dpi`); matplotlib's raster backend stops at
#: 2^16, and a larger image costs gigabytes of memory.
MAX_PIXELS_SIDE = 20_000


def check_pixels(size, dpi) -> None:
    """Refuses a raster figure whose side (``size`` inches times ``dpi``) exceeds
    :data:`MAX_PIXELS_SIDE` pixels; ``None`` values are the defaults."""
    w, h = size if size is not None else (6.4, 4.8)
    d = dpi if dpi is not None else 130.0
    side = max(w, h) * d
    if side > MAX_PIXELS_SIDE:
        raise _bad(
            "size",
            (w, h),
            f"at {d:g} dpi the figure is {side:.0f} pixels wide: at most "
            f"{MAX_PIXELS_SIDE} pixels a side (lower --size or --dpi)",
        )


def check_dpi(dpi) -> float | None:
    """Validates a resolution in dots per inch (``None`` keeps the default)."""
    if dpi is None:
        return None
    if isinstance(dpi, bool) or not isinstance(dpi, (int, float)) or not 10 <= dpi <= 2400:
        raise _bad("dpi", dpi, "must be a number in [10, 2400] dots per inch")
    return float(dpi)


def check_style(style) -> None:
    """Validates a matplotlib style: a name of ``matplotlib.style.available`` or a file."""
    if style is None:
        return
    import matplotlib.pyplot as plt

    names = [style] if isinstance(style, (str, os.PathLike)) else list(style)
    for name in names:
        if isinstance(name, dict):
            continue
        if str(name) in plt.style.available or str(name) == "default":
            continue
        if Path(name).is_file():
            try:
                import matplotlib

                matplotlib.rc_params_from_file(str(name), use_default_template=False)
            except (OSError, ValueError) as exc:  # (UnicodeDecodeError is a ValueError)
                reason = " ".join(str(exc).split())[:120]
                raise _bad(
                    "style", style, f"could not be read as a .mplstyle file ({reason})"
                ) from None
            continue
        raise _bad(
            "style",
            style,
            "must be a matplotlib style name (e.g. "
            + ", ".join(sorted(plt.style.available)[:4])
            + ", ...) or a .mplstyle file",
        )


@contextmanager
def figure_style(style) -> Iterator[None]:
    """Applies a matplotlib style while a figure is built (``None``: the current rcParams)."""
    check_style(style)
    if style is None:
        yield
        return
    import matplotlib.pyplot as plt

    with plt.style.context(style):
        yield


def new_figure(size, default: tuple[float, float], dpi=None, **kwargs):
    """A constrained-layout figure of ``size`` (inches; ``default`` when ``None``)."""
    import matplotlib.pyplot as plt

    size = check_size(size) or default
    dpi = check_dpi(dpi)
    check_pixels(size, dpi)
    kwargs.setdefault("layout", "constrained")
    fig = plt.figure(figsize=size, **({"dpi": dpi} if dpi else {}), **kwargs)
    return fig


def save_figure(
    fig, path: str | os.PathLike[str], *, dpi: float | None = None, overwrite: bool = False
) -> str:
    """Writes a figure; the format (png, pdf, svg) comes from the extension.

    Args:
        fig: The matplotlib figure.
        path: Output file (``.png``, ``.pdf`` or ``.svg``).
        dpi: Resolution of raster output (dots per inch; default: the figure's).
        overwrite: Replace an existing file at ``path`` (default: refuse).

    Returns:
        The path written, as a string.

    Raises:
        ParameterError: Unknown extension, missing folder, or ``path`` exists and
            ``overwrite`` is false (checked before writing; the file is left as it was).
        ParameterTypeError: ``overwrite`` is not True or False.
    """
    fmt = check_figure_path(path)
    dpi = check_dpi(dpi)
    if dpi is not None:
        check_pixels(tuple(fig.get_size_inches()), dpi)
    overwrite = _args.flag(overwrite, "overwrite")
    if os.path.isdir(path):
        raise _bad("path", os.fspath(path), "is a folder (give a file name)")
    if not overwrite and os.path.exists(path):
        raise _bad("path", os.fspath(path), "exists (pass overwrite=True to replace it)")
    fig.savefig(path, format=fmt, **({"dpi": dpi} if dpi else {}))
    return os.fspath(path)


def fmt_vector(v, *, scale: float = 1.0, unit: str = "", digits: int = 3) -> str:
    """A vector as ``(1.23, -4.56, 7.89) unit`` with ``digits`` significant figures; a
    component below 1e-9 of the largest (round-off: -1.79e-16 of a tip 0.15 m away) shows
    as 0."""
    values = np.ravel(np.asarray(v, dtype=float)) * scale
    largest = float(np.max(np.abs(values), initial=0.0))
    values = np.where(np.abs(values) <= 1e-9 * largest, 0.0, values)
    body = ", ".join(f"{x:.{digits}g}" for x in values)
    return f"({body}) {unit}".rstrip()


def fmt_quantity(x: float, unit: str = "", digits: int = 3) -> str:
    """A scalar as ``1.23 unit`` with ``digits`` significant figures."""
    return f"{float(x):.{digits}g} {unit}".rstrip()


def nice_number(x: float) -> float:
    """The largest of 1, 2, 2.5 or 5 times a power of ten that is at most ``x`` (> 0)."""
    if not x > 0 or not np.isfinite(x):
        return 1.0
    e = np.floor(np.log10(x))
    for m in (5.0, 2.5, 2.0, 1.0):
        if m * 10**e <= x * (1 + 1e-12):
            return float(m * 10**e)
    return float(10**e)


def nice_ceil(x: float) -> float:
    """The smallest of 1, 2, 2.5 or 5 times a power of ten that is at least ``x`` (> 0)."""
    if not x > 0 or not np.isfinite(x):
        return 1.0
    e = np.floor(np.log10(x))
    for m in (1.0, 2.0, 2.5, 5.0, 10.0):
        if m * 10**e >= x * (1 - 1e-12):
            return float(m * 10**e)
    return float(10 ** (e + 1))


def set_equal_3d(ax, pts: np.ndarray, pad: float = 0.04) -> np.ndarray:
    """Equal-aspect cube limits around ``pts`` (n, 3); returns the limits, shape (3, 2)."""
    pts = np.asarray(pts, dtype=float).reshape(-1, 3)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre, half = (lo + hi) / 2, max((hi - lo).max() / 2, 1e-9) * (1 + pad)
    limits = np.column_stack((centre - half, centre + half))
    apply_limits_3d(ax, limits)
    return limits


def apply_limits_3d(ax, limits: np.ndarray) -> None:
    """Sets x, y, z limits (rows of ``limits``, shape (3, 2)) and a cubic box."""
    ax.set_xlim(*limits[0])
    ax.set_ylim(*limits[1])
    ax.set_zlim(*limits[2])
    ax.set_box_aspect((1, 1, 1))


def as_list(solutions, name: str = "solutions") -> list:
    """A solution or a sequence of them, as a list.

    Raises:
        ParameterTypeError: Naming ``name``: neither a solution (an object with a
            ``position``) nor a sequence of them, e.g. an array of backbone points.
    """
    if hasattr(solutions, "position"):
        return [solutions]
    expected = "a statics solution (softrod.StaticsSolution) or a sequence of them"
    if isinstance(solutions, (str, bytes, dict)):
        raise _args.type_error(name, solutions, expected)
    try:
        sols = list(solutions)
    except TypeError:
        raise _args.type_error(name, solutions, expected) from None
    for i, sol in enumerate(sols):
        if not hasattr(sol, "position"):
            raise _args.type_error(
                name, solutions, f"{expected} (item {i} is a {type(sol).__name__})"
            )
    return sols
