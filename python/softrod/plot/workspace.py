"""Workspace maps: tip positions coloured by a stiffness measure, beside the actuation space.

A one-axis sweep is a curve (in the actuation space and in the workspace) coloured by the
measure; a full two-axis grid is an image over the actuation grid beside the tip surface;
anything else (three or more actuators, scattered samples) is binned into hexagons coloured by
the mean measure, so that thousands of overlapping tips are not overplotted.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .._core import ParameterError
from ._figure import figure_style, new_figure

__all__ = ["plot_workspace_map"]

_UNITS = {
    "max_translational_compliance": "m/N",
    "min_translational_compliance": "m/N",
    "tangent_max_translational_compliance": "m/N",
    "condition": "",
}
_KINDS = ("auto", "surface", "scatter")


def _measure(wmap, measure: str) -> tuple[np.ndarray, str]:
    if measure.startswith("eigen_stiffness_"):
        k = int(measure.rsplit("_", 1)[1])
        return np.asarray(wmap.eigen_stiffness)[:, k], "N/m or N m/rad"
    values = getattr(wmap, measure, None)
    if values is None:
        err = ParameterError(
            f"invalid parameter `measure` = {measure!r}: the map has no such field (e.g. "
            "max_translational_compliance, condition, eigen_stiffness_0)"
        )
        err.parameter = "measure"
        raise err
    return np.asarray(values, dtype=float), _UNITS.get(measure, "")


def _grid(a: np.ndarray, b: np.ndarray):
    """``(ua, ub, index)`` when the samples fill the grid ua x ub exactly once, else None."""
    ua, ia = np.unique(a, return_inverse=True)
    ub, ib = np.unique(b, return_inverse=True)
    if len(ua) * len(ub) != len(a) or len(ua) < 2 or len(ub) < 2:
        return None
    flat = ia * len(ub) + ib
    if len(np.unique(flat)) != len(a):
        return None
    return ua, ub, ia, ib


def _colored_line(ax, x, y, values, norm, cmap, lw=3.0):
    from matplotlib.collections import LineCollection

    pts = np.column_stack((x, y)).reshape(-1, 1, 2)
    segs = np.concatenate((pts[:-1], pts[1:]), axis=1)
    lc = LineCollection(segs, cmap=cmap, norm=norm, linewidths=lw)
    lc.set_array(0.5 * (values[:-1] + values[1:]))
    ax.add_collection(lc)
    ax.autoscale_view()
    return lc


def plot_workspace_map(
    wmap,
    *,
    measure: str = "max_translational_compliance",
    kind: str = "auto",
    actuation=None,
    actuation_labels: Sequence[str] | None = None,
    title: str | None = None,
    gridsize: int | None = None,
    size: tuple[float, float] | None = None,
    dpi: float | None = None,
    style=None,
):
    """Tip positions of a workspace map coloured by a stiffness measure, beside the actuation.

    Args:
        wmap: A :class:`softrod.WorkspaceMap` (or any object with ``tip_position`` (M, 3) m,
            ``converged`` (M,) and the measure).
        measure: ``"max_translational_compliance"`` (m/N, default),
            ``"min_translational_compliance"``, ``"tangent_max_translational_compliance"``
            (needs ``tangent=`` in :func:`softrod.workspace_map`), ``"condition"`` or
            ``"eigen_stiffness_k"`` (k-th eigenstiffness, k = 0..5).
        kind: ``"auto"``, ``"surface"`` (a full two-axis grid: the tip surface in 3-D) or
            ``"scatter"`` (hexagonal bins coloured by the mean measure).
        actuation: The actuation of every sample, shape (M, n) (default: ``wmap.tensions``);
            columns that do not vary are left out.
        actuation_labels: Axis label of each actuation column (default ``"T0 (N)"``, ...).
        title: Figure title (default: the number of configurations and failures).
        gridsize: Hexagons across a binned panel (default: from the number of samples).
        size: Figure size (width, height) in inches.
        dpi: Resolution (dots per inch).
        style: A matplotlib style name or file.

    Returns:
        The matplotlib figure: the actuation space on the left, the workspace (tips, mm) on
        the right, one colour bar for the measure.
    """
    if kind not in _KINDS:
        err = ParameterError(f"invalid parameter `kind` = {kind!r}: must be one of {_KINDS}")
        err.parameter = "kind"
        raise err
    values, unit = _measure(wmap, measure)
    ok = np.asarray(wmap.converged, dtype=bool) & np.isfinite(values)
    tips = np.asarray(wmap.tip_position) * 1e3
    act = actuation if actuation is not None else getattr(wmap, "tensions", None)
    cols: list[int] = []
    if act is not None:
        act = np.atleast_2d(np.asarray(act, dtype=float))
        if act.shape[0] != len(values):
            err = ParameterError(
                f"invalid parameter `actuation` with shape {act.shape}: must have one row per "
                f"sample ({len(values)})"
            )
            err.parameter = "actuation"
            raise err
        cols = [c for c in range(act.shape[1]) if np.ptp(act[:, c]) > 0]
        if actuation_labels is None:
            actuation_labels = [f"T{c} (N)" for c in range(act.shape[1])]
    grid = _grid(act[:, cols[0]], act[:, cols[1]]) if len(cols) == 2 else None
    if kind == "surface" and grid is None:
        err = ParameterError(
            "invalid parameter `kind` = 'surface': needs a full grid over exactly two actuators"
        )
        err.parameter = "kind"
        raise err
    mode = (
        "curve"
        if len(cols) == 1
        else "surface"
        if grid is not None and kind != "scatter"
        else "binned"
    )
    v = values[ok]
    label = measure.replace("_", " ") + (f" ({unit})" if unit else "")
    with figure_style(style):
        import matplotlib.pyplot as plt
        from matplotlib.colors import Normalize

        cmap = plt.get_cmap("viridis")
        norm = Normalize(float(np.min(v)), float(np.max(v))) if v.size else Normalize(0, 1)
        has_act = bool(cols)
        fig = new_figure(size, (13.5 if has_act else 11, 4.6), dpi)
        n_panels = 3 if has_act else 2
        if mode == "surface":
            n_panels = 2
            spec = fig.add_gridspec(1, 2, width_ratios=(1, 1.25))
        else:
            spec = fig.add_gridspec(1, n_panels)
        hexes = (
            int(np.clip(np.sqrt(max(int(ok.sum()), 1)) / 1.6, 8, 60))
            if gridsize is None
            else gridsize
        )
        panels = []
        mappable = None
        if has_act:
            ax_a = fig.add_subplot(spec[0])
            panels.append(ax_a)
            a = act[ok]
            if mode == "curve":
                c = cols[0]
                order = np.argsort(a[:, c])
                mappable = _colored_line(ax_a, a[order, c], v[order], v[order], norm, cmap)
                ax_a.set_ylabel(label)
                ax_a.set_title("actuation space")
            elif mode == "surface":
                ua, ub, ia, ib = grid
                img = np.full((len(ub), len(ua)), np.nan)
                img[ib, ia] = np.where(ok, values, np.nan)
                mappable = ax_a.pcolormesh(ua, ub, img, cmap=cmap, norm=norm, shading="nearest")
                ax_a.set_ylabel(actuation_labels[cols[1]])
                ax_a.set_title("actuation space")
            else:
                ua, ia = np.unique(a[:, cols[0]], return_inverse=True)
                ub, ib = np.unique(a[:, cols[1]], return_inverse=True)
                if len(ua) <= 200 and len(ub) <= 200:  # a grid: mean over the other actuators
                    total = np.zeros((len(ub), len(ua)))
                    count = np.zeros_like(total)
                    np.add.at(total, (ib, ia), v)
                    np.add.at(count, (ib, ia), 1.0)
                    img = np.where(count > 0, total / np.maximum(count, 1), np.nan)
                    mappable = ax_a.pcolormesh(ua, ub, img, cmap=cmap, norm=norm, shading="nearest")
                else:
                    mappable = ax_a.hexbin(
                        a[:, cols[0]],
                        a[:, cols[1]],
                        C=v,
                        gridsize=hexes,
                        cmap=cmap,
                        norm=norm,
                        reduce_C_function=np.mean,
                        mincnt=1,
                    )
                ax_a.set_ylabel(actuation_labels[cols[1]])
                others = [actuation_labels[c] for c in cols[2:]]
                ax_a.set_title(
                    "actuation space" + (f" (mean over {', '.join(others)})" if others else "")
                )
            mappable.set_gid("actuation")
            ax_a.set_xlabel(actuation_labels[cols[0]])
            ax_a.grid(alpha=0.3)
        if mode == "surface":
            ax3 = fig.add_subplot(spec[1], projection="3d")
            ua, ub, ia, ib = grid
            shape = (len(ua), len(ub))
            x = np.full(shape, np.nan)
            y, z, c = x.copy(), x.copy(), x.copy()
            x[ia, ib], y[ia, ib], z[ia, ib] = tips[:, 0], tips[:, 1], tips[:, 2]
            c[ia, ib] = np.where(ok, values, np.nan)
            colors = cmap(norm(np.nan_to_num(c, nan=float(norm.vmin))))
            surf = ax3.plot_surface(
                x, y, z, facecolors=colors, shade=False, linewidth=0.2, edgecolor=(0, 0, 0, 0.15)
            )
            surf.set_gid("workspace-surface")
            span = np.array([np.nanmax(q) - np.nanmin(q) for q in (x, y, z)])
            ax3.set_box_aspect(np.maximum(span, 0.25 * span.max()))  # true proportions
            ax3.set_xlabel("x (mm)")
            ax3.set_ylabel("y (mm)")
            ax3.set_zlabel("z (mm)")
            ax3.set_title("tip surface (workspace)")
            panels.append(ax3)
        else:
            p = tips[ok]
            views = ((0, 1, "top view"), (0, 2, "side view"))
            for n, (i, j, name) in enumerate(views):
                ax = fig.add_subplot(spec[n_panels - 2 + n])
                if mode == "curve":
                    order = np.argsort(act[ok][:, cols[0]])
                    m = _colored_line(ax, p[order, i], p[order, j], v[order], norm, cmap)
                else:
                    m = ax.hexbin(
                        p[:, i],
                        p[:, j],
                        C=v,
                        gridsize=hexes,
                        cmap=cmap,
                        norm=norm,
                        reduce_C_function=np.mean,
                        mincnt=1,
                    )
                m.set_gid(f"workspace-{name.split()[0]}")
                mappable = mappable or m
                ax.set_xlabel(f"{'xyz'[i]} (mm)")
                ax.set_ylabel(f"{'xyz'[j]} (mm)")
                ax.set_aspect("equal", adjustable="datalim")
                ax.set_title(name + ("" if mode == "curve" else " (hexagons: mean over tips)"))
                ax.grid(alpha=0.3)
                panels.append(ax)
        from matplotlib.cm import ScalarMappable

        cb = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=panels, label=label)
        cb.ax.set_gid("measure-colorbar")
        failed = int((~ok).sum())
        fig.suptitle(
            title or f"workspace map: {int(ok.sum())} configurations ({failed} not converged)"
        )
        fig.softrod_mode = mode
    return fig
