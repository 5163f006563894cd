"""The extracted backbone drawn over its photograph."""

from __future__ import annotations

import numpy as np

from .backbone import Backbone

__all__ = ["plot_backbone_overlay"]


def plot_backbone_overlay(
    backbone: Backbone,
    image,
    *,
    ax=None,
    title: str | None = None,
    size: tuple[float, float] | None = None,
    dpi: float | None = None,
    style=None,
):
    """Draws the photo with the centreline, the fitted edges (+- half-width), base and tip.

    Args:
        backbone: The extracted backbone.
        image: The photograph (array or path) the backbone came from.
        ax: Matplotlib axes to draw in; default a new figure.
        title: Axes title; default a one-line summary of the quality report.
        size: Figure size (width, height) in inches (new figure only).
        dpi: Resolution (dots per inch).
        style: A matplotlib style name or file.

    Returns:
        The matplotlib figure (axes in pixels: column across, row downward).
    """
    from ..plot._figure import figure_style

    with figure_style(style):
        return _overlay(backbone, image, ax, title, size, dpi)


def _overlay(backbone, image, ax, title, size, dpi):
    from ..plot._figure import new_figure
    from .segment import read_image

    arr = read_image(image)
    if ax is None:
        h, w = arr.shape[:2]
        fig = new_figure(size, (8.0, 8.0 * h / w + 0.5), dpi)
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    ax.imshow(arr, cmap="gray" if arr.ndim == 2 else None, interpolation="nearest")
    px, hw = backbone.pixels, backbone.half_width_px
    d = np.gradient(px, axis=0)
    t = d / np.maximum(np.hypot(*d.T), 1e-12)[:, None]
    n = np.column_stack([t[:, 1], -t[:, 0]])
    q = backbone.quality
    n_head = 0
    if q.base_extrapolated:
        n_head = int(
            np.searchsorted(backbone.arc_length / (backbone.scale or 1.0), q.extrapolated_length)
        )
    for sgn in (1, -1):
        e = px + sgn * hw[:, None] * n
        ax.plot(e[:, 0], e[:, 1], color="#00b4d8", lw=0.9, label="edges" if sgn > 0 else None)
    ax.plot(px[n_head:, 0], px[n_head:, 1], color="#ff006e", lw=1.4, label="centreline")
    if n_head:
        ax.plot(
            px[: n_head + 1, 0],
            px[: n_head + 1, 1],
            color="#ff006e",
            lw=1.4,
            ls="--",
            label="extrapolated",
        )
    ax.plot(*backbone.base, "o", ms=7, mfc="none", mec="#ffbe0b", mew=2, label="base")
    ax.plot(*px[-1], "s", ms=7, mfc="none", mec="#fb5607", mew=2, label="tip")
    ax.arrow(
        *backbone.base,
        *(backbone.direction * 0.12 * max(arr.shape[:2])),
        color="#ffbe0b",
        width=0.5,
        head_width=6,
        length_includes_head=True,
    )
    ax.legend(loc="upper right", fontsize=8, framealpha=0.8)
    ax.set_xlabel("column (px)")
    ax.set_ylabel("row (px)")
    if title is None:
        title = (
            f"length {backbone.length:.4g} {backbone.unit}, coverage {q.coverage:.1%}, "
            f"fit residual {q.fit_residual:.2f} px, {q.discarded_components} discarded"
            + (f", {len(q.warnings)} warning(s)" if q.warnings else "")
        )
    ax.set_title(title, fontsize=9)
    if q.warnings:
        ax.text(
            0.01,
            0.01,
            "\n".join(f"warning: {w}" for w in q.warnings),
            transform=ax.transAxes,
            fontsize=7,
            color="#7a0000",
            va="bottom",
            ha="left",
            bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none"},
        )
    return fig
