"""Reading a photograph and segmenting the arm from its background.

The lighting of a tank is never even, so a global threshold on the raw image fails. The
background is estimated instead: the image is reduced to about 200 px, smoothed by normalised
convolution over the pixels currently classified as background (the arm and a margin around it
are left out and filled from their surroundings), subtracted, and the difference thresholded
with Otsu's method; two rounds converge. The arm's polarity (lighter or darker than the
background) is the class that holds the minority of the image border, which is background
except where the arm enters. Connected components are labelled; the arm is the largest one, or
the one at (or nearest to) the given base point; holes in it are filled.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import ndimage
from skimage.filters import threshold_otsu

from .backbone import parameter_error

#: Side (px) of the reduced image on which the background is estimated.
BACKGROUND_SIZE = 200
#: Smoothing of the background estimate, as a fraction of the reduced image's larger side.
BACKGROUND_SIGMA = 1 / 8
#: Components smaller than this fraction of the image (or 20 px) are noise, not distractors.
MIN_AREA_FRACTION = 2e-5
#: Smallest accepted image side (px).
MIN_SIDE = 8

_LUMA = np.array([0.2125, 0.7154, 0.0721])  # ITU-R BT.709, as skimage.color.rgb2gray


def read_image(image: str | os.PathLike[str] | ArrayLike) -> np.ndarray:
    """The photograph as an array: read from a path, or validated if already an array.

    Returns:
        Shape (rows, cols) or (rows, cols, 3 or 4), the file's dtype.

    Raises:
        ParameterError: Missing or unreadable file, or an array that is not an image.
    """
    if isinstance(image, (str, os.PathLike)):
        path = os.fspath(image)
        if not os.path.isfile(path):
            raise parameter_error("image", f"{path!r} is not a file")
        import warnings

        from skimage import io

        try:
            with warnings.catch_warnings():  # imageio's plugin probing on odd files
                warnings.simplefilter("ignore")
                arr = np.asarray(io.imread(path))
        except Exception as exc:  # imageio raises many types for non-image content
            reason = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
            raise parameter_error(
                "image", f"{path!r} is not a readable image ({type(exc).__name__}: {reason})"
            ) from None
    else:
        try:
            arr = np.asarray(image)
        except Exception as exc:
            raise parameter_error("image", f"not an array ({exc})") from None
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[:, :, 0]
    if not (arr.ndim == 2 or (arr.ndim == 3 and arr.shape[2] in (3, 4))):
        raise parameter_error(
            "image",
            f"shape {arr.shape}: must be (rows, cols) grey or (rows, cols, 3 or 4) RGB(A)",
        )
    if min(arr.shape[:2]) < MIN_SIDE:
        raise parameter_error("image", f"shape {arr.shape}: both sides must be >= {MIN_SIDE} px")
    if not (arr.dtype == bool or np.issubdtype(arr.dtype, np.number)):
        raise parameter_error("image", f"dtype {arr.dtype}: must be numeric")
    if np.issubdtype(arr.dtype, np.complexfloating):
        raise parameter_error("image", f"dtype {arr.dtype}: must be real")
    return arr


def to_grey(arr: np.ndarray) -> np.ndarray:
    """Luminance as float64: integer images scaled to [0, 1], float images kept as they are.

    Raises:
        ParameterError: Non-finite values.
    """
    if np.issubdtype(arr.dtype, np.integer):
        info = np.iinfo(arr.dtype)
        g = arr.astype(np.float64) / float(info.max)
    else:
        g = arr.astype(np.float64)
    if g.ndim == 3:
        g = g[:, :, :3] @ _LUMA
    if not np.all(np.isfinite(g)):
        raise parameter_error("image", "has non-finite values (NaN or inf)")
    return g


@dataclass
class Segmentation:
    """The arm's mask and the signal its edges are measured on.

    ``signal`` is the background-flattened image with the arm's polarity made positive:
    about 0 on the background and ``contrast`` on the arm.
    """

    mask: np.ndarray  # bool (rows, cols): the arm's component, holes filled
    signal: np.ndarray  # float (rows, cols)
    threshold: float
    polarity: str
    contrast: float
    noise: float
    discarded_components: int
    discarded_area: int
    warnings: list[str]


def _reduce(g: np.ndarray, k: int) -> np.ndarray:
    h, w = (g.shape[0] // k) * k, (g.shape[1] // k) * k
    return g[:h, :w].reshape(h // k, k, w // k, k).mean(axis=(1, 3))


def _expand(small: np.ndarray, k: int, shape: tuple[int, int]) -> np.ndarray:
    """Bilinear upsampling of a block-reduced image back to ``shape`` (pixel centres aligned)."""
    rows = (np.arange(shape[0]) + 0.5) / k - 0.5
    cols = (np.arange(shape[1]) + 0.5) / k - 0.5

    def weights(x: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x = np.clip(x, 0, n - 1)
        i0 = np.minimum(np.floor(x).astype(int), max(n - 2, 0))
        return i0, np.minimum(i0 + 1, n - 1), x - i0

    r0, r1, fr = weights(rows, small.shape[0])
    c0, c1, fc = weights(cols, small.shape[1])
    top = small[r0][:, c0] * (1 - fc) + small[r0][:, c1] * fc
    bot = small[r1][:, c0] * (1 - fc) + small[r1][:, c1] * fc
    return top * (1 - fr[:, None]) + bot * fr[:, None]


def _normalised_blur(img: np.ndarray, weight: np.ndarray, sigma: float) -> np.ndarray:
    num = ndimage.gaussian_filter(img * weight, sigma, mode="nearest")
    den = ndimage.gaussian_filter(weight.astype(np.float64), sigma, mode="nearest")
    fallback = np.median(img[weight > 0]) if np.any(weight > 0) else np.median(img)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = num / den
    return np.where(den > 1e-6, out, fallback)


def _border(a: np.ndarray) -> np.ndarray:
    return np.concatenate([a[0], a[-1], a[1:-1, 0], a[1:-1, -1]])


def _otsu(values: np.ndarray) -> float:
    if values.size == 0 or np.ptp(values) <= 0:
        return float("nan")
    return float(threshold_otsu(values))


def segment(
    grey: np.ndarray,
    *,
    polarity: str | None = None,
    base: np.ndarray | None = None,
    min_area: int | None = None,
) -> Segmentation:
    """Segments the arm (see the module docstring for the method).

    Args:
        grey: Luminance, shape (rows, cols).
        polarity: ``"bright"`` or ``"dark"`` arm; default detected.
        base: Base point (col, row): selects the component at or nearest to it.
        min_area: Smallest component (px) counted as a distractor.

    Raises:
        ParameterError: A constant image or no arm found.
    """
    shape = grey.shape
    warnings: list[str] = []
    k = max(1, int(np.ceil(max(shape) / BACKGROUND_SIZE)))
    small = _reduce(grey, k)
    sigma = BACKGROUND_SIGMA * max(small.shape)
    if np.ptp(small) <= 0 or np.ptp(grey) <= 0:
        raise parameter_error("image", "is constant: no arm to find")

    # Polarity: after removing a coarse background, the border is mostly background.
    coarse = small - ndimage.gaussian_filter(small, sigma, mode="nearest")
    t0 = _otsu(coarse.ravel())
    if polarity is None:
        above = np.mean(_border(coarse) > t0)
        polarity = "bright" if above < 0.5 else "dark"
    sign = 1.0 if polarity == "bright" else -1.0
    fg = sign * coarse > sign * t0
    thr = sign * t0
    for _ in range(3):  # background from the pixels away from the current foreground
        keep = ~ndimage.binary_dilation(fg, iterations=2)
        if keep.sum() < 0.05 * keep.size:
            raise parameter_error("image", "has no background: the arm fills the frame")
        bg = _normalised_blur(small, keep.astype(np.float64), sigma)
        flat = sign * (small - bg)
        thr = _otsu(flat.ravel())
        if not np.isfinite(thr):
            raise parameter_error("image", "is constant after flattening: no arm to find")
        fg = flat > thr
    noise = 1.4826 * float(np.median(np.abs(flat[keep] - np.median(flat[keep]))))
    contrast = float(np.median(flat[fg])) - float(np.median(flat[keep])) if fg.any() else 0.0
    if not fg.any() or contrast <= 6 * noise:
        raise parameter_error(
            "image",
            f"shows no arm: contrast {contrast:.3g} is within 6 x the background noise "
            f"{noise:.3g} (all background?)",
        )
    signal = sign * (grey - _expand(bg, k, shape))
    mask = signal > thr

    labels, _ = ndimage.label(mask, structure=np.ones((3, 3), bool))
    areas = np.bincount(labels.ravel())
    areas[0] = 0
    if min_area is None:
        min_area = max(20, int(MIN_AREA_FRACTION * grey.size))
    if areas.max() < min_area:
        raise parameter_error(
            "image", f"shows no arm: largest component {areas.max()} px < min_area {min_area}"
        )
    chosen = int(np.argmax(areas))
    if base is not None:
        chosen = _component_near(labels, areas, base, chosen)
    others = (areas >= min_area) & (np.arange(len(areas)) != chosen)
    slc = ndimage.find_objects((labels == chosen).astype(np.int8))[0]
    arm = np.zeros(shape, dtype=bool)
    arm[slc] = ndimage.binary_fill_holes(labels[slc] == chosen)
    big = areas[others].max() if others.any() else 0
    if big > 0.3 * areas[chosen]:
        warnings.append(
            f"another component of {big} px is {big / areas[chosen]:.0%} of the arm's area: "
            "check that the right object was taken"
        )
    return Segmentation(
        mask=arm,
        signal=signal,
        threshold=float(thr),
        polarity=polarity,
        contrast=contrast,
        noise=noise,
        discarded_components=int(others.sum()),
        discarded_area=int(areas[others].sum()),
        warnings=warnings,
    )


def _component_near(labels: np.ndarray, areas: np.ndarray, base: np.ndarray, largest: int) -> int:
    """The component at ``base`` (col, row), else the nearest one of at least 5 % of the
    largest's area."""
    c, r = round(float(base[0])), round(float(base[1]))
    if 0 <= r < labels.shape[0] and 0 <= c < labels.shape[1] and labels[r, c] > 0:
        if areas[labels[r, c]] >= 0.05 * areas[largest]:
            return int(labels[r, c])
    best, best_d = largest, np.inf
    objects = ndimage.find_objects(labels)
    for lab in np.nonzero(areas >= 0.05 * areas[largest])[0]:
        slc = objects[lab - 1]
        rr, cc = np.nonzero(labels[slc] == lab)
        d = np.min(np.hypot(cc + slc[1].start - base[0], rr + slc[0].start - base[1]))
        if d < best_d:
            best, best_d = int(lab), d
    return best


