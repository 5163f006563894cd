"""Uniaxial tensile data: reading test files and fitting material laws to them.

Two file formats are read by :func:`read_tensile_csv`:

* the files of the Soft Robotics Materials Database (Marechal et al., Soft Robotics 8(3), 2021,
  doi:10.1089/soro.2019.0115), as vendored in ``data/silicone-tensile/``: 17 header lines, then
  ``;``-separated columns ``Time (s); True Strain; True Stress (MPa); Engineering Strain;
  Engineering Stress (MPa)``. Their "true strain" is the logarithmic strain ``ln(stretch)``;
  stresses are converted from MPa to Pa;
* a plain two-column CSV ``strain, stress`` (comma, semicolon, tab or space separated, optional
  header line, ``#`` comments), with the measures and units given as options.

The laws, the fit and the silicone library are in the compiled core and re-exported by
:mod:`softrod`: :class:`softrod.Yeoh`, :func:`softrod.fit_uniaxial`, :func:`softrod.silicone`, ...
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._core import ParameterError, UniaxialFit, fit_uniaxial

__all__ = ["TensileCurve", "read_tensile_csv"]

#: Factors from the accepted stress units to Pa.
STRESS_UNITS = {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9}
#: Factors from the accepted strain units to a fraction (engineering or logarithmic strain).
STRAIN_UNITS = {"fraction": 1.0, "percent": 1e-2}

_STRAIN_MEASURES = ("engineering", "stretch", "logarithmic")
_STRESS_MEASURES = ("nominal", "true")
# Column names of a Soft Robotics Materials Database file, by which pair is read.
_DATABASE_COLUMNS = {
    "engineering": ("Engineering Strain", "Engineering Stress (MPa)", "engineering", "nominal"),
    "true": ("True Strain", "True Stress (MPa)", "logarithmic", "true"),
}
_DATABASE_HEADER = "Time (s);"


def _bad(name: str, value: object, expected: str) -> ParameterError:
    """A ParameterError worded like the core's, with ``parameter`` set."""
    err = ParameterError(f"invalid parameter `{name}` = {value}: must be {expected}")
    err.parameter = name
    return err


@dataclass(frozen=True)
class TensileCurve:
    """One uniaxial test: a strain column and a stress column (Pa), with their measures.

    Attributes:
        strain: Strain of each point, shape (n,), in ``strain_measure`` (a fraction, not %).
        stress: Stress of each point (Pa), shape (n,), in ``stress_measure``.
        strain_measure: "engineering" (stretch - 1), "stretch" or "logarithmic" (ln stretch).
        stress_measure: "nominal" (force / undeformed area) or "true" (force / deformed area).
        name: A label, e.g. the file name without extension.
        metadata: Header fields of a database file (e.g. "Material", "Standard"), else empty.
    """

    strain: np.ndarray
    stress: np.ndarray
    strain_measure: str = "engineering"
    stress_measure: str = "nominal"
    name: str = ""
    metadata: dict[str, str] = field(default_factory=dict)

    @property
    def stretch(self) -> np.ndarray:
        """Stretch of each point, shape (n,)."""
        if self.strain_measure == "stretch":
            return np.asarray(self.strain, dtype=float)
        if self.strain_measure == "logarithmic":
            return np.exp(self.strain)
        return 1.0 + np.asarray(self.strain, dtype=float)

    def __len__(self) -> int:
        return len(self.strain)

    def fit(self, model: str = "yeoh", **options) -> UniaxialFit:
        """Fits a law to this curve: :func:`softrod.fit_uniaxial` with the curve's measures.

        Args:
            model: "neo-hookean", "mooney-rivlin", "yeoh", "ogden" or "linearised".
            **options: Keyword options of :func:`softrod.fit_uniaxial` (``terms``,
                ``nonnegative``, ``stretch_range``, ...).

        Returns:
            The fit (its ``model`` is the fitted law).
        """
        return fit_uniaxial(
            self.strain,
            self.stress,
            model,
            strain_measure=self.strain_measure,
            stress_measure=self.stress_measure,
            **options,
        )


