"""The extracted backbone of an arm in a photograph, and its quality report."""

from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .. import _args
from .._core import ParameterError

__all__ = ["Backbone", "BackboneQuality"]


def parameter_error(name: str, message: str) -> ParameterError:
    """A :class:`ParameterError` whose ``parameter`` attribute names ``name``."""
    err = ParameterError(f"invalid parameter `{name}`: {message}")
    err.parameter = name
    return err


@dataclass(frozen=True)
class BackboneQuality:
    """How well the extracted backbone explains the photograph.

    Attributes:
        polarity: ``"bright"`` (arm lighter than the background) or ``"dark"``;
            ``"mask"`` when the caller gave the mask.
        contrast: Median arm level minus background level after flattening the lighting, in
            grey units of the image scaled to [0, 1].
        noise: Robust standard deviation of the flattened background (same units).
        threshold: Segmentation threshold on the flattened signal (same units).
        coverage: Fraction of the arm's mask inside the fitted tube (points +- half-width).
        tube_fill: Fraction of the fitted tube inside the arm's mask.
        fit_residual: RMS distance (px) of the measured edge midpoints from the fitted curve.
        edge_outliers: Cross-sections where one edge was rejected (a blob touching the arm,
            glare) and the centre was taken from the other edge and the local half-width.
        discarded_components: Segmented components other than the arm (floats, markers,
            bubbles) larger than ``min_area``.
        discarded_area: Their total area (px).
        base_source: How the base end was chosen: ``"given"`` (the ``base`` argument),
            ``"border"`` (the end at the image border) or ``"wider end"``.
        base_extrapolated: True when the curve was extended beyond the visible arm to reach
            ``base`` (occluded base, e.g. under a clamp).
        extrapolated_length: Length of that extension (px).
        base_offset: Distance (px) from the given ``base`` to the visible curve's tangent line
            (how far the base point lies beside the arm's axis).
        direction_source: ``"given"``, or ``"fitted"`` (the tangent at the base).
        tip_source: ``"end edge"`` (the arm's end face was found) or ``"border"`` (the arm
            leaves the image).
        warnings: Human-readable warnings; empty when nothing looked wrong.
    """

    polarity: str
    contrast: float
    noise: float
    threshold: float
    coverage: float
    tube_fill: float
    fit_residual: float
    edge_outliers: int
    discarded_components: int
    discarded_area: int
    base_source: str
    base_extrapolated: bool
    extrapolated_length: float
    base_offset: float
    direction_source: str
    tip_source: str
    warnings: tuple[str, ...] = field(default_factory=tuple)

    @property
    def ok(self) -> bool:
        """True when there is no warning."""
        return not self.warnings

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict of every field."""
        d = asdict(self)
        d["warnings"] = list(self.warnings)
        return d


@dataclass(frozen=True, eq=False)
class Backbone:
    """An arm's centreline in a photograph, ordered from base to tip.

    Pixel coordinates are (column, row) with rows downward and pixel centres at integers. With
    a ``scale``, ``points`` are in metres in the arm's frame: origin at the base, x along the
    unloaded arm's ``direction``, y turned +90 degrees from x as seen on the image (toward
    the top of the image for a rightward direction), the frame of
    :class:`softrod.PlanarCableArm` solutions. Without a scale, ``points`` are pixels.

    Attributes:
        points: Centreline, shape (n, 2), base first; metres (arm frame) or pixels.
        arc_length: Arc length from the base along ``points``, shape (n,), same unit.
        half_width: Half the arm's apparent width across the centreline, shape (n,), same
            unit (the radius of a round arm seen from above).
        pixels: The same centreline in image pixels (column, row), shape (n, 2).
        unit: ``"m"`` or ``"px"``.
        scale: Metres per pixel, or None.
        base: Base point used, pixels (column, row), shape (2,).
        direction: Unit direction of the arm frame's x axis in pixels, shape (2,).
        image_shape: (rows, columns) of the photograph.
        quality: The quality report.
    """

    points: np.ndarray
    arc_length: np.ndarray
    half_width: np.ndarray
    pixels: np.ndarray
    unit: str
    scale: float | None
    base: np.ndarray
    direction: np.ndarray
    image_shape: tuple[int, int]
    quality: BackboneQuality

    def __len__(self) -> int:
        return len(self.points)

    @property
    def length(self) -> float:
        """Length of the centreline (``points`` unit)."""
        return float(self.arc_length[-1])

    @property
    def tip(self) -> np.ndarray:
        """Tip point, shape (2,), ``points`` unit and frame."""
        return self.points[-1].copy()

    @property
    def arm_index(self) -> np.ndarray:
        """Arc length as a fraction of the length, shape (n,), 0 at the base, 1 at the tip."""
        return self.arc_length / self.arc_length[-1]

    @property
    def half_width_px(self) -> np.ndarray:
        """Half-widths in pixels, shape (n,)."""
        return self.half_width / self.scale if self.scale else self.half_width.copy()

    def at_arm_index(self, u: ArrayLike) -> np.ndarray:
        """Points at arm index ``u`` (fraction of the length in [0, 1]), linear interpolation.

        Args:
            u: A scalar or an array of arm indices.

        Returns:
            Shape (2,) for a scalar, else ``u.shape + (2,)``; ``points`` unit and frame.

        Raises:
            ParameterError: ``u`` outside [0, 1] or not finite.
        """
        ua = _args.finite_array(u, "u")
        if not np.all(np.isfinite(ua)) or np.any(ua < 0) or np.any(ua > 1):
            raise parameter_error("u", f"arm index {u!r} must be finite and in [0, 1]")
        t = self.arm_index
        flat = ua.ravel()
        out = np.column_stack([np.interp(flat, t, self.points[:, k]) for k in range(2)])
        return out.reshape((*ua.shape, 2))

    def resample(self, n: int) -> Backbone:
        """The same backbone at ``n`` points uniform in arc length (linear interpolation).

        Raises:
            ParameterError: ``n`` not in ``[2, MAX_SAMPLES]``.
        """
        n = _args.count(n, "n", 2, _args.MAX_SAMPLES)
        s = np.linspace(0.0, self.length, int(n))
        s[-1] = self.arc_length[-1]

        def lerp(a: np.ndarray) -> np.ndarray:
            return np.column_stack([np.interp(s, self.arc_length, a[:, k]) for k in range(2)])

        return replace(
            self,
            points=lerp(self.points),
            arc_length=s,
            half_width=np.interp(s, self.arc_length, self.half_width),
            pixels=lerp(self.pixels),
        )

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict: frame, quality and every per-point array as lists."""
        return {
            "unit": self.unit,
            "scale": self.scale,
            "base_px": self.base.tolist(),
            "direction_px": self.direction.tolist(),
            "image_shape": list(self.image_shape),
            "length": self.length,
            "quality": self.quality.to_dict(),
            "points": self.points.tolist(),
            "arc_length": self.arc_length.tolist(),
            "half_width": self.half_width.tolist(),
            "pixels": self.pixels.tolist(),
        }

    def to_csv(self, path: str | os.PathLike[str], *, overwrite: bool = False) -> None:
        """Writes one row per point: ``x, y, arc_length, half_width, col, row``.

        ``#`` comment lines above the header carry the unit, the frame and the quality report,
        so :meth:`read_csv` restores the whole backbone;
        ``softrod.read_backbone_csv(path, columns=(0, 1))`` reads the points alone.

        Args:
            path: Output file.
            overwrite: Replace an existing file (default: refuse).

        Raises:
            FileExistsError: ``path`` exists and ``overwrite`` is False.
        """
        path = _args.path(path)
        mode = "w" if _args.flag(overwrite, "overwrite") else "x"
        frame = {k: v for k, v in self.to_dict().items() if k in _FRAME_KEYS}
        with open(path, mode, newline="", encoding="utf-8") as fh:
            fh.write(
                f"# softrod backbone, base to tip; x, y, arc_length, half_width in {self.unit}"
                "; col, row in image pixels (rows downward)\n"
            )
            fh.write(f"# frame: {json.dumps(frame)}\n")
            fh.write(f"# quality: {json.dumps(self.quality.to_dict())}\n")
            fh.write("x,y,arc_length,half_width,col,row\n")
            table = np.column_stack([self.points, self.arc_length, self.half_width, self.pixels])
            np.savetxt(fh, table, delimiter=",", fmt="%.10g")

    @classmethod
    def read_csv(cls, path: str | os.PathLike[str]) -> Backbone:
        """Reads a file written by :meth:`to_csv`.

        Raises:
            ParameterError: Not a backbone file (missing frame or columns).
        """
        meta: dict[str, Any] = {}
        path = _args.path(path)
        with open(path, encoding="utf-8") as fh:
            for line in fh:
                if not line.startswith("#"):
                    break
                key, _, value = line[1:].partition(":")
                if key.strip() in ("frame", "quality"):
                    meta[key.strip()] = json.loads(value)
        try:
            table = _load_table(path)
            frame, q = meta["frame"], meta["quality"]
            quality = BackboneQuality(**{**q, "warnings": tuple(q["warnings"])})
        except (KeyError, TypeError, ValueError) as exc:
            raise parameter_error(
                "path", f"{os.fspath(path)!r} is not a backbone file written by to_csv ({exc})"
            ) from None
        return cls(
            points=table[:, 0:2].copy(),
            arc_length=table[:, 2].copy(),
            half_width=table[:, 3].copy(),
            pixels=table[:, 4:6].copy(),
            unit=frame["unit"],
            scale=frame["scale"],
            base=np.asarray(frame["base_px"], dtype=np.float64),
            direction=np.asarray(frame["direction_px"], dtype=np.float64),
            image_shape=tuple(frame["image_shape"]),
            quality=quality,
        )


_FRAME_KEYS = ("unit", "scale", "base_px", "direction_px", "image_shape", "length")


def _load_table(path: str | os.PathLike[str]) -> np.ndarray:
    with open(path, encoding="utf-8") as fh:
        rows = [ln for ln in fh if ln.strip() and not ln.startswith("#")]
    table = np.loadtxt(rows[1:], delimiter=",", ndmin=2)  # rows[0] is the header
    if table.shape[1] != 6 or table.shape[0] < 2:
        raise ValueError(f"table of shape {table.shape}, expected (n >= 2, 6)")
    return table
