"""Synthetic top-view photographs of a tapered arm, rendered from a known backbone.

The renderer is an oracle for the backbone extractor and shares none of its assumptions: the arm
is a rod of circular cross-sections of radius r(s) perpendicular to its backbone, seen from
above, so its silhouette is the union of the segments c(s) +- r(s) n(s) (n from the model's
tangent angle, not from image data) and its top-lit shading is the cosine of the surface normal
with the viewing direction, sqrt(1 - (lambda / r)^2) at lateral offset lambda. Edges are
anti-aliased by supersampling; the photo then gets a non-polynomial illumination field (a
light spot and a gradient multiplying everything), a faint textured tank floor, distractor blobs
(floats, markers, a bubble ring), an optional clamp over the base, Gaussian blur, Gaussian noise
and 8-bit quantisation.

Pixel coordinates are (column, row), rows downward, pixel centres at integers. The model frame
(x along the unloaded arm, y toward the cable) maps to pixels by
``p = base + (x d + y n) / scale`` with ``d`` the unit direction and ``n = (d_row, -d_col)``,
i.e. y is turned +90 degrees from x as seen on the image.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

import softrod

ARM = softrod.PlanarCableArm.published_arm()

#: Image sizes of the accuracy tests: ~0.3 MP and ~1 MP, with the scale that fits every
#: tension of the planar cable-arm paper's arm in the frame (m per pixel).
SIZES = {
    "0.3MP": ((480, 640), 0.27 / 560),
    "1MP": ((864, 1152), 0.27 / 1010),
}


@dataclass
class Photo:
    """A rendered photo and the truth it was made from (pixels unless stated)."""

    image: np.ndarray  # uint8, (H, W) or (H, W, 3)
    centre: np.ndarray  # (n, 2) true backbone (col, row), base -> tip, dense
    s: np.ndarray  # (n,) undeformed arc length of those samples (m)
    radius: np.ndarray  # (n,) true radius (px)
    x: np.ndarray  # (n,) model backbone, arm frame (m)
    y: np.ndarray  # (n,) model backbone, arm frame (m)
    base: np.ndarray  # (2,) base point (col, row)
    direction: np.ndarray  # (2,) unit, pixel coordinates
    scale: float  # m per pixel
    length: float  # arm length L (m)
    clamp_s: float  # arc length hidden under the clamp (m), 0 without a clamp
    blobs: list  # (kind, centre (col, row), semi-axes (px)) of each distractor

    @property
    def tip(self) -> np.ndarray:
        return self.centre[-1]


def _frame(direction) -> tuple[np.ndarray, np.ndarray]:
    d = np.asarray(direction, dtype=float)
    d = d / np.hypot(*d)
    return d, np.array([d[1], -d[0]])


def _coverage(poly_cr: np.ndarray, shape: tuple[int, int], ss: int) -> np.ndarray:
    """Fraction of each pixel inside a polygon (vertices (col, row)), by ss x ss supersampling.

    A scanline fill (even-odd rule) evaluated at subpixel centres: subpixel m of a pixel axis
    has its centre at (m + 0.5) / ss - 0.5 in pixel coordinates.
    """
    h, w = shape
    q = (np.asarray(poly_cr, dtype=float) + 0.5) * ss - 0.5
    c0 = max(int(np.floor(q[:, 0].min())) - 1, 0)
    c1 = min(int(np.ceil(q[:, 0].max())) + 2, w * ss)
    r0 = max(int(np.floor(q[:, 1].min())) - 1, 0)
    r1 = min(int(np.ceil(q[:, 1].max())) + 2, h * ss)
    c0, r0 = c0 - c0 % ss, r0 - r0 % ss  # whole pixels
    c1, r1 = min(c1 + (-c1) % ss, w * ss), min(r1 + (-r1) % ss, h * ss)
    cov = np.zeros(shape)
    if c1 <= c0 or r1 <= r0:
        return cov
    x0, y0 = q[:, 0] - c0, q[:, 1] - r0
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    nr, nc = r1 - r0, c1 - c0
    lo, hi = np.minimum(y0, y1), np.maximum(y0, y1)
    j0 = np.clip(np.ceil(lo), 0, nr).astype(int)  # rows j with lo <= j < hi
    j1 = np.clip(np.ceil(hi), 0, nr).astype(int)
    cnt = np.maximum(j1 - j0, 0)
    e = np.repeat(np.arange(len(q)), cnt)
    j = np.repeat(j0, cnt) + np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    x = x0[e] + (j - y0[e]) / (y1[e] - y0[e]) * (x1[e] - x0[e])
    order = np.lexsort((x, j))
    j, x = j[order], x[order]
    ja, xa, xb = j[0::2], x[0::2], x[1::2]
    ia = np.clip(np.ceil(xa), 0, nc).astype(int)
    ib = np.clip(np.ceil(xb), 0, nc).astype(int)
    diff = np.zeros((nr, nc + 1), dtype=np.int32)
    np.add.at(diff, (ja, ia), 1)
    np.add.at(diff, (ja, ib), -1)
    sub = np.cumsum(diff[:, :nc], axis=1)
    block = sub.reshape(nr // ss, ss, nc // ss, ss).sum(axis=(1, 3)) / ss**2
    cov[r0 // ss : r1 // ss, c0 // ss : c1 // ss] = block
    return cov


def _ellipse(centre, axes, angle, n=96) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ca, sa = np.cos(angle), np.sin(angle)
    u, v = axes[0] * np.cos(t), axes[1] * np.sin(t)
    return np.column_stack([centre[0] + ca * u - sa * v, centre[1] + sa * u + ca * v])


def render_backbone(
    x,
    y,
    angle,
    radius,
    s,
    *,
    shape=(480, 640),
    scale=0.27 / 560,
    base=None,
    direction=(1.0, 0.0),
    background="dark",
    blur=1.2,
    noise=0.02,
    n_blobs=5,
    touching=False,
    clamp=0.0,
    rgb=False,
    seed=0,
    supersample=4,
) -> Photo:
    """Renders a photo of an arm whose backbone is (x, y, angle)(s) in the arm frame (m).

    Args:
        x, y, angle: Backbone and tangent angle in the arm frame, dense samples (m, rad).
        radius: Radius at each sample (m).
        s: Undeformed arc length of the samples (m).
        shape: Image (rows, columns).
        scale: m per pixel.
        base: Base point (col, row); default 30 px from the left border, 40 mm above the
            bottom.
        direction: Unloaded arm direction in pixel coordinates.
        background: "dark" (light arm) or "light" (dark arm).
        blur: Gaussian blur sigma (px).
        noise: Gaussian noise sigma (fraction of full scale).
        n_blobs: Number of distractors (0 to 5): two floats, a marker, a bubble ring, and a
            float 3-5 px + 2 blur sigmas beyond the tip.
        touching: Moves the first float onto the arm's side at mid-length (overlapping it).
        clamp: Fraction of the arm length hidden by a clamp over the base (0 for none).
        rgb: Returns an RGB image (tinted silicone on a tinted floor) instead of grey.
        seed: Seed of every random choice.
        supersample: Supersampling factor per axis for anti-aliasing.
    """
    rng = np.random.default_rng(seed)
    h, w = shape
    d, n = _frame(direction)
    if base is None:
        base = np.array([30.0, h - 1 - 0.04 / scale])
    base = np.asarray(base, dtype=float)
    x, y, angle, radius, s = (np.asarray(v, dtype=float) for v in (x, y, angle, radius, s))
    centre = base + (np.outer(x, d) + np.outer(y, n)) / scale
    normal = np.outer(-np.sin(angle), d) + np.outer(np.cos(angle), n)  # model's left normal
    r_px = radius / scale
    left, right = centre + r_px[:, None] * normal, centre - r_px[:, None] * normal
    cov = _coverage(np.vstack([left, right[::-1]]), shape, supersample)

    # Shading at pixel centres from the lateral offset lambda: nearest dense sample's frame.
    rows, cols = np.nonzero(cov > 0)
    pts = np.column_stack([cols, rows]).astype(float)
    _, idx = cKDTree(centre).query(pts)
    lam = np.einsum("ij,ij->i", pts - centre[idx], normal[idx])
    shade = np.zeros(shape)
    shade[rows, cols] = np.sqrt(np.clip(1.0 - (lam / r_px[idx]) ** 2, 0.0, 1.0))
    shade = 0.6 + 0.4 * shade  # 0.6 at the silhouette edge, 1 along the middle

    if background == "dark":
        floor, arm = 0.14, 0.78 * shade
    elif background == "light":
        floor, arm = 0.84, 0.12 + 0.25 * (shade - 0.6) / 0.4  # 0.12 at the edges, 0.37 middle
    else:
        raise ValueError(background)
    tex = ndimage.gaussian_filter(rng.normal(size=shape), 12.0)
    img = floor + 0.015 * tex / tex.std()
    img = img * (1 - cov) + arm * cov

    # Distractors, placed clear of the arm and of each other (4 px + 2 blur sigmas at least),
    # except the float asked to touch the arm.
    dist = ndimage.distance_transform_edt(cov < 0.01)
    r0, rl = r_px[0], r_px[-1]
    arm_like = 0.72 if background == "dark" else 0.2
    specs = [
        ("float", (0.8 * r0, 0.45 * r0), arm_like),
        ("float", (0.55 * r0, 0.3 * r0), arm_like * 0.9 + 0.05),
        ("marker", (0.18 * r0, 0.18 * r0), 0.03),
        ("bubble", (0.3 * r0, 0.3 * r0), 0.95),
        ("float", (0.5 * rl, 0.35 * rl), arm_like),
    ][:n_blobs]
    blobs = []
    tip_t = np.array([np.cos(angle[-1]), np.sin(angle[-1])])
    tip_dir = tip_t[0] * d + tip_t[1] * n
    for k, (kind, axes, level) in enumerate(specs):
        for _ in range(2000):
            ang = rng.uniform(0, np.pi)
            if k == 4:  # near the tip: beyond its end face, a few px of floor in between
                gap = rng.uniform(3.0, 5.0) + 2 * blur
                c = (
                    centre[-1]
                    + tip_dir * (gap + axes[0])
                    + rng.uniform(-0.3, 0.3) * rl * (normal[-1])
                )
                ang = np.arctan2(tip_dir[1], tip_dir[0])
            elif k == 0 and touching:
                i = len(s) // 2
                c = centre[i] + normal[i] * (r_px[i] + 0.4 * axes[1])
                ang = np.arctan2(normal[i][1], normal[i][0]) + np.pi / 2
            else:
                c = rng.uniform([axes[0] + 5, axes[0] + 5], [w - axes[0] - 5, h - axes[0] - 5])
            poly = _ellipse(c, axes, ang)
            inside = (
                (poly[:, 0] > 1) & (poly[:, 0] < w - 2) & (poly[:, 1] > 1) & (poly[:, 1] < h - 2)
            )
            pc = np.clip(np.round(poly).astype(int), 0, [w - 1, h - 1])
            clear = dist[pc[:, 1], pc[:, 0]].min() > (2.5 if k == 4 else 4.0) + 2 * blur
            near_base = np.hypot(*(c - base)) < 3 * r0
            apart = all(np.hypot(*(c - c2)) > axes[0] + a2[0] + 4 + 2 * blur for _, c2, a2 in blobs)
            if inside.all() and apart and not near_base and (clear or (k == 0 and touching)):
                break
        else:
            raise RuntimeError(f"no room for distractor {k}")
        bc = _coverage(poly, shape, supersample)
        if kind == "bubble":  # a ring: bright rim, the floor seen through the middle
            bc = bc - _coverage(_ellipse(c, (axes[0] * 0.7, axes[1] * 0.7), ang), shape, 2)
        img = img * (1 - bc) + level * bc
        blobs.append((kind, c, axes))

    clamp_s = 0.0
    if clamp > 0:  # a grey clamp over the base, from the left border across the arm
        clamp_s = clamp * s[-1]
        i = np.searchsorted(s, clamp_s)
        reach = (centre[i] - base) @ d + 0.2 * r0
        half = 1.6 * r0
        quad = np.array(
            [
                base - 40 * d + half * n,
                base + reach * d + half * n,
                base + reach * d - half * n,
                base - 40 * d - half * n,
            ]
        )
        cc = _coverage(quad, shape, supersample)
        img = img * (1 - cc) + (0.3 if background == "dark" else 0.7) * cc

    # Illumination: a broad light spot and a gradient, multiplying floor, arm and blobs alike.
    rr, ccol = np.mgrid[0:h, 0:w]
    spot = np.exp(-(((ccol - 0.7 * w) ** 2 + (rr - 0.3 * h) ** 2) / (2 * (0.45 * w) ** 2)))
    light = 0.72 + 0.28 * spot + 0.12 * (ccol / w - 0.5)
    img = img * light
    img = ndimage.gaussian_filter(img, blur)
    if rgb:
        tint = np.array([1.0, 0.8, 0.55]) if background == "dark" else np.array([0.9, 0.95, 1.0])
        img = img[..., None] * tint
    img = img + rng.normal(scale=noise, size=img.shape)
    image = np.clip(np.round(img * 255), 0, 255).astype(np.uint8)
    return Photo(
        image=image,
        centre=centre,
        s=s,
        radius=r_px,
        x=x,
        y=y,
        base=base,
        direction=d,
        scale=scale,
        length=float(s[-1]),
        clamp_s=clamp_s,
        blobs=blobs,
    )


def render_published_arm(
    tension: float,
    size: str = "0.3MP",
    *,
    shape: tuple[int, int] | None = None,
    scale: float | None = None,
    radius=None,
    **kwargs,
) -> Photo:
    """A photo of the planar cable-arm paper's arm (``PlanarCableArm.published_arm()``) at a cable
    tension (N): ``size`` picks the image shape and scale (or give ``shape`` and ``scale``),
    ``radius(s)`` (m) replaces the arm's taper, and the other keywords go to
    :func:`render_backbone`."""
    shape0, scale0 = SIZES[size]
    sol = ARM.solve(tension, 4001)
    r = ARM.radius(sol.s) if radius is None else radius(sol.s)
    return render_backbone(
        sol.x, sol.y, sol.angle, r, sol.s, shape=shape or shape0, scale=scale or scale0, **kwargs
    )


def thin_radius(s, scale: float):
    """A thin arm's radius (m) at arc length ``s``: 2.5 px at the base to 1.5 px at the tip."""
    return (2.5 - np.asarray(s) / ARM.length) * scale


