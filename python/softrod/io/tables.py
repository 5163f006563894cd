"""File I/O: backbones from CSV, solution samples to CSV or JSON-ready dicts."""

from __future__ import annotations

import csv
import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from .. import _args
from .._core import ParameterError, PlanarSolution, StaticsSolution

__all__ = [
    "read_backbone_csv",
    "solution_to_dict",
    "statics_to_dict",
    "write_samples_csv",
    "write_statics_csv",
]

SAMPLE_FIELDS = ("s", "curvature", "strain", "angle", "x", "y")


def read_backbone_csv(
    path: str | os.PathLike[str],
    *,
    scale: float = 1.0,
    columns: Sequence[int] | None = None,
) -> np.ndarray:
    """Reads a backbone (a list of points) from a CSV file.

    The file has one point per row, two or three numeric columns (x, y[, z]); an optional
    header row is skipped, as are blank lines and lines starting with ``#``. Delimiters
    ``,``, ``;``, tab or spaces are detected. A header that names columns ``x`` and ``y`` (and
    ``z``) selects them (e.g. the CSV of ``softrod backbone``, whose third column is the arc
    length).

    Args:
        path: CSV file.
        scale: Factor applied to every coordinate, e.g. ``1e-3`` for a file in millimetres.
        columns: Indices of the coordinate columns (default: those a header names ``x``,
            ``y`` and ``z``, else the first two, or three if every row has three numeric
            columns).

    Returns:
        Points, shape (n, 2) or (n, 3), multiplied by ``scale``.

    Raises:
        ParameterError: No data rows (an empty file, a header alone), unreadable numbers,
            fewer than two points or two columns, or a bad ``scale`` (``.parameter``: ``path``
            for the file's content); ``columns`` beyond the file's columns (named, with the
            file and its number of columns).
    """
    scale = _args.number(scale, "scale", positive=True)
    if columns is not None:
        if isinstance(columns, (str, bytes)) or not hasattr(columns, "__iter__"):
            raise _args.type_error("columns", columns, "a sequence of 2 or 3 column indices")
        columns = [_args.count(c, f"columns[{i}]", 0, 2**31) for i, c in enumerate(columns)]
    with open(_args.path(path), newline="", encoding="utf-8") as fh:
        text = fh.read()
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise _bad_file(path, "no data rows")
    try:
        dialect = csv.Sniffer().sniff(lines[0], delimiters=",;\t ")
        delim = dialect.delimiter
    except csv.Error:
        delim = ","
    rows: list[list[str]] = [
        [c for c in (r if delim != " " else ln.split()) if c.strip() != ""]
        for ln, r in zip(lines, csv.reader(lines, delimiter=delim), strict=True)
    ]

    def numeric(row: list[str]) -> list[float] | None:
        try:
            return [float(c) for c in row]
        except ValueError:
            return None

    parsed = [numeric(r) for r in rows]
    named = None
    if parsed and parsed[0] is None:  # header
        named = _named_columns(rows[0])
        parsed = parsed[1:]
        rows = rows[1:]
    if not parsed:  # a header (or one line of text) alone
        raise _bad_file(path, "no data rows")
    bad = [i for i, p in enumerate(parsed) if p is None]
    if bad:
        raise _bad_file(path, f"row {bad[0] + 1} of data is not numeric: {rows[bad[0]]!r}")
    width = min(len(p) for p in parsed if p is not None)
    if columns is None and named is not None:
        columns = named
    if columns is None:
        if width < 2:
            raise _bad_file(
                path,
                f"a row of {width} column{'s' if width != 1 else ''}: needs 2 or 3 numeric "
                "columns (x, y[, z])",
            )
        columns = (0, 1, 2) if width >= 3 else (0, 1)
    cols = list(columns)
    if len(cols) not in (2, 3) or max(cols) >= width or min(cols) < 0:
        exc = ParameterError(
            f"invalid parameter `columns` = {cols}: must be 2 or 3 indices < {width} (the "
            f"file {os.fspath(path)!r} has {width} column{'s' if width != 1 else ''}"
            f"{' in its shortest row' if any(len(p) != width for p in parsed) else ''})"
        )
        exc.parameter = "columns"
        raise exc
    pts = np.array([[p[c] for c in cols] for p in parsed if p is not None], dtype=np.float64)
    if pts.shape[0] < 2:
        raise _bad_file(path, f"{pts.shape[0]} points, need >= 2")
    if not np.all(np.isfinite(pts)):
        raise _bad_file(path, "non-finite value")
    return pts * scale


def _named_columns(header: list[str]) -> list[int] | None:
    """The indices of the columns a header names ``x``, ``y`` (and ``z``; case and a unit in
    brackets ignored), or None if it does not name ``x`` and ``y``."""
    names = [c.strip().lower().split("(")[0].split("[")[0].strip() for c in header]
    if "x" not in names or "y" not in names:
        return None
    return [names.index(a) for a in ("x", "y", "z") if a in names]


def _bad_file(path: str | os.PathLike[str], why: str) -> ParameterError:
    """A ParameterError at ``path``: what is wrong with the file's content."""
    exc = ParameterError(f"invalid parameter `path` = {os.fspath(path)!r}: {why}")
    exc.parameter = "path"
    return exc


