"""Models side by side: the backbones of every applicable model overlaid."""

from __future__ import annotations

import numpy as np

from ._figure import figure_style, new_figure
from ._figure import set_equal_3d as _set_equal_3d

__all__ = ["plot_models"]


def plot_models(
    comparison,
    *,
    title: str | None = None,
    size: tuple[float, float] | None = None,
    dpi: float | None = None,
    style=None,
):
    """Backbones of every applicable model of a :func:`softrod.compare_models` result,
    overlaid in 3-D, with the inapplicable models named in the legend title.

    Args:
        comparison: A :class:`softrod.ModelComparison`.
        title: Figure title (default: the robot's name).
        size: Figure size (width, height) in inches.
        dpi: Resolution (dots per inch).
        style: A matplotlib style name or file.

    Returns:
        The matplotlib figure (axes in millimetres, world frame).
    """
    with figure_style(style):
        return _models_figure(comparison, title, size, dpi)


def _models_figure(comparison, title, size, dpi):
    fig = new_figure(size, (6.5, 6.5), dpi)
    ax = fig.add_subplot(projection="3d")
    styles = {"cosserat": ("black", "-", 2.6), "pcc": ("tab:orange", "--", 2.0)}
    allpts = []
    for r in comparison.results:
        if not r.applies:
            continue
        color, ls, lw = styles.get(r.model, ("tab:blue", ":", 2.2))
        p = r.positions * 1e3
        allpts.append(p)
        label = r.model
        if r.model != "cosserat":
            label += f" (tip {r.tip_error * 1e3:.2f} mm, {np.degrees(r.angle_error):.2f} deg)"
        ax.plot(p[:, 0], p[:, 1], p[:, 2], color=color, ls=ls, lw=lw, label=label)
        ax.scatter(*p[-1], color=color, s=18)
    _set_equal_3d(ax, np.vstack(allpts))
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    missing = [r.model for r in comparison.results if not r.applies]
    ax.legend(
        loc="upper left",
        fontsize="small",
        title=("not applicable: " + ", ".join(missing)) if missing else None,
        title_fontsize="small",
    )
    ax.set_title(title or comparison.robot)
    return fig
