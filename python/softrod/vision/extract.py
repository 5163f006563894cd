"""``extract_backbone``: from a top-view photograph of an arm to its ordered backbone."""

from __future__ import annotations

import os
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial import cKDTree

from .. import _args
from .._core import MAX_LENGTH
from .backbone import Backbone, BackboneQuality, parameter_error
from .centreline import fit_centreline
from .segment import mask_segmentation, read_image, segment, to_grey

__all__ = ["base_out_of_reach", "extract_backbone"]

#: Output point spacing along the centreline when ``n_points`` is not given (px).
POINT_SPACING = 1.0
#: A given base within max(this (px), a quarter half-width) of the visible end, along the
#: arm's axis, is taken as the end itself (no extrapolation, no trimming).
BASE_TOLERANCE = 1.0
#: A given base may lie at most this many image diagonals outside the image (px, per axis).
BASE_REACH = 1.0
#: Smallest knot spacing of the centreline spline (px): closer knots fit pixel noise.
MIN_KNOT_SPACING = 1.0
#: Ends whose half-widths differ by less than this ratio cannot tell base from tip.
WIDTH_RATIO_MIN = 1.05


def _pair(name: str, value: Any) -> np.ndarray | None:
    if value is None:
        return None
    try:
        arr = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise parameter_error(name, f"{value!r} must be two numbers (col, row)") from None
    if arr.shape != (2,) or not np.all(np.isfinite(arr)):
        raise parameter_error(name, f"{value!r} must be two finite numbers (col, row)")
    return arr


def _positive(name: str, value: Any) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool):
        raise parameter_error(name, f"{value!r} must be a number > 0")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise parameter_error(name, f"{value!r} must be a number > 0") from None
    if not (np.isfinite(v) and v > 0):
        raise parameter_error(name, f"{value!r} must be finite and > 0")
    return v


def base_out_of_reach(base: np.ndarray, shape: tuple[int, ...]) -> str | None:
    """Why a base point is too far from the image, or None if it is within reach.

    The base is where the arm is clamped: on the image, or hidden just beside it (under a
    clamp), and the curve is extrapolated to it one point per pixel. A base more than one
    image diagonal (:data:`BASE_REACH`) outside the image, along either axis, would be a
    hidden part longer than anything the image can show, so it is refused.

    Args:
        base: Base point (col, row) in pixels, finite.
        shape: The image's shape, (rows, cols, ...).

    Returns:
        The reason with the valid range (``"must be within ... col in [lo, hi], row in
        [lo, hi] px"``), or None.
    """
    rows, cols = int(shape[0]), int(shape[1])
    reach = BASE_REACH * float(np.hypot(rows, cols))
    col_range = (-reach, cols - 1 + reach)
    row_range = (-reach, rows - 1 + reach)
    col, row = float(base[0]), float(base[1])
    if col_range[0] <= col <= col_range[1] and row_range[0] <= row <= row_range[1]:
        return None
    return (
        f"must be within one image diagonal ({reach:.1f} px) of the {cols} x {rows} px image "
        f"(cols x rows): col in [{col_range[0]:.1f}, {col_range[1]:.1f}], row in "
        f"[{row_range[0]:.1f}, {row_range[1]:.1f}] px"
    )