def solution_to_dict(sol: PlanarSolution) -> dict[str, Any]:
    """A JSON-ready dict of one planar solution (lists of floats, SI units)."""
    out: dict[str, Any] = {"tension": sol.tension, "method": sol.method}
    out["tip"] = [float(v) for v in sol.tip]
    out["tip_angle"] = sol.tip_angle
    out["max_compressive_strain"] = sol.max_compressive_strain
    for name in SAMPLE_FIELDS:
        out[name] = getattr(sol, name).tolist()
    return out


def write_samples_csv(path: str | os.PathLike[str], solutions: Sequence[PlanarSolution]) -> None:
    """Writes the samples of one or more planar solutions to one CSV file.

    Columns: ``tension, s, curvature, strain, angle, x, y`` (SI units), one row per sample.
    """
    if isinstance(solutions, (str, bytes)) or not hasattr(solutions, "__iter__"):
        raise _args.type_error("solutions", solutions, "a sequence of PlanarSolution")
    solutions = list(solutions)
    for i, sol in enumerate(solutions):
        if not isinstance(sol, PlanarSolution):
            raise _args.type_error(f"solutions[{i}]", sol, "a PlanarSolution")
    with open(_args.path(path), "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(("tension", *SAMPLE_FIELDS))
        for sol in solutions:
            cols = [getattr(sol, name) for name in SAMPLE_FIELDS]
            for i in range(len(sol.s)):
                w.writerow([repr(sol.tension), *(repr(float(c[i])) for c in cols)])


STATICS_COLUMNS = (
    ("s", ("s",)),
    ("position", ("x", "y", "z")),
    ("quaternion", ("qx", "qy", "qz", "qw")),
    ("force", ("nx", "ny", "nz")),
    ("moment", ("mx", "my", "mz")),
    ("v", ("vx", "vy", "vz")),
    ("u", ("ux", "uy", "uz")),
)


def write_statics_csv(
    path: str | os.PathLike[str], sol: StaticsSolution, contacts: bool | None = None
) -> None:
    """Writes a statics solution's samples to CSV, one row per sample (SI units).

    Columns: ``s``; position ``x, y, z`` (world); quaternion ``qx, qy, qz, qw``; internal force
    ``nx, ny, nz`` and moment ``mx, my, mz`` (world); strains ``vx..vz``, ``ux..uz`` (body);
    with ``contacts`` the contact force on the rod at the sample, ``cfx, cfy, cfz`` (N, world;
    by default when the solution has a contact).
    """
    blocks = [
        np.asarray(getattr(sol, name), dtype=float).reshape(len(sol), -1)
        for name, _ in STATICS_COLUMNS
    ]
    names = [c for _, cols in STATICS_COLUMNS for c in cols]
    if _with_contacts(sol, contacts):
        blocks.append(np.asarray(sol.contact_force, dtype=float).reshape(len(sol), 3))
        names += ["cfx", "cfy", "cfz"]
    table = np.hstack(blocks)
    np.savetxt(path, table, delimiter=",", header=",".join(names), comments="", fmt="%.17g")


def _with_contacts(sol: StaticsSolution, contacts: bool | None) -> bool:
    """Whether the contacts of ``sol`` are written: ``contacts`` if given, else whether it
    has a contact or a tip reaction."""
    if contacts is not None:
        return bool(contacts)
    return bool(sol.contacts) or sol.tip_reaction is not None


def contacts_to_list(sol: StaticsSolution) -> list[dict[str, Any]]:
    """The active contacts of ``sol`` as JSON-ready dicts: ``obstacle`` (index), ``s`` and
    ``length`` (m; a belt or interval from ``s`` to ``s + length``), ``point``, ``normal``,
    ``normal_force`` (N), ``tangential_force`` (N), their sum ``force`` (N, world) and ``state``.
    """
    out = []
    for c in sol.contacts:
        normal = np.asarray(c["normal"], dtype=float)
        tangential = np.asarray(c["tangential_force"], dtype=float)
        out.append(
            {
                "obstacle": int(c["obstacle"]),
                "s": float(c["s"]),
                "length": float(c["length"]),
                "point": np.asarray(c["point"], dtype=float).tolist(),
                "normal": normal.tolist(),
                "normal_force": float(c["normal_force"]),
                "tangential_force": tangential.tolist(),
                "force": (normal * float(c["normal_force"]) + tangential).tolist(),
                "state": str(c["state"]),
            }
        )
    return out


def statics_to_dict(sol: StaticsSolution, contacts: bool | None = None) -> dict[str, Any]:
    """A JSON-ready dict of a statics solution (lists of floats, SI units, world frame).

    With ``contacts`` (by default when the solution has a contact or a tip reaction) also
    ``contacts`` (:func:`contacts_to_list`), ``contact_force`` per
    sample (N, world, shape (N, 3)) and, with a tip constraint, ``tip_reaction`` (N, N m).
    """
    out: dict[str, Any] = {
        name: np.asarray(getattr(sol, name)).tolist()
        for name in (
            "s",
            "position",
            "rotation",
            "quaternion",
            "force",
            "moment",
            "v",
            "u",
            "tendon_lengths",
            "base_wrench",
            "tip_position",
            "tip_rotation",
        )
    }
    out["stable"] = sol.stable
    out["stats"] = dict(sol.stats)
    if _with_contacts(sol, contacts):
        out["contacts"] = contacts_to_list(sol)
        out["contact_force"] = np.asarray(sol.contact_force, dtype=float).tolist()
        if sol.tip_reaction is not None:
            out["tip_reaction"] = np.asarray(sol.tip_reaction, dtype=float).tolist()
    return out
