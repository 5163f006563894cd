"""Comparing backbones at equal arm index (fraction of arm length), as the planar cable-arm
paper did."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .. import _core
from .._core import ParameterError

__all__ = ["BackboneDistance", "backbone_distance"]


@dataclass(frozen=True)
class BackboneDistance:
    """Pointwise distance between two backbones at equal arm index.

    Unpacks as ``(max, mean)``: ``worst, mean = backbone_distance(a, b)``.

    Attributes:
        max: Largest distance, in the units of the inputs.
        mean: Mean distance over the compared indices.
        argmax_index: Arm index in [0, 1] of the largest distance.
        index: Compared arm indices, shape (n,), uniform in [0, 1].
        distance: Distance at each index, shape (n,).
    """

    max: float
    mean: float
    argmax_index: float
    index: np.ndarray
    distance: np.ndarray

    def __iter__(self) -> Iterator[float]:
        return iter((self.max, self.mean))


def _points(name: str, value: ArrayLike) -> np.ndarray:
    if hasattr(value, "points") and hasattr(value, "arc_length"):  # a Backbone
        value = value.points
    elif hasattr(value, "x") and hasattr(value, "y") and hasattr(value, "tension"):
        value = np.column_stack([value.x, value.y])  # a PlanarSolution (m)
    try:
        arr = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ParameterError(
            f"invalid parameter `{name}`: not an array of numbers ({exc})"
        ) from None
    if arr.ndim != 2 or arr.shape[1] not in (2, 3):
        raise ParameterError(
            f"invalid parameter `{name}` with shape {arr.shape}: must be (n, 2) or (n, 3) points"
        )
    return arr


def _check_units(a: object, b: object) -> None:
    units = [getattr(v, "unit", "m" if hasattr(v, "tension") else None) for v in (a, b)]
    if None not in units and units[0] != units[1]:
        raise ParameterError(
            f"invalid parameter `b`: backbones in different units ({units[0]} and {units[1]}); "
            "extract the photo's backbone with `scale` (m per pixel) to compare it with a model"
        )


def backbone_distance(a: ArrayLike, b: ArrayLike, n_index: int | None = None) -> BackboneDistance:
    """Distance between two backbones at the same arm index, max and mean.

    Each backbone is a polyline of points (any number, e.g. digitised from a photo), shape
    (n, 2) or (n, 3), in any length unit; or a :class:`softrod.Backbone` extracted from a
    photo (its ``points``), or a :class:`softrod.PlanarSolution` (its x, y in m). Each is
    parametrised by its own normalised chord length (arm index in [0, 1]) and resampled
    linearly; distances are taken between points of equal index.

    Args:
        a: First backbone, shape (n_a, dim), a Backbone or a PlanarSolution.
        b: Second backbone, shape (n_b, dim), same dim as ``a``, or as for ``a``.
        n_index: Number of uniform arm indices compared; default ``max(n_a, n_b)``.

    Returns:
        The distances; unpacks as ``(max, mean)``.

    Raises:
        ParameterError: Bad shapes, fewer than two points, zero length, non-finite values,
            or a Backbone in pixels compared with one in metres.
    """
    _check_units(a, b)
    d = _core.backbone_distance(_points("a", a), _points("b", b), n_index)
    return BackboneDistance(
        max=d["max"],
        mean=d["mean"],
        argmax_index=d["argmax_index"],
        index=d["index"],
        distance=d["distance"],
    )
