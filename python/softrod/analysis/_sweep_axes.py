"""Axes of a sweep: grids (outer products) and sample tables, named by robot-file paths.

An *axis set* is what ``softrod.sweep`` receives as ``actuation=`` or ``design=``: a mapping of
paths to 1-D grids (their outer product, one dimension per path), or a sample table (a
:func:`samples` table, a pandas ``DataFrame`` or an xarray ``Dataset`` with one dimension: one
``sample`` or ``design`` dimension). Grids are solved in boustrophedon order (the last axis
fastest, its direction reversed at every step of the axes before it) so that consecutive
samples are neighbours and warm starts help; results are stored back in grid order.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _args
from .._core import ParameterError

#: Actuation paths: tendon tensions, chamber pressures, components of the tip load.
ACTUATION_PATH = re.compile(
    r"(?:(?P<tendon>tendons)\[(?P<ti>\d+)\]\.(?P<tkey>tension|displacement)"
    r"|(?P<chamber>chambers)\[(?P<ci>\d+)\]\.pressure"
    r"|loads\.(?P<load>tip_force|tip_moment)\[(?P<k>[0-2])\])\Z"
)


def _bad(name: str, value: Any, expected: str) -> ParameterError:
    exc = ParameterError(f"invalid parameter `{name}` = {value!r}: must be {expected}")
    exc.parameter = name
    return exc


class SampleTable(Mapping):
    """A table of samples: equal-length columns named by robot-file paths.

    Build one with :func:`softrod.samples`; ``softrod.sweep`` solves its rows (one ``sample``
    dimension for an actuation table, one ``design`` dimension for a design table) instead of
    the outer product a plain dict of grids stands for. Values are in the SI units of their
    paths (tensions in N, pressures in Pa, lengths in m).

    Args:
        columns: Path -> 1-D array, all of one length.

    Attributes:
        rows: The number of samples.
    """

    def __init__(self, columns: Mapping[str, Any]) -> None:
        self._columns, self.rows = _check_columns(columns, "columns")

    def __getitem__(self, key: str) -> np.ndarray:
        return self._columns[key]

    def __iter__(self):
        return iter(self._columns)

    def __len__(self) -> int:
        return len(self._columns)

    def __repr__(self) -> str:
        return f"SampleTable(rows={self.rows}, columns={list(self._columns)})"


def _check_columns(columns: Any, name: str) -> tuple[dict[str, np.ndarray], int]:
    """The columns as 1-D float arrays of equal length, and that length."""
    if not isinstance(columns, Mapping) or not columns:
        raise _bad(name, columns, "a non-empty mapping of path -> 1-D array")
    cols = {}
    n = None
    for key, value in columns.items():
        a = _float_array(value, f"{name}[{key!r}]")
        if a.ndim != 1:
            raise _bad(f"{name}[{key!r}]", f"shape {a.shape}", "a 1-D array")
        if n is not None and len(a) != n:
            raise _bad(f"{name}[{key!r}]", f"{len(a)} rows", f"{n} rows like the others")
        n = len(a)
        cols[str(key)] = a
    if not n:
        raise _bad(name, "0 rows", "at least one row")
    return cols, n


def samples(table: Any) -> SampleTable:
    """Marks a table of samples for :func:`softrod.sweep` (rows, not an outer product).

    Args:
        table: A mapping of path -> 1-D array of equal lengths, a pandas ``DataFrame`` or an
            xarray ``Dataset`` with one dimension (its data variables and coordinates along
            it are the columns).

    Returns:
        The table.

    Raises:
        ParameterError: Columns of different lengths, not 1-D, not numbers, or no rows.
    """
    if isinstance(table, SampleTable):
        return table
    columns = _columns_of(table)
    _check_columns(columns, "table")
    return SampleTable(columns)


def _columns_of(table: Any) -> Mapping[str, Any]:
    mod = type(table).__module__.split(".")[0]
    if mod == "pandas" and hasattr(table, "columns"):
        return {str(c): table[c].to_numpy() for c in table.columns}
    if mod == "xarray" and hasattr(table, "data_vars"):
        if len(table.dims) != 1:
            raise _bad("table", f"dims {tuple(table.dims)}", "a Dataset with one dimension")
        (dim,) = table.dims
        cols = {str(k): v.values for k, v in table.variables.items() if v.dims == (dim,)}
        cols.pop(str(dim), None)
        return cols
    return table


def _float_array(value: Any, name: str) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise _bad(name, value, "numbers") from None
    if not np.all(np.isfinite(a)):
        bad = a[~np.isfinite(a)].ravel()[0]
        raise _bad(name, float(bad), "finite numbers")
    return a


@dataclass(frozen=True)
class Axes:
    """A parsed axis set.

    Attributes:
        kind: ``"grid"``, ``"table"`` or ``"none"`` (a single point: the robot as it is).
        paths: The robot-file paths, in order.
        values: One array per path: the grid of each axis, or the table's column.
        dims: Dimension names of the result (the paths of a grid, ``(table_dim,)`` of a
            table, ``()`` for none).
        shape: Sizes of ``dims``.
        rows: The points in solve order, shape (n, len(paths)).
        order: ``order[k]`` is the flat (C-order) index in ``shape`` of solve position ``k``.
    """

    kind: str
    paths: tuple[str, ...]
    values: tuple[np.ndarray, ...]
    dims: tuple[str, ...]
    shape: tuple[int, ...]
    rows: np.ndarray
    order: np.ndarray
    given: tuple[str, ...] = ()

    @property
    def size(self) -> int:
        return len(self.rows)

    def spelling(self, path: str) -> str:
        """The path as the caller spelt it (``path`` is canonical)."""
        return dict(zip(self.paths, self.given or self.paths, strict=True))[path]


def boustrophedon(shape: tuple[int, ...]) -> np.ndarray:
    """Flat C-order indices of a grid visited in boustrophedon order (neighbours adjacent).

    Along each axis the direction reverses whenever an earlier axis steps, so that two
    consecutive points differ by one step of one axis.
    """
    if not shape:
        return np.zeros(1, dtype=np.int64)
    idx = np.indices(shape).reshape(len(shape), -1).T  # C order
    snake = idx.copy()
    for ax in range(1, len(shape)):
        # Parity of the number of steps taken by the earlier axes (in snake coordinates).
        parity = snake[:, :ax].sum(axis=1) % 2
        snake[:, ax] = np.where(parity == 1, shape[ax] - 1 - idx[:, ax], idx[:, ax])
    return np.ravel_multi_index(tuple(snake.T), shape)


@dataclass(frozen=True)
class _Columns:
    """An axis set checked but not expanded: its kind, paths (canonical, and as given) and
    values; ``shape`` the sizes of its dimensions."""

    kind: str
    paths: tuple[str, ...]
    given: tuple[str, ...]
    values: tuple[np.ndarray, ...]
    shape: tuple[int, ...]

    @property
    def points(self) -> int:
        return math.prod(self.shape)


def _canonical(paths: tuple[str, ...], what: str) -> tuple[str, ...]:
    """The paths spelt canonically (``tendons[00]`` -> ``tendons[0]``; a path that does not
    parse is kept, for the caller's check to name); two naming one parameter are refused."""
    from ..robot import canonical_path, same_parameter

    same_parameter(paths, what)
    out = []
    for p in paths:
        try:
            out.append(canonical_path(p))
        except ParameterError:
            out.append(p)
    return tuple(out)


def _columns(spec: Any, what: str) -> _Columns:
    """Checks ``actuation=`` or ``design=`` (``what``) without expanding a grid."""
    if spec is None:
        return _Columns("none", (), (), (), ())
    if not isinstance(spec, (Mapping, SampleTable)):
        mod = type(spec).__module__.split(".")[0]
        if mod not in ("pandas", "xarray"):
            raise _bad(
                what,
                spec,
                "a dict of path -> 1-D grid, or a table (softrod.samples(...), a DataFrame)",
            )
        spec = samples(spec)
    if isinstance(spec, SampleTable):
        given = tuple(spec)
        values = tuple(spec[p] for p in given)
        for p, v in zip(given, values, strict=True):
            _float_array(v, f"{what}[{p!r}]")
        return _Columns("table", _canonical(given, what), given, values, (spec.rows,))
    if not spec:
        raise _bad(what, spec, "a non-empty dict of path -> 1-D grid")
    given = tuple(str(p) for p in spec)
    values = []
    for key, p in zip(spec, given, strict=True):
        a = _float_array(spec[key], f"{what}[{p!r}]")
        if a.ndim != 1 or a.size == 0:
            raise _bad(f"{what}[{p!r}]", f"shape {a.shape}", "a non-empty 1-D grid")
        values.append(a)
    shape = tuple(len(v) for v in values)
    return _Columns("grid", _canonical(given, what), given, tuple(values), shape)


def _too_many(name: str, count: str) -> ParameterError:
    """The error of a sweep beyond :data:`softrod._args.MAX_GRID_VALUES` points (worded like
    the workspace map's)."""
    noun = "parameters" if " and " in name else "parameter"
    exc = ParameterError(
        f"invalid {noun} {name}: {count}: must be at most {_args.MAX_GRID_VALUES} points"
    )
    exc.parameter = name.split("`")[1]
    return exc


def check_points(actuation: _Columns, design: _Columns) -> None:
    """Refuses a sweep of more than :data:`softrod._args.MAX_GRID_VALUES` points (design
    points x actuation samples), before anything of that size is allocated.

    Raises:
        ParameterError: Naming ``actuation``, ``design`` or both, the number of points and
            the limit.
    """
    limit = _args.MAX_GRID_VALUES
    for what, cols in (("actuation", actuation), ("design", design)):
        if cols.points > limit:
            shape = "x".join(str(n) for n in cols.shape)
            raise _too_many(f"`{what}`", f"{cols.points} points ({cols.kind} {shape})")
    total = actuation.points * design.points
    if total > limit:
        raise _too_many(
            "`design` and `actuation`",
            f"{design.points} design points x {actuation.points} actuation samples = "
            f"{total} points",
        )


def _expand(cols: _Columns, table_dim: str) -> Axes:
    """The :class:`Axes` of checked columns: the rows in solve order."""
    if cols.kind == "none":
        return Axes("none", (), (), (), (), np.zeros((1, 0)), np.zeros(1, dtype=np.int64))
    if cols.kind == "table":
        rows = np.column_stack(cols.values)
        (n,) = cols.shape
        return Axes(
            "table", cols.paths, cols.values, (table_dim,), (n,), rows, np.arange(n), cols.given
        )
    order = boustrophedon(cols.shape)
    idx = np.unravel_index(order, cols.shape)
    rows = np.column_stack([v[i] for v, i in zip(cols.values, idx, strict=True)])
    return Axes("grid", cols.paths, cols.values, cols.paths, cols.shape, rows, order, cols.given)


def parse_axes(spec: Any, what: str, table_dim: str) -> Axes:
    """Parses ``actuation=`` or ``design=`` (``what``) into :class:`Axes`.

    Paths are spelt canonically (``tendons[00].tension`` is ``tendons[0].tension``, and so
    labelled).

    Raises:
        ParameterError: Not a mapping or table, an empty or non-1-D grid, non-finite values,
            two paths naming one parameter, more than :data:`softrod._args.MAX_GRID_VALUES`
            points.
    """
    cols = _columns(spec, what)
    none = _Columns("none", (), (), (), ())
    check_points(cols, none)
    return _expand(cols, table_dim)


def parse_axis_sets(actuation: Any, design: Any) -> tuple[Axes, Axes]:
    """The actuation and design axes of a sweep (dimensions ``sample`` and ``design`` for
    tables), checked together: at most :data:`softrod._args.MAX_GRID_VALUES` points in all,
    refused before any grid is expanded.

    Raises:
        ParameterError: As :func:`parse_axes`; the product beyond the limit (naming both).
    """
    act = _columns(actuation, "actuation")
    des = _columns(design, "design")
    check_points(act, des)
    return _expand(act, "sample"), _expand(des, "design")


@dataclass(frozen=True)
class ActuationAxis:
    """What one actuation path drives: ``kind`` is ``"tension"``, ``"displacement"``,
    ``"pressure"``, ``"tip_force"`` or ``"tip_moment"``; ``index`` the tendon, chamber or
    vector component."""

    path: str
    kind: str
    index: int


def actuation_axis(path: str, n_tendons: int, n_chambers: int) -> ActuationAxis:
    """Parses an actuation path and checks its index against the robot.

    Raises:
        ParameterError: Not an actuation path (tendon tension, chamber pressure, tip load
            component), or an index the robot does not have.
    """
    m = ACTUATION_PATH.match(path)
    if m is None:
        raise _bad(
            "actuation",
            path,
            "an actuation path: `tendons[i].tension`, `chambers[i].pressure`, "
            "`loads.tip_force[k]` or `loads.tip_moment[k]` (design parameters go in `design=`)",
        )
    if m.group("tendon"):
        i = int(m.group("ti"))
        if i >= n_tendons:
            raise _bad("actuation", path, f"a tendon index in [0, {n_tendons})")
        return ActuationAxis(path, m.group("tkey"), i)
    if m.group("chamber"):
        i = int(m.group("ci"))
        if i >= n_chambers:
            raise _bad("actuation", path, f"a chamber index in [0, {n_chambers})")
        return ActuationAxis(path, "pressure", i)
    return ActuationAxis(path, m.group("load"), int(m.group("k")))


_UNITS = {
    "tension": ("N", "tension"),
    "displacement": ("m", "tendon displacement"),
    "pressure": ("Pa", "gauge pressure"),
    "tip_force": ("N", "tip force"),
    "tip_moment": ("N m", "tip moment"),
    "length": ("m", "length"),
    "radius": ("m", "radius"),
    "base_radius": ("m", "base radius"),
    "tip_radius": ("m", "tip radius"),
    "outer_radius": ("m", "outer radius"),
    "inner_radius": ("m", "inner radius"),
    "distance": ("m", "offset distance"),
    "offset": ("m", "offset"),
    "end": ("m", "end"),
    "start": ("m", "start"),
    "s": ("m", "arc length"),
    "area": ("m^2", "area"),
    "ratio": ("1", "offset / local radius"),
    "angle_deg": ("degree", "angle"),
    "phase_deg": ("degree", "phase"),
    "pitch": ("m", "pitch"),
    "youngs_modulus": ("Pa", "Young's modulus"),
    "shear_modulus": ("Pa", "shear modulus"),
    "secant_modulus": ("Pa", "secant modulus"),
    "poisson_ratio": ("1", "Poisson's ratio"),
    "mu": ("Pa", "shear modulus"),
    "c10": ("Pa", "C10"),
    "c01": ("Pa", "C01"),
    "c20": ("Pa", "C20"),
    "c30": ("Pa", "C30"),
    "density": ("kg m-3", "density"),
    "gravity": ("m s-2", "gravity"),
    "shear_coefficient": ("1", "shear coefficient"),
    "steps": ("1", "RK4 steps"),
    "rtol": ("1", "relative tolerance"),
    "atol": ("1", "absolute tolerance"),
    "tolerance": ("1", "residual tolerance"),
}


def units_of(path: str) -> tuple[str, str]:
    """``(units, long_name)`` of a robot-file path (``("", path)`` when unknown)."""
    key = re.sub(r"\[\d+\]", "", path.rsplit(".", 1)[-1])
    base = re.sub(r"\[\d+\]\Z", "", path.rsplit(".", 1)[-1])
    units, name = _UNITS.get(key, _UNITS.get(base, ("", "")))
    return units, f"{name} ({path})" if name else path


def design_points(axes: Axes) -> list[dict[str, float]]:
    """The design points in solve order, as ``with_parameters`` dicts."""
    return [
        {p: float(v) for p, v in zip(axes.paths, row, strict=True)}
        for row in axes.rows
        if axes.paths
    ] or [{}]