def _read_database(path: Path, lines: list[str], header_at: int, columns: str) -> TensileCurve:
    if columns not in _DATABASE_COLUMNS:
        raise _bad("columns", repr(columns), '"engineering" or "true"')
    strain_col, stress_col, strain_measure, stress_measure = _DATABASE_COLUMNS[columns]
    names = [n.strip() for n in lines[header_at].split(";")]
    missing = [c for c in (strain_col, stress_col) if c not in names]
    if missing:
        raise _bad("path", str(path), f"a database file with the column {missing[0]!r}")
    i_strain, i_stress = names.index(strain_col), names.index(stress_col)
    metadata = {}
    for line in lines[:header_at]:
        parts = [p.strip() for p in line.split(";")]
        if len(parts) >= 2 and parts[0] and parts[0] != "PARAMETER":
            metadata[parts[0]] = parts[1]
    strain, stress = [], []
    for number, line in enumerate(lines[header_at + 1 :], start=header_at + 2):
        if not line.strip():
            continue
        parts = line.split(";")
        try:
            strain.append(float(parts[i_strain]))
            stress.append(float(parts[i_stress]) * 1e6)  # MPa -> Pa
        except (IndexError, ValueError):
            raise _bad(f"{path.name}:{number}", repr(line), "numbers in every column") from None
    return TensileCurve(
        np.array(strain),
        np.array(stress),
        strain_measure,
        stress_measure,
        name=path.stem,
        metadata=metadata,
    )


def _read_plain(
    path: Path,
    lines: list[str],
    strain_measure: str,
    stress_measure: str,
    strain_unit: str,
    stress_unit: str,
) -> TensileCurve:
    if strain_measure not in _STRAIN_MEASURES:
        raise _bad("strain_measure", repr(strain_measure), " or ".join(_STRAIN_MEASURES))
    if stress_measure not in _STRESS_MEASURES:
        raise _bad("stress_measure", repr(stress_measure), " or ".join(_STRESS_MEASURES))
    if stress_unit not in STRESS_UNITS:
        raise _bad("stress_unit", repr(stress_unit), "one of " + ", ".join(STRESS_UNITS))
    if strain_unit not in STRAIN_UNITS:
        raise _bad("strain_unit", repr(strain_unit), "one of " + ", ".join(STRAIN_UNITS))
    if strain_measure == "stretch" and strain_unit != "fraction":
        raise _bad("strain_unit", repr(strain_unit), '"fraction" for a stretch column')
    rows = []
    for number, raw in enumerate(lines, start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        parts = [p for p in re.split(r"[,;\t ]+", line) if p]
        try:
            values = [float(p) for p in parts]
        except ValueError:
            if not rows:  # a header line
                continue
            raise _bad(f"{path.name}:{number}", repr(raw.rstrip()), "two numbers") from None
        if len(values) != 2:
            raise _bad(f"{path.name}:{number}", repr(raw.rstrip()), "two columns: strain, stress")
        rows.append(values)
    if not rows:
        raise _bad("path", str(path), "a file with at least one row of strain, stress")
    data = np.array(rows)
    return TensileCurve(
        data[:, 0] * STRAIN_UNITS[strain_unit],
        data[:, 1] * STRESS_UNITS[stress_unit],
        strain_measure,
        stress_measure,
        name=path.stem,
    )


def read_tensile_csv(
    path: str | Path,
    *,
    columns: str = "engineering",
    strain_measure: str = "engineering",
    stress_measure: str = "nominal",
    strain_unit: str = "fraction",
    stress_unit: str = "Pa",
) -> TensileCurve:
    """Reads a uniaxial tensile curve from a CSV file (format detected from the content).

    Args:
        path: The file.
        columns: For a Soft Robotics Materials Database file: which pair of columns to read,
            "engineering" (engineering strain and nominal stress: the measured ones) or "true"
            (logarithmic strain and true stress, derived from them). Units are fixed by the
            format (stress in MPa, converted to Pa); the options below are then ignored.
        strain_measure: For a plain two-column file: "engineering", "stretch" or
            "logarithmic".
        stress_measure: For a plain file: "nominal" or "true".
        strain_unit: For a plain file: "fraction" or "percent" (not for stretch).
        stress_unit: For a plain file: "Pa", "kPa", "MPa" or "GPa"; converted to Pa.

    Returns:
        The curve, stress in Pa.

    Raises:
        OSError: If the file cannot be read.
        ParameterError: If the content or an option is not valid; the message names it (for a
            bad line, ``file:line``).
    """
    path = Path(path)
    text = path.read_text(encoding="utf-8-sig", errors="replace")
    lines = text.splitlines()
    header_at = next(
        (i for i, ln in enumerate(lines[:40]) if ln.startswith(_DATABASE_HEADER)),
        None,
    )
    if header_at is not None:
        return _read_database(path, lines, header_at, columns)
    return _read_plain(path, lines, strain_measure, stress_measure, strain_unit, stress_unit)
