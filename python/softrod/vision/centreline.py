"""The arm's centreline to sub-pixel accuracy: skeleton, then a tube fit on the edges.

1. A first guess: the skeleton of the arm's mask (reduced so that the arm stays 8-16 px wide),
   its longest path, trimmed by 1.5 local half-widths at each end where the skeleton forks
   toward the corners of the end faces.
2. A tube fit: the curve is a least-squares cubic B-spline in arc length. Across it, at every
   pixel of length, the flattened signal is sampled along the normal; the two edges are where the
   profile falls to half of its peak, walking outward from the curve (linear interpolation
   between samples). The centre is midway between the edges along the normal: for a round arm
   seen from above the silhouette is exactly the union of the segments c(s) +- r(s) n(s), so the
   midpoint is the backbone and the half-distance its radius, taper included. A cross-section
   whose half-width leaves its robust trend (a float or a marker touching one side) keeps the
   edge that agrees with the trend and the trend's half-width; near the ends such sections are
   dropped instead (there they reach an end face). The spline is refitted to the midpoints with
   Huber weights; the curve grows at its ends while cross-sections still find the arm, then is
   refined in place until it stops moving. Half-widths come from the steepest descent of each
   profile near its half-peak crossing, which shading shifts.
3. The ends: along the extended centreline, averaged over a few lines parallel to it, the
   signal falls to half its value on the arm at the end face; or the line leaves the image first
   (an arm entering from the border).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.interpolate import make_lsq_spline
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, dijkstra
from skimage.morphology import skeletonize

#: Spacing of the cross-sections along the curve (px).
SECTION_STEP = 1.0
#: Largest number of tube-fit rounds.
MAX_ROUNDS = 12
#: The ends have stopped growing when neither moved by more than this in a round (px).
GROWN = 3.0
#: The fit has converged when the curve moves across itself by less than this (px), or by
#: less than a quarter of the midpoints' scatter, between rounds.
CONVERGED = 0.05
#: A cross-section's half-width is an outlier beyond max(this (px), 4 robust sigmas).
OUTLIER_FLOOR = 0.75
#: A cross-section whose peak is below this fraction of the running median is blurred by an
#: end face and is left out.
FAINT = 0.7
#: Cross-sections within this many half-widths of an end get no one-sided repair.
END_ZONE = 2.0
#: Knot spacing of the robust trends of half-width, offset and peak, in half-widths.
TREND_SPACING = 8.0
#: Tukey biweight constant, in robust sigmas.
TUKEY = 4.685
#: Half-width of the window around the half-peak crossing where the steepest edge is sought
#: (px), at most half the half-width; arms thinner than 6 px keep the crossings.
EDGE_WINDOW = 3.0
#: Invalid cross-sections in a row that end the curve.
GAP = 3
#: Huber constant, in robust sigmas of the midpoints about the curve.
HUBER = 1.345


@dataclass
class Centreline:
    """A fitted centreline in pixels, first end to last end (not yet ordered base to tip)."""

    points: np.ndarray  # (n, 2) (col, row), about SECTION_STEP apart
    half_width: np.ndarray  # (n,) px
    ends: tuple[str, str]  # "end edge" or "border" for the first and last end
    residual: float  # RMS midpoint distance to the curve (px)
    outliers: int  # cross-sections that kept one edge only
    warnings: list[str]


def _skeleton_path(mask: np.ndarray) -> np.ndarray:
    """Longest geodesic path through the skeleton of ``mask``, as (col, row) pixel points."""
    skel = skeletonize(mask)
    rr, cc = np.nonzero(skel)
    if rr.size < 2:
        return np.column_stack([cc, rr]).astype(np.float64)
    index = -np.ones(skel.shape, dtype=np.int64)
    index[rr, cc] = np.arange(rr.size)
    src, dst, wts = [], [], []
    for dr, dc in ((0, 1), (1, -1), (1, 0), (1, 1)):
        r2, c2 = rr + dr, cc + dc
        ok = (r2 < skel.shape[0]) & (c2 >= 0) & (c2 < skel.shape[1])
        j = np.full(rr.size, -1)
        j[ok] = index[r2[ok], c2[ok]]
        hit = j >= 0
        src.append(np.nonzero(hit)[0])
        dst.append(j[hit])
        wts.append(np.full(hit.sum(), np.hypot(dr, dc)))
    src, dst, wts = np.concatenate(src), np.concatenate(dst), np.concatenate(wts)
    graph = coo_matrix((wts, (src, dst)), shape=(rr.size, rr.size)).tocsr()
    _, comp = connected_components(graph, directed=False)
    main = np.argmax(np.bincount(comp))
    start = int(np.nonzero(comp == main)[0][0])
    d0 = dijkstra(graph, directed=False, indices=start)
    a = int(np.argmax(np.where(np.isfinite(d0), d0, -1)))
    d1, pred = dijkstra(graph, directed=False, indices=a, return_predecessors=True)
    b = int(np.argmax(np.where(np.isfinite(d1), d1, -1)))
    path = [b]
    while path[-1] != a:
        path.append(int(pred[path[-1]]))
    path = np.array(path[::-1])
    return np.column_stack([cc[path], rr[path]]).astype(np.float64)


def _chord(pts: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])


class _Curve:
    """A B-spline centreline in arc length, extended by straight lines beyond its ends."""

    def __init__(self, u: np.ndarray, pts: np.ndarray, spacing: float, w=None) -> None:
        u0, u1 = float(u[0]), float(u[-1])
        n_int = max(int((u1 - u0) / spacing) - 1, 0)
        n_int = min(n_int, max(len(u) // 3 - 4, 0))
        inner = np.quantile(u, np.linspace(0, 1, n_int + 2)[1:-1]) if n_int else np.array([])
        k = 3 if len(u) >= 8 else 1
        t = np.concatenate([[u0] * (k + 1), inner, [u1] * (k + 1)])
        self.spline = make_lsq_spline(u, pts, t, k=k, w=w)
        self.u0, self.u1 = u0, u1
        self.deriv = self.spline.derivative()

    def tangent(self, u: np.ndarray) -> np.ndarray:
        d = self.deriv(np.clip(u, self.u0, self.u1))
        return d / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-12)[:, None]

    def __call__(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points and unit tangents at ``u`` (straight beyond the ends)."""
        uc = np.clip(u, self.u0, self.u1)
        tan = self.tangent(u)
        pts = self.spline(uc) + (u - uc)[:, None] * tan
        return pts, tan


