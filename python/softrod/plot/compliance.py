"""Compliance figures: smooth ellipsoids at chosen arc lengths with a legend and a scale bar in
physical units, and the dimensionless flexural compliance gamma_c(s)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .._core import ParameterError
from ._figure import figure_style, fmt_quantity, new_figure, nice_number, set_equal_3d

__all__ = ["plot_compliance_ellipsoids", "plot_gamma_c"]

_UNITS = {"translational": "m/N", "rotational": "rad/(N m)"}


def _ellipsoid_mesh(center, axes, directions, n: int = 48):
    """Surface of the ellipsoid with semi-axes ``axes`` along the rows of ``directions``;
    ``n`` points around (smooth at 48), ``n / 2 + 1`` from pole to pole."""
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, n + 1), np.linspace(0, np.pi, n // 2 + 1))
    sphere = np.stack((np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)), axis=-1)
    pts = (sphere * axes) @ directions
    return [center[k] + pts[..., k] for k in range(3)]


def _nodes(comp_s: np.ndarray, s, nodes: int) -> np.ndarray:
    """Indices of the compliance samples nearest to the arc lengths ``s`` (m)."""
    if s is None:
        return np.unique(np.linspace(1, len(comp_s) - 1, nodes).round().astype(int))
    s = np.atleast_1d(np.asarray(s, dtype=float))
    lo, hi = float(comp_s[0]), float(comp_s[-1])
    if np.any(~np.isfinite(s)) or np.any(s < lo - 1e-12) or np.any(s > hi + 1e-12):
        err = ParameterError(
            f"invalid parameter `s` = {s.tolist()!r}: arc lengths must be in [{lo:g}, {hi:g}] m"
        )
        err.parameter = "s"
        raise err
    return np.array([int(np.argmin(np.abs(comp_s - x))) for x in s])


def plot_compliance_ellipsoids(
    solution,
    compliance=None,
    *,
    nodes: int = 6,
    s: Sequence[float] | None = None,
    which: str = "translational",
    robot=None,
    view: str = "auto",
    title: str | None = None,
    ax=None,
    size: tuple[float, float] | None = None,
    dpi: float | None = None,
    style=None,
):
    """Compliance ellipsoids along the backbone (world frame), with a legend and a scale bar.

    At each selected node the ellipsoid's semi-axes are the principal compliances of the
    force-to-translation block (``which="translational"``, m/N) or of the moment-to-rotation
    block (``"rotational"``, rad/(N m)) of the integrated world compliance, along their
    eigenvectors, all drawn with one factor (mm on the figure per unit of compliance). The
    scale bar, drawn in the view plane so that it is seen at full length, shows what length on
    the figure is what compliance.

    Args:
        solution: A :class:`softrod.StaticsSolution`.
        compliance: Its :func:`softrod.compliance` (computed when omitted).
        nodes: Number of nodes (evenly spaced along the mesh, base excluded) when ``s`` is not
            given.
        s: Arc lengths (m) at which to draw ellipsoids (the nearest compliance nodes).
        which: ``"translational"`` or ``"rotational"``.
        robot: The :class:`softrod.Robot` that was solved, to draw its tube faintly.
        view: ``"auto"`` (normal to the bending plane) or ``"default"``.
        title: Figure title.
        ax: A 3-D matplotlib axes to draw into (default: a new figure).
        size: Figure size (width, height) in inches.
        dpi: Resolution (dots per inch).
        style: A matplotlib style name or file.

    Returns:
        The matplotlib figure (axes in millimetres). The 3-D axes carries
        ``ax.softrod_scale`` = (compliance of the bar, its length in mm, mm per unit), None
        when every chosen compliance is zero. A zero block (the clamped base, ``s = 0``) has
        no ellipsoid: it is drawn as a point, so noted in the legend.

    Raises:
        ParameterError: An arc length outside the rod, a bad ``which``, or a block that is
            neither zero nor positive.
    """
    from .._core import compliance as _compliance
    from .views import _draw_robot_3d, _light_dir, bending_view

    if which not in _UNITS:
        err = ParameterError(
            f"invalid parameter `which` = {which!r}: must be 'translational' or 'rotational'"
        )
        err.parameter = "which"
        raise err
    comp = compliance if compliance is not None else _compliance(solution)
    blk = slice(0, 3) if which == "translational" else slice(3, 6)
    unit = _UNITS[which]
    comp_s = np.asarray(comp.s)
    idx = _nodes(comp_s, s, nodes)
    world = np.asarray(comp.world)
    # A block exactly zero (the clamped base) has no ellipsoid: it is drawn as a point.
    zero = [not np.any(world[k][blk, blk]) for k in idx]
    eig = [np.linalg.eigh(0.5 * (world[k][blk, blk] + world[k][blk, blk].T)) for k in idx]
    drawn = [float(w.max()) for (w, _), z in zip(eig, zero, strict=True) if not z]
    if not all(np.isfinite(c) and c > 0 for c in drawn):
        raise ParameterError(
            "invalid parameter `compliance`: its blocks at the chosen arc lengths are not "
            "positive (nor zero)"
        )
    mm = 1e3
    p_sol = np.asarray(solution.position)
    p = np.column_stack([np.interp(comp_s, np.asarray(solution.s), p_sol[:, k]) for k in range(3)])
    p *= mm
    extent = max(float(np.ptp(p_sol * mm, axis=0).max()), 1e-9)
    mm_per_unit = 0.2 * extent / max(drawn) if drawn else None
    with figure_style(style):
        import matplotlib.pyplot as plt
        from matplotlib.colors import LightSource
        from matplotlib.patches import Patch

        if ax is None:
            fig = new_figure(size, (7.2, 7.0), dpi)
            ax = fig.add_subplot(projection="3d")
        else:
            fig = ax.figure
        chosen = bending_view(solution) if view == "auto" else None
        if chosen is not None:
            chosen.apply(ax)
        normal = chosen.normal if chosen is not None else np.array([0.43, -0.75, 0.5])
        light = LightSource(*_light_dir(normal))
        if robot is not None:
            from .geometry import robot_geometry

            _draw_robot_3d(
                ax,
                solution,
                robot_geometry(robot),
                color="0.75",
                light=_light_dir(normal),
                alpha=0.25,
                mm=mm,
                options={"tendons": False, "disks": False, "chambers": False, "label_tendons": 0},
            )
        else:
            ax.plot(p_sol[:, 0] * mm, p_sol[:, 1] * mm, p_sol[:, 2] * mm, color="0.2", lw=2.0)
        from matplotlib.lines import Line2D

        cmap = plt.get_cmap("viridis")
        pts = [p_sol * mm]
        handles = []
        ax.softrod_ellipsoids = []
        for j, (k, (w, v)) in enumerate(zip(idx, eig, strict=True)):
            color = cmap(0.1 + 0.8 * j / max(len(idx) - 1, 1))
            if zero[j] or mm_per_unit is None:
                (dot,) = ax.plot(*p[k][:, None], "o", color=color, ms=6, mec="k", mew=0.6)
                dot.set_gid(f"zero-compliance-{j}")
                pts.append(p[k][None, :])
                handles.append(
                    Line2D(
                        [],
                        [],
                        ls="",
                        marker="o",
                        color=color,
                        mec="k",
                        mew=0.6,
                        label=f"s = {comp_s[k] * mm:.0f} mm: zero compliance (a point)",
                    )
                )
                continue
            x, y, z = _ellipsoid_mesh(p[k], np.clip(w, 0, None) * mm_per_unit, v.T)
            surf = ax.plot_surface(
                x,
                y,
                z,
                color=color,
                alpha=0.55,
                shade=True,
                lightsource=light,
                linewidth=0,
                antialiased=True,
                rstride=1,
                cstride=1,
            )
            surf.set_gid(f"ellipsoid-{j}")
            ax.softrod_ellipsoids.append(surf)
            pts.append(np.column_stack((x.ravel(), y.ravel(), z.ravel())))
            handles.append(
                Patch(
                    color=color,
                    alpha=0.8,
                    label=f"s = {comp_s[k] * mm:.0f} mm: largest {fmt_quantity(w.max(), unit)}",
                )
            )
        limits = set_equal_3d(ax, np.vstack(pts))
        ax.softrod_view = chosen
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_zlabel("z (mm)")
        ax.legend(handles=handles, loc="upper left", fontsize="small", title="arc length")
        head = title or f"{which} compliance ellipsoids"
        if mm_per_unit is None:  # nothing to scale: every chosen compliance is zero
            ax.softrod_scale = None
            ax.set_title(f"{head}\nzero compliance at every chosen arc length", fontsize="medium")
            return fig
        # Scale bar along the screen's horizontal (in the view plane: seen at full length).
        azim = np.radians(ax.azim)
        elev = np.radians(ax.elev)
        right = np.array([-np.sin(azim), np.cos(azim), 0.0])
        n_view = np.array([np.cos(elev) * np.cos(azim), np.cos(elev) * np.sin(azim), np.sin(elev)])
        up = np.cross(n_view, right)
        half = 0.5 * float(np.ptp(limits, axis=1).max())
        bar_value = nice_number(0.35 * half / mm_per_unit)
        bar_mm = bar_value * mm_per_unit
        centre = limits.mean(axis=1)
        start = centre - 0.6 * half * right - 0.6 * half * up
        end = start + bar_mm * right
        (bar,) = ax.plot(*np.column_stack((start, end)), color="k", lw=3, solid_capstyle="butt")
        bar.set_gid("scale-bar")
        label = ax.text(
            *(0.5 * (start + end) + 0.06 * half * up),
            f"{fmt_quantity(bar_value, unit)}",
            ha="center",
            va="bottom",
            fontsize="small",
        )
        label.set_gid("scale-bar-label")
        ax.softrod_scale = (bar_value, bar_mm, mm_per_unit)
        ax.set_title(
            f"{head}\nsemi-axes: principal compliances; bar = {fmt_quantity(bar_value, unit)}"
            f" = {bar_mm:.3g} mm on the axes",
            fontsize="medium",
        )
    return fig


def plot_gamma_c(
    compliances,
    *,
    labels: Sequence[str] | None = None,
    title: str | None = None,
    size: tuple[float, float] | None = None,
    dpi: float | None = None,
    style=None,
):
    """Dimensionless flexural compliance ``gamma_c(s)`` along the arm, one panel per body axis.

    Args:
        compliances: A :class:`softrod.Compliance` or a sequence of them (e.g. one per
            actuation level).
        labels: One legend label per compliance.
        title: Figure title.
        size: Figure size (width, height) in inches.
        dpi: Resolution (dots per inch).
        style: A matplotlib style name or file.

    Returns:
        The matplotlib figure: ``gamma_c`` (dimensionless) against arc length ``s`` (mm).
    """
    comps = [compliances] if hasattr(compliances, "gamma_c") else list(compliances)
    with figure_style(style):
        import matplotlib.pyplot as plt

        fig = new_figure(size, (11, 3.6), dpi)
        axes = fig.subplots(1, 3, sharex=True)
        cmap = plt.get_cmap("viridis")
        for i, c in enumerate(comps):
            color = cmap(0.1 + 0.8 * i / max(len(comps) - 1, 1))
            for k, ax in enumerate(axes):
                ax.plot(
                    np.asarray(c.s) * 1e3,
                    np.asarray(c.gamma_c)[:, k],
                    color=color,
                    lw=1.8,
                    label=labels[i] if labels else None,
                )
        for k, ax in enumerate(axes):
            ax.set_title(f"body {'xyz'[k]}")
            ax.set_xlabel("s (mm)")
            ax.grid(alpha=0.3)
        axes[0].set_ylabel(r"$\gamma_c = C_{f}\,3EI(0)/L^3$")
        if labels:
            axes[0].legend(fontsize="small")
        if title:
            fig.suptitle(title)
    return fig