def _resample(pts: np.ndarray, hw: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    t = np.linspace(0.0, s[-1], n)
    return np.column_stack([np.interp(t, s, pts[:, 0]), np.interp(t, s, pts[:, 1])]), np.interp(
        t, s, hw
    )


def _hermite(p0, t0, p1, t1, step) -> np.ndarray:
    """Cubic Hermite points from p0 (tangent t0) to p1 (tangent t1), p1 excluded."""
    chord = float(np.hypot(*(p1 - p0)))
    n = max(int(np.ceil(chord / step)), 1)
    u = np.linspace(0.0, 1.0, n + 1)[:-1, None]
    h00, h10 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u
    h01, h11 = -2 * u**3 + 3 * u**2, u**3 - u**2
    return h00 * p0 + h10 * chord * t0 + h01 * p1 + h11 * chord * t1


def _unit(v: np.ndarray) -> np.ndarray:
    return v / max(float(np.hypot(*v)), 1e-12)


def _start_tangent(pts: np.ndarray) -> np.ndarray:
    return _unit(pts[min(2, len(pts) - 1)] - pts[0])


def _coverage(mask, pts, hw, seen) -> tuple[float, float]:
    """Fraction of the mask inside the tube, and of the tube's seen part (``seen``: bool per
    point) inside the mask. The tube tested for the second is narrowed by 5 % and 2 px: the
    mask's edge is the segmentation threshold's, a pixel or two inside the steepest edge."""
    g = max(1, int(np.median(hw) // 4))
    rr, cc = np.nonzero(mask[::g, ::g])
    mp = np.column_stack([cc * g, rr * g]).astype(np.float64)
    dist, j = cKDTree(pts).query(mp)
    coverage = float(np.mean(dist <= hw[j] + 0.75)) if len(mp) else 0.0
    sub = np.zeros(len(pts), dtype=bool)
    sub[::g] = True
    sub &= seen
    c, h = pts[sub], hw[sub]
    d = np.diff(pts, axis=0)
    tan = np.vstack([d, d[-1:]])[sub]
    tan = tan / np.maximum(np.hypot(*tan.T), 1e-12)[:, None]
    nrm = np.column_stack([tan[:, 1], -tan[:, 0]])
    lam = np.linspace(-1, 1, 9)[None, :] * np.maximum(0.95 * h - 2.0, 0)[:, None]
    q = np.rint(c[:, None, :] + lam[..., None] * nrm[:, None, :]).astype(int).reshape(-1, 2)
    inside = (q[:, 0] >= 0) & (q[:, 0] < mask.shape[1]) & (q[:, 1] >= 0) & (q[:, 1] < mask.shape[0])
    hit = np.zeros(len(q), dtype=bool)
    hit[inside] = mask[q[inside, 1], q[inside, 0]]
    return coverage, float(np.mean(hit[inside])) if inside.any() else 0.0


def extract_backbone(
    image: str | os.PathLike[str] | ArrayLike,
    *,
    scale: float | None = None,
    base: ArrayLike | None = None,
    direction: ArrayLike | None = None,
    mask: ArrayLike | None = None,
    polarity: str | None = None,
    n_points: int | None = None,
    knot_spacing: float | None = None,
    min_area: int | None = None,
) -> Backbone:
    """Extracts an arm's backbone from a top-view photograph.

    The arm is segmented from its background (either polarity, uneven lighting flattened,
    distractors dropped), its skeleton gives a first curve, and a tube fit refines it to
    sub-pixel accuracy: the centre is midway between the two edges along the normal. The
    curve is ordered from the base to the tip. See ``docs/backbone.md`` for the method and
    its measured accuracy.

    Args:
        image: Path of an image file, or an array: (rows, cols) grey or (rows, cols, 3 or 4)
            RGB(A), integer or float. Pixel coordinates are (column, row), rows downward.
        scale: Metres per pixel. With it, ``points`` are metres in the arm's frame (origin at
            the base, x along ``direction``, y turned +90 degrees from x as seen on the image,
            i.e. toward the top of the image for a rightward direction); without it, pixels.
        base: Base point (col, row) in pixels. Sets which end is the base, and the curve is
            extrapolated to it when the base is hidden (e.g. under a clamp). It must lie
            within one image diagonal outside the image: col in [-D, cols - 1 + D], row in
            [-D, rows - 1 + D] with D = hypot(rows, cols) px. Default: the end at the image
            border, else the wider end.
        direction: The unloaded arm's direction in the image, (d_col, d_row) in pixels (any
            length). Default: the curve's tangent at the base (a clamped base keeps its
            direction under load).
        mask: Boolean array of the image's (rows, cols): the arm's pixels. Overrides the
            segmentation; the edges are then the mask's.
        polarity: ``"bright"`` (arm lighter than the background) or ``"dark"``; default
            detected from the image border.
        n_points: Number of output points; default one per pixel of length.
        knot_spacing: Knot spacing of the smoothing B-spline (px); default 1.5 half-widths
            within [6, 40] px.
        min_area: Smallest segmented component (px) counted as a distractor in the report.

    Returns:
        The backbone, base first, with its quality report.

    Raises:
        ParameterError: Unreadable or ill-shaped image, a bad argument (named; e.g. a
            ``base`` farther than one image diagonal outside the image, checked before any
            work), or no arm in the image.
    """
    arr = read_image(image)
    grey = to_grey(arr)
    scale = _positive("scale", scale)
    if scale is not None and scale > MAX_LENGTH:
        raise parameter_error("scale", f"{scale!r} must be <= {MAX_LENGTH:g} m per pixel")
    base_px = _pair("base", base)
    if base_px is not None:
        why = base_out_of_reach(base_px, grey.shape)
        if why is not None:
            raise parameter_error("base", f"{base!r} {why}")
    dir_px = _pair("direction", direction)
    if dir_px is not None and np.hypot(*dir_px) == 0:
        raise parameter_error("direction", f"{direction!r} must be non-zero")
    if polarity not in (None, "bright", "dark"):
        raise parameter_error("polarity", f"{polarity!r} must be 'bright', 'dark' or None")
    if n_points is not None:
        n_points = _args.count(n_points, "n_points", 2, _args.MAX_SAMPLES)
    knot_spacing = _positive("knot_spacing", knot_spacing)
    if knot_spacing is not None and knot_spacing < MIN_KNOT_SPACING:
        raise parameter_error("knot_spacing", f"{knot_spacing!r} must be >= {MIN_KNOT_SPACING} px")
    if min_area is not None and (
        isinstance(min_area, bool) or not isinstance(min_area, (int, np.integer)) or min_area < 1
    ):
        raise parameter_error("min_area", f"{min_area!r} must be an integer >= 1")

    if mask is not None:
        seg = mask_segmentation(mask, grey.shape)
    else:
        seg = segment(grey, polarity=polarity, base=base_px, min_area=min_area)
    try:
        cl = fit_centreline(seg.signal, seg.mask, seg.threshold, knot_spacing=knot_spacing)
    except ValueError as exc:
        raise parameter_error("image", f"no centreline found: {exc}") from None
    warnings = [*seg.warnings, *cl.warnings]
    pts, hw, ends = cl.points, cl.half_width, cl.ends

    # Which end is the base.
    if base_px is not None:
        flip = np.hypot(*(pts[-1] - base_px)) < np.hypot(*(pts[0] - base_px))
        base_source = "given"
    elif (ends[0] == "border") != (ends[1] == "border"):
        flip = ends[1] == "border"
        base_source = "border"
    else:
        n_end = max(len(hw) // 7, 1)
        w0, w1 = float(np.median(hw[:n_end])), float(np.median(hw[-n_end:]))
        flip = w1 > w0
        base_source = "wider end"
        if max(w0, w1) < WIDTH_RATIO_MIN * min(w0, w1):
            warnings.append(
                "the two ends are equally wide: base and tip may be swapped (pass `base`)"
            )
    if flip:
        pts, hw, ends = pts[::-1], hw[::-1], (ends[1], ends[0])
    tip_source = ends[1]
    if tip_source == "border":
        warnings.append("the arm leaves the image: the tip is at the border, not seen")

    # The base: extrapolate to a hidden base, or start at the given one.
    extrapolated = 0.0
    offset = 0.0
    if base_px is not None:
        t0 = _start_tangent(pts)
        v = base_px - pts[0]
        along = float(v @ t0)
        offset = float(abs(t0[0] * v[1] - t0[1] * v[0]))
        tol = max(BASE_TOLERANCE, 0.25 * float(hw[0]))
        if along < -tol:
            tb = _unit(dir_px) if dir_px is not None else t0
            if tb @ t0 < 0:
                tb = -tb
            head = _hermite(base_px, tb, pts[0], t0, POINT_SPACING)
            extrapolated = float(np.sum(np.hypot(*np.diff(np.vstack([head, pts[:1]]), axis=0).T)))
            n_head = len(head)
            w = hw[: max(len(hw) // 5, 2)]
            s = np.arange(len(w)) * POINT_SPACING
            slope = np.polyfit(s, w, 1)[0] if len(w) >= 2 else 0.0
            head_hw = hw[0] - slope * np.linspace(extrapolated, 0, n_head + 1)[:-1]
            pts = np.vstack([head, pts])
            hw = np.concatenate([np.maximum(head_hw, 0.0), hw])
            warnings.append(
                f"the base is hidden: the curve was extrapolated over {extrapolated:.1f} px "
                "to the given base"
            )
        elif along > tol:  # the given base lies on the visible arm: start there
            j = int(np.argmin(np.hypot(*(pts - base_px).T)))
            pts, hw = pts[j:], hw[j:]
        if offset > max(2.0, 0.5 * float(hw[0])):
            warnings.append(f"the given base is {offset:.1f} px beside the arm's axis")
        base_used = base_px
    else:
        base_used = pts[0].copy()
    length_px = float(np.sum(np.hypot(*np.diff(pts, axis=0).T)))
    if extrapolated > 0.1 * length_px:
        warnings.append(
            f"{extrapolated / length_px:.0%} of the length is extrapolated: more than 10 %"
        )

    n = n_points or max(int(np.ceil(length_px / POINT_SPACING)) + 1, 2)
    pixels, hw = _resample(pts, hw, int(n))
    if dir_px is not None:
        d = _unit(dir_px)
        direction_source = "given"
    else:
        d = _start_tangent(pixels)
        direction_source = "fitted"
    arc = np.linspace(0.0, length_px, len(pixels))

    seen = arc >= extrapolated
    coverage, fill = _coverage(seg.mask, pixels, hw, seen)
    if coverage < 0.9:
        warnings.append(f"the fitted tube covers only {coverage:.0%} of the arm's mask")
    if fill < 0.95:
        warnings.append(f"only {fill:.0%} of the fitted tube lies on the arm's mask")
    if cl.residual > 1.0:
        warnings.append(f"edge midpoints scatter by {cl.residual:.2f} px RMS about the curve")
    if cl.outliers > 0.1 * len(pixels):
        warnings.append(f"{cl.outliers} cross-sections had one edge rejected")
    if seg.noise > 0 and seg.contrast < 8 * seg.noise:
        warnings.append(
            f"low contrast: {seg.contrast:.3g} is {seg.contrast / seg.noise:.1f} x the noise"
        )

    if scale is not None:
        nrm = np.array([d[1], -d[0]])
        rel = pixels - base_used
        points = scale * np.column_stack([rel @ d, rel @ nrm])
        unit = "m"
        factor = scale
    else:
        points, unit, factor = pixels.copy(), "px", 1.0
    quality = BackboneQuality(
        polarity=seg.polarity,
        contrast=seg.contrast,
        noise=seg.noise,
        threshold=seg.threshold,
        coverage=coverage,
        tube_fill=fill,
        fit_residual=cl.residual,
        edge_outliers=cl.outliers,
        discarded_components=seg.discarded_components,
        discarded_area=seg.discarded_area,
        base_source=base_source,
        base_extrapolated=extrapolated > 0,
        extrapolated_length=extrapolated,
        base_offset=offset,
        direction_source=direction_source,
        tip_source=tip_source,
        warnings=tuple(warnings),
    )
    return Backbone(
        points=points,
        arc_length=arc * factor,
        half_width=hw * factor,
        pixels=pixels,
        unit=unit,
        scale=scale,
        base=np.asarray(base_used, dtype=np.float64),
        direction=d,
        image_shape=(int(grey.shape[0]), int(grey.shape[1])),
        quality=quality,
    )