def _sample(img: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Bilinear samples at (col, row) points, any leading shape; NaN outside the image."""
    flat = pts.reshape(-1, 2)
    v = ndimage.map_coordinates(
        img, [flat[:, 1], flat[:, 0]], order=1, mode="constant", cval=np.nan
    )
    return v.reshape(pts.shape[:-1])


def _first_below(v: np.ndarray, level: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Walking along axis 1 from index 0, the sub-sample position (in units of ``step``) where
    each row first falls below ``level``; valid only where that happens before a NaN."""
    below = v < level[:, None]
    stop = below | np.isnan(v)
    j = np.argmax(stop, axis=1)
    rows = np.arange(len(v))
    ok = stop[rows, j] & below[rows, j] & (j > 0)
    j = np.maximum(j, 1)
    a, b = v[rows, j - 1], v[rows, j]
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = np.clip((a - level) / (a - b), 0.0, 1.0)
    return (j - 1 + frac) * step, ok & np.isfinite(frac)


def _robust_trend(u: np.ndarray, x: np.ndarray, spacing: float) -> np.ndarray:
    """A smooth trend of ``x(u)`` that ignores local bumps: a cubic least-squares spline with
    Tukey biweights (4.685 robust sigmas), a few reweighting rounds."""
    w = np.ones(len(u))
    fit = np.full(len(u), np.median(x))
    for _ in range(4):
        fit = _Curve(u, x[:, None], spacing, w).spline(u)[:, 0]
        r = x - fit
        sig = max(1.4826 * float(np.median(np.abs(r))), 1e-6)
        w = np.clip(1.0 - (r / (TUKEY * sig)) ** 2, 0.0, 1.0) ** 2 + 1e-6
    return fit


def _sections(signal, mask, curve, u, reach, peak_min, step):
    """Cross-sections of the curve at parameters ``u`` (``mask`` as floats): points, normals,
    half-peak edge offsets (+, -), validity, peaks, steepest-edge offsets (+, -)."""
    pts, tan = curve(u)
    nrm = np.column_stack([tan[:, 1], -tan[:, 0]])  # +90 deg as seen on the image
    lam = np.arange(0.0, reach + step, step)
    plus = _sample(signal, pts[:, None, :] + lam[None, :, None] * nrm[:, None, :])
    minus = _sample(signal, pts[:, None, :] - lam[None, :, None] * nrm[:, None, :])
    core = max(1, int(np.ceil(1.0 / step)))
    near = np.concatenate([plus[:, : core + 1], minus[:, : core + 1]], axis=1)
    peak = np.where(np.isnan(near), -np.inf, near).max(axis=1)  # -inf: off the image
    level = 0.5 * peak
    ep, okp = _first_below(plus, level, step)
    em, okm = _first_below(minus, level, step)
    inside = _sample(mask, pts) > 0.5
    ok = okp & okm & (peak > peak_min) & inside
    gp, gm = _steepest(plus, ep, step), _steepest(minus, em, step)
    return pts, nrm, ep, -em, ok, peak, gp, -gm


def _steepest(v: np.ndarray, edge: np.ndarray, step: float) -> np.ndarray:
    """Sub-sample position of the steepest descent of each profile within EDGE_WINDOW px of
    its half-peak crossing ``edge`` (parabola through the three samples around the maximum);
    the crossing itself where the window does not fit."""
    g = -np.gradient(v, step, axis=1)
    j = np.arange(v.shape[1])[None, :]
    c = edge[:, None] / step
    half = 0.5 * float(np.nanmedian(edge))
    w = min(EDGE_WINDOW, half) / step
    g = np.where((np.abs(j - c) <= w) & np.isfinite(g), g, -np.inf)
    k = np.clip(np.argmax(g, axis=1), 1, v.shape[1] - 2)
    rows = np.arange(len(v))
    a, b, d = g[rows, k - 1], g[rows, k], g[rows, k + 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        den = a - 2 * b + d
        shift = np.where(np.isfinite(den) & (den < 0), 0.5 * (a - d) / den, 0.0)
    out = (k + np.clip(shift, -0.5, 0.5)) * step
    good = np.isfinite(b) & (half >= 1.5)
    return np.where(good, out, edge)


def _contiguous(ok: np.ndarray, lo: int, hi: int) -> np.ndarray:
    """Drops the samples before ``lo`` / after ``hi`` beyond the first run of GAP invalid ones
    going outward (isolated noisy cross-sections do not stop the curve)."""
    keep = ok.copy()
    run = np.convolve(~ok, np.ones(GAP, dtype=int), mode="valid") == GAP  # run starts
    starts = np.nonzero(run)[0]
    below = starts[starts + GAP <= lo]
    if below.size:
        keep[: below[-1] + GAP] = False
    above = starts[starts >= hi]
    if above.size:
        keep[above[0] :] = False
    return keep


def _robust_fit(u, pts, spacing) -> tuple[_Curve, np.ndarray]:
    w = np.ones(len(u))
    for _ in range(3):
        curve = _Curve(u, pts, spacing, w)
        res = np.hypot(*(curve.spline(u) - pts).T)
        sig = max(1.4826 * np.median(res), 1e-3)
        w = np.minimum(1.0, HUBER * sig / np.maximum(res, 1e-12))
    return curve, res


def _first_guess(mask: np.ndarray, knot_spacing: float | None) -> tuple[_Curve, float]:
    """The skeleton's longest path as a first curve, and the mean half-width (px)."""
    area = int(mask.sum())
    edge = area - int(ndimage.binary_erosion(mask).sum())
    hw0 = max(area / max(edge, 1), 0.5)  # a long strip: area / perimeter
    k = max(1, int(hw0 // 4))
    rows, cols = np.nonzero(mask)
    r0, c0 = max(rows.min() - 2 * k, 0), max(cols.min() - 2 * k, 0)
    crop = mask[r0 : rows.max() + 2 * k + 1, c0 : cols.max() + 2 * k + 1]
    if k > 1:
        h, w = (crop.shape[0] // k + 1) * k, (crop.shape[1] // k + 1) * k
        pad = np.zeros((h, w), dtype=bool)
        pad[: crop.shape[0], : crop.shape[1]] = crop
        small = pad.reshape(h // k, k, w // k, k).mean(axis=(1, 3)) > 0.5
    else:
        small = crop
    path_small = _skeleton_path(small)
    if len(path_small) < 2:
        raise ValueError("the arm's mask is too small to hold a centreline")
    ri, ci = path_small[:, 1].astype(int), path_small[:, 0].astype(int)
    depth = ndimage.distance_transform_edt(small)[ri, ci] * k
    path = path_small * k + (k - 1) / 2 + np.array([c0, r0])
    u = _chord(path)
    if u[-1] < 2:
        raise ValueError("the arm's mask is too small to hold a centreline")
    # Trim each end by 1.5 local half-widths: the skeleton forks toward the end-face corners.
    quarter = max(len(u) // 4, 1)
    trim0 = min(1.5 * float(depth[:quarter].max()), 0.25 * u[-1])
    trim1 = min(1.5 * float(depth[-quarter:].max()), 0.25 * u[-1])
    sel = (u >= trim0) & (u <= u[-1] - trim1)
    if sel.sum() < 4:
        sel = np.ones(len(u), dtype=bool)
    path, u = path[sel], u[sel] - u[sel][0]
    spacing0 = knot_spacing or float(np.clip(1.5 * hw0, 6.0, 40.0))
    return _Curve(u, path, max(spacing0, 2.0 * k)), hw0


def fit_centreline(
    signal: np.ndarray,
    mask: np.ndarray,
    threshold: float,
    *,
    knot_spacing: float | None = None,
) -> Centreline:
    """Fits the centreline of the arm in ``mask`` (see the module docstring).

    Args:
        signal: Flattened image, arm positive, background about 0.
        mask: The arm's mask (one component).
        threshold: Segmentation threshold on ``signal``: a cross-section whose peak is below
            half of it does not show the arm.
        knot_spacing: B-spline knot spacing (px); default 1.5 half-widths, within [6, 40].

    Raises:
        ValueError: The mask is too small to hold a curve (caught by the caller).
    """
    warnings: list[str] = []
    curve, hw0 = _first_guess(mask, knot_spacing)
    mask_f = mask.astype(np.float64)
    step = min(0.5, max(hw0 / 6, 0.1))  # profile sampling (px): finer for thin arms
    reach = 2.2 * hw0 + 6
    peak_min = 0.5 * threshold
    lo_u, hi_u = curve.u0, curve.u1
    hw_lo = hw_hi = hw0
    outliers = 0
    grow = True  # extend the ends while cross-sections find the arm, then refine in place
    for rnd in range(MAX_ROUNDS):
        n_lo = int(np.ceil(max(3.0, hw_lo) / SECTION_STEP)) if grow else 0
        n_hi = int(np.ceil(max(3.0, hw_hi) / SECTION_STEP)) if grow else 0
        core = np.append(np.arange(lo_u, hi_u, SECTION_STEP), hi_u)
        us = np.concatenate(
            [
                lo_u - SECTION_STEP * np.arange(n_lo, 0, -1),
                core,
                hi_u + SECTION_STEP * np.arange(1, n_hi + 1),
            ]
        )
        i_lo, i_hi = n_lo, n_lo + len(core)
        sections = _sections(signal, mask_f, curve, us, reach, peak_min, step)
        pts, nrm, lp, lm, ok, peak, gp, gm = sections
        idx = np.nonzero(ok)[0]
        if idx.size < 4:
            raise ValueError("no cross-section of the arm could be measured")
        half, mid = 0.5 * (lp[idx] - lm[idx]), 0.5 * (lp[idx] + lm[idx])
        trend_spacing = max(TREND_SPACING * float(np.median(half)), 20.0)
        h_med = _robust_trend(us[idx], half, trend_spacing)
        m_med = _robust_trend(us[idx], mid, trend_spacing)
        p_med = _robust_trend(us[idx], peak[idx], trend_spacing)
        dev = half - h_med
        tol = max(OUTLIER_FLOOR, 4 * 1.4826 * float(np.median(np.abs(dev))))
        bad = np.abs(dev) > tol
        plus_dev = np.abs(lp[idx] - (m_med + h_med))
        minus_dev = np.abs(lm[idx] - (m_med - h_med))
        both = bad & (plus_dev > tol) & (minus_dev > tol)
        faint = peak[idx] < FAINT * p_med  # blurred by an end face
        # Near the ends a bad cross-section is one that reaches an end face: drop it (a
        # one-sided repair there would bend the curve toward an end-face corner).
        span = us[idx]
        end_zone = (span < span[0] + END_ZONE * h_med) | (span > span[-1] - END_ZONE * h_med)
        ok[idx[both | faint | (end_zone & bad)]] = False
        ok = _contiguous(ok, i_lo, i_hi)
        use = ok[idx]
        if use.sum() < 4:
            raise ValueError("no cross-section of the arm could be measured")
        keep_minus = bad & (plus_dev > minus_dev)  # the + edge is off: keep the - one
        mid = np.where(bad & keep_minus, lm[idx] + h_med, mid)
        mid = np.where(bad & ~keep_minus, lp[idx] - h_med, mid)
        half = np.where(bad, h_med, half)
        outliers = int((bad & use).sum())
        sel = idx[use]
        centres = pts[sel] + mid[use, None] * nrm[sel]
        u_fit = us[sel]
        old, old_lo, old_hi = curve, lo_u, hi_u
        curve, res = _robust_fit(u_fit, centres, _knot_spacing(half[use], knot_spacing))
        # Half-widths from the steepest edges: the half-peak crossings are shifted by shading.
        # Sections with a rejected edge are left out.
        steep = 0.5 * (gp[sel] - gm[sel])
        two = ~bad[use] if (~bad[use]).sum() >= 8 else np.ones(len(sel), dtype=bool)
        hw_spacing = 2.0 * _knot_spacing(half[use], knot_spacing)
        trend = _robust_trend(u_fit[two], steep[two], hw_spacing)
        hw_curve = _Curve(u_fit[two], trend[:, None], hw_spacing)
        hw = hw_curve.spline(np.clip(u_fit, hw_curve.u0, hw_curve.u1))[:, 0]
        lo_u, hi_u = curve.u0, curve.u1
        hw_lo, hw_hi = float(hw[0]), float(hw[-1])
        reach = 1.5 * float(hw.max()) + 6
        a, b = max(lo_u, old_lo), min(hi_u, old_hi)
        margin = END_ZONE * float(np.median(hw))
        a, b = a + margin, b - margin
        if grow:  # the first round measures on the skeleton's rough curve: keep growing
            grow = rnd == 0 or max(abs(lo_u - old_lo), abs(hi_u - old_hi)) > GROWN
        elif b > a:
            uu = np.linspace(a, b, 200)
            p_new, _ = curve(uu)
            p_old, t_old = old(uu)
            dp = p_new - p_old
            moved = np.abs(dp[:, 0] * t_old[:, 1] - dp[:, 1] * t_old[:, 0])  # across the curve
            if moved.max() < max(CONVERGED, 0.25 * float(np.sqrt(np.mean(res**2)))):
                break
    else:
        warnings.append(f"the tube fit did not settle in {MAX_ROUNDS} rounds")

    # Dense samples in arc length.
    uu = np.linspace(lo_u, hi_u, max(int(np.ceil((hi_u - lo_u) * 4)), 8))
    pu, _ = curve(uu)
    su = _chord(pu)
    n_out = max(int(np.ceil(su[-1] / SECTION_STEP)) + 1, 2)
    s_out = np.linspace(0.0, su[-1], n_out)
    u_out = np.interp(s_out, su, uu)
    dense, _ = curve(u_out)
    dense_hw = hw_curve.spline(np.clip(u_out, hw_curve.u0, hw_curve.u1))[:, 0]

    # Ends: along the curve, a profile averaged over lines parallel to it.
    ends = []
    first, last = [], []
    for side in (0, 1):
        u_end = lo_u if side == 0 else hi_u
        p, t = curve(np.array([u_end]))
        out = -t[0] if side == 0 else t[0]
        h = float(dense_hw[0] if side == 0 else dense_hw[-1])
        end, kind = _end_point(signal, p[0], out, h, step)
        ends.append(kind)
        if end is None:
            warnings.append(f"no end face found at the {('first', 'last')[side]} end")
        elif side == 0:
            first = [end]
        else:
            last = [end]
    pts = np.vstack([*first, dense, *last]) if first or last else dense
    hws = np.concatenate([dense_hw[:1]] * len(first) + [dense_hw] + [dense_hw[-1:]] * len(last))
    keep = np.concatenate([[True], np.hypot(*np.diff(pts, axis=0).T) > 1e-9])
    residual = float(np.sqrt(np.mean(res**2)))
    return Centreline(
        points=pts[keep],
        half_width=hws[keep],
        ends=(ends[0], ends[1]),
        residual=residual,
        outliers=outliers,
        warnings=warnings,
    )


def _knot_spacing(half: np.ndarray, knot_spacing: float | None) -> float:
    """Knot spacing of the centreline spline (px): given, or 1.5 half-widths in [6, 40]."""
    return knot_spacing or float(np.clip(1.5 * np.median(half), 6.0, 40.0))


def _end_point(signal, p, out, h, step) -> tuple[np.ndarray | None, str]:
    """Where the arm ends beyond ``p`` along the outward unit tangent ``out``."""
    nrm = np.array([out[1], -out[0]])
    back = max(h, 2.0)
    t = np.arange(-back, h + 8.0 + step, step)
    offs = np.linspace(-0.4, 0.4, 5) * h
    lines = p + t[:, None, None] * out + offs[None, :, None] * nrm
    v = _sample(signal, lines)
    prof = v.mean(axis=1)  # NaN where any line is off the image
    inside = prof[(t >= -back) & (t <= -1.0)]
    if inside.size == 0 or np.all(np.isnan(inside)):
        return None, "end edge"
    level = 0.5 * np.nanmedian(inside)
    start = int(np.searchsorted(t, -1.0))
    pos, ok = _first_below(prof[None, start:], np.array([level]), step)
    if ok[0]:
        return p + (t[start] + pos[0]) * out, "end edge"
    seg = prof[start:]
    if np.isnan(seg).any():  # the line leaves the image before the arm ends
        return _border_point(p, out, signal.shape), "border"
    return None, "end edge"


def _border_point(p, d, shape) -> np.ndarray:
    """First point of the ray p + t d (t >= 0) on the image border [-0.5, side - 0.5]."""
    ts = []
    for k, n in ((0, shape[1]), (1, shape[0])):
        if abs(d[k]) > 1e-12:
            for edge in (-0.5, n - 0.5):
                tk = (edge - p[k]) / d[k]
                if tk >= 0:
                    ts.append(tk)
    return p + min(ts) * d if ts else p.copy()
