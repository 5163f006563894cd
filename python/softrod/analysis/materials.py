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

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _args
from .._core import ParameterError, UniaxialFit, fit_uniaxial

__all__ = ["FitCheck", "TensileCurve", "check_fit", "read_tensile_csv"]

#: Engineering strain below which the data's initial slope is measured.
INITIAL_STRAIN = 0.1
#: Fewest points the initial slope is measured on (the smallest strains, if fewer lie below
#: :data:`INITIAL_STRAIN`).
INITIAL_POINTS = 3
#: A fit is plausible at small strain if its small-strain modulus is within this factor of the
#: data's initial slope (either way).
PLAUSIBLE_MODULUS_RATIO = 3.0
#: Stretches at which the sign of a fitted law's tangent is checked, from 1 to the top of the
#: fitted range.
TANGENT_SAMPLES = 400

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

    def __post_init__(self) -> None:
        # Data are checked on construction: finite 1-d columns of one length.
        strain = _args.finite_array(self.strain, "strain", ndim=1)
        stress = _args.finite_array(self.stress, "stress", ndim=1)
        if strain.size == 0 or stress.shape != strain.shape:
            raise _bad(
                "stress",
                f"{stress.size} values (strain has {strain.size})",
                "as many values as strain, at least one",
            )
        if self.strain_measure not in _STRAIN_MEASURES:
            raise _bad("strain_measure", repr(self.strain_measure), " or ".join(_STRAIN_MEASURES))
        from .._core import MAX_MODULUS

        # (A stress beyond any modulus overflowed the fit: "initial slope inf kPa".)
        big = np.flatnonzero(np.abs(stress) > MAX_MODULUS)
        if big.size:
            raise _bad(
                f"stress[{big[0]}]", f"{stress[big[0]]:g}", f"of magnitude <= {MAX_MODULUS:g} Pa"
            )
        if self.stress_measure not in _STRESS_MEASURES:
            raise _bad("stress_measure", repr(self.stress_measure), " or ".join(_STRESS_MEASURES))
        if not isinstance(self.name, str):
            raise _args.type_error("name", self.name, "a string")
        if not isinstance(self.metadata, dict):
            raise _args.type_error("metadata", self.metadata, "a dict of strings")
        object.__setattr__(self, "strain", strain)
        object.__setattr__(self, "stress", stress)

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

    def initial_slope(self) -> float:
        """The data's small-strain modulus (Pa): least-squares slope through the origin of
        nominal stress against engineering strain over the points below
        :data:`INITIAL_STRAIN` (at least the :data:`INITIAL_POINTS` smallest strains)."""
        stretch = self.stretch
        nominal = np.asarray(self.stress, dtype=float)
        if self.stress_measure == "true":
            nominal = nominal / stretch
        strain = stretch - 1.0
        order = np.argsort(strain)
        pick = strain <= INITIAL_STRAIN
        if pick.sum() < INITIAL_POINTS:
            pick = np.zeros(len(strain), dtype=bool)
            pick[order[:INITIAL_POINTS]] = True
        e, p = strain[pick], nominal[pick]
        if not np.any(e != 0.0):
            raise _bad(
                "strain",
                f"{e.size} smallest values all 0",
                "some nonzero among the smallest (the initial slope is that of the stress "
                "against them)",
            )
        return float(np.sum(p * e) / np.sum(e * e))

    def fit(self, model: str = "yeoh", **options) -> UniaxialFit:
        """Fits a law to this curve: :func:`softrod.fit_uniaxial` with the curve's measures.

        Args:
            model: "neo-hookean", "mooney-rivlin", "yeoh", "ogden" or "linearised".
            **options: Keyword options of :func:`softrod.fit_uniaxial` (``terms``,
                ``nonnegative``, ``stretch_range``, ...).

        Returns:
            The fit (its ``model`` is the fitted law).

        Raises:
            ParameterError: A bad option (named), or data that the law cannot fit (naming
                ``data``: a fitted coefficient that is not physical, e.g. a Yeoh ``c10 <= 0``
                Pa, named with its value in the message).
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
    if not strain:
        raise _bad("path", str(path), "a database file with at least one row of data")
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
    path = _args.path(path)
    text = path.read_text(encoding="utf-8-sig", errors="replace")
    lines = text.splitlines()
    header_at = next(
        (i for i, ln in enumerate(lines[:40]) if ln.startswith(_DATABASE_HEADER)),
        None,
    )
    # Every option checked whatever the file (a misspelt one was ignored by the other kind),
    # and the options of the other kind of file refused rather than ignored.
    if columns not in _DATABASE_COLUMNS:
        raise _bad("columns", repr(columns), '"engineering" or "true"')
    if stress_unit not in STRESS_UNITS:
        raise _bad("stress_unit", repr(stress_unit), "one of " + ", ".join(STRESS_UNITS))
    if strain_unit not in STRAIN_UNITS:
        raise _bad("strain_unit", repr(strain_unit), "one of " + ", ".join(STRAIN_UNITS))
    if header_at is not None:
        for name, value, default in (
            ("strain_unit", strain_unit, "fraction"),
            ("stress_unit", stress_unit, "Pa"),
        ):
            if value != default:
                raise _bad(
                    name,
                    repr(value),
                    f"{default!r} for a Soft Robotics Materials Database file (its units are "
                    "its own; the option is for plain files)",
                )
        return _read_database(path, lines, header_at, columns)
    if columns != "engineering":
        raise _bad(
            "columns",
            repr(columns),
            '"engineering" for a plain file (the option picks a database file\'s columns)',
        )
    return _read_plain(path, lines, strain_measure, stress_measure, strain_unit, stress_unit)


@dataclass(frozen=True)
class FitCheck:
    """Plausibility of a fitted law against its data.

    Attributes:
        small_strain_modulus: The law's E0 (Pa).
        initial_slope: The data's initial slope (Pa), :meth:`TensileCurve.initial_slope`.
        modulus_ratio: ``small_strain_modulus / initial_slope``.
        modulus_plausible: The ratio is within :data:`PLAUSIBLE_MODULUS_RATIO` either way.
        stretch_max: Top of the checked range (the fitted range's upper stretch).
        tangent_positive: dP/dstretch > 0 on [1, stretch_max].
        first_negative_stretch: The smallest checked stretch where it is not (else None).
    """

    small_strain_modulus: float
    initial_slope: float
    modulus_ratio: float
    modulus_plausible: bool
    stretch_max: float
    tangent_positive: bool
    first_negative_stretch: float | None

    @property
    def plausible(self) -> bool:
        """Both checks pass."""
        return self.modulus_plausible and self.tangent_positive

    def summary(self) -> str:
        """One line: both checks and the verdict."""
        ratio = self.modulus_ratio
        tangent = (
            f"dP/dstretch > 0 on [1, {self.stretch_max:.4g}]"
            if self.tangent_positive
            else f"dP/dstretch <= 0 at stretch {self.first_negative_stretch:.4g}"
        )
        verdict = "plausible" if self.plausible else "NOT plausible"
        return (
            f"{verdict}: E0 / initial slope of the data ({self.initial_slope / 1e3:.4g} kPa) "
            f"= {ratio:.3g} (accepted within x{PLAUSIBLE_MODULUS_RATIO:g}), {tangent}"
        )


def check_fit(curve: TensileCurve, fit: UniaxialFit) -> FitCheck:
    """Checks a fit for plausibility: its small-strain modulus against the data's initial
    slope, and the sign of its tangent from the unstretched state to the top of the fit.

    A fit can have a small residual and still be useless at small strain (a Mooney-Rivlin fit
    to large stretches with E0 a fiftieth of the measured one) or unstable inside its range.
    """
    law = fit.model
    e0 = float(law.small_strain_modulus)
    slope = curve.initial_slope()
    ratio = e0 / slope if slope > 0 else math.inf
    plausible_modulus = 1.0 / PLAUSIBLE_MODULUS_RATIO <= ratio <= PLAUSIBLE_MODULUS_RATIO
    top = float(fit.stretch_range[1])
    stretches = np.linspace(1.0, max(top, 1.0), TANGENT_SAMPLES)
    tangent = np.asarray(law.nominal_tangent(stretches), dtype=float)
    bad = np.flatnonzero(~(tangent > 0))
    return FitCheck(
        small_strain_modulus=e0,
        initial_slope=slope,
        modulus_ratio=ratio,
        modulus_plausible=bool(plausible_modulus),
        stretch_max=top,
        tangent_positive=len(bad) == 0,
        first_negative_stretch=float(stretches[bad[0]]) if len(bad) else None,
    )