def point_to_polyline(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Distance from each point (m, 2) to a polyline (n, 2), exactly (segment projections)."""
    a, b = line[:-1], line[1:]
    ab = b - a
    out = np.empty(len(points))
    for i0 in range(0, len(points), 512):
        p = points[i0 : i0 + 512, None, :]
        t = np.clip(np.einsum("mnk,nk->mn", p - a, ab) / np.einsum("nk,nk->n", ab, ab), 0, 1)
        q = a + t[..., None] * ab
        out[i0 : i0 + 512] = np.sqrt(((p - q) ** 2).sum(-1)).min(axis=1)
    return out


def centreline_errors(photo: Photo, pixels: np.ndarray, keep=(0.025, 0.975)) -> dict:
    """RMS and max distance (px) from the true backbone, over the arm fraction ``keep``, to an
    extracted polyline (col, row); the other way round too; and the tip distance."""
    u = photo.s / photo.length
    sel = (u >= keep[0]) & (u <= keep[1])
    d_true = point_to_polyline(photo.centre[sel], pixels)
    # Extracted points whose nearest true point lies in the kept fraction, to the true curve.
    _, j = cKDTree(photo.centre).query(pixels)
    ext = pixels[(u[j] >= keep[0]) & (u[j] <= keep[1])]
    d_ext = point_to_polyline(ext, photo.centre)
    d = np.concatenate([d_true, d_ext])
    return {
        "rms": float(np.sqrt(np.mean(d_true**2))),
        "max": float(d.max()),
        "tip": float(np.hypot(*(pixels[-1] - photo.tip))),
    }