def mask_segmentation(mask: ArrayLike, shape: tuple[int, int]) -> Segmentation:
    """A segmentation from a caller's mask: the largest component, edges on the mask itself.

    Raises:
        ParameterError: Wrong shape, non-boolean values or an empty mask.
    """
    m = np.asarray(mask)
    if m.shape != shape:
        raise parameter_error("mask", f"shape {m.shape}: must be the image's {shape}")
    if m.dtype != bool:
        if not (np.issubdtype(m.dtype, np.number) and np.all(np.isin(m, (0, 1)))):
            raise parameter_error("mask", f"dtype {m.dtype}: must be boolean (or 0/1)")
        m = m.astype(bool)
    labels, n = ndimage.label(m, structure=np.ones((3, 3), bool))
    if n == 0:
        raise parameter_error("mask", "is empty")
    areas = np.bincount(labels.ravel())
    areas[0] = 0
    chosen = int(np.argmax(areas))
    arm = ndimage.binary_fill_holes(labels == chosen)
    signal = ndimage.gaussian_filter(arm.astype(np.float64), 0.7)
    return Segmentation(
        mask=arm,
        signal=signal,
        threshold=0.5,
        polarity="mask",
        contrast=1.0,
        noise=0.0,
        discarded_components=int(np.sum(areas >= 20) - 1),
        discarded_area=int(areas.sum() - areas[chosen]),
        warnings=[],
    )
