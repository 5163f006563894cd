"""Planar figures: the tapered cable-driven arm (backbones, outline, profiles)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .._core import PlanarCableArm, PlanarSolution
from ._figure import figure_style, new_figure

__all__ = ["plot_planar", "plot_planar_rod"]


def _section_outline(arm: PlanarCableArm, sol: PlanarSolution) -> tuple[np.ndarray, np.ndarray]:
    """Outline of the deformed cone: backbone offset by +-R(s) along the normal (m)."""
    r = arm.radius(sol.s)
    nx, ny = -np.sin(sol.angle), np.cos(sol.angle)
    upper = np.column_stack((sol.x + r * nx, sol.y + r * ny))
    lower = np.column_stack((sol.x - r * nx, sol.y - r * ny))
    return upper, lower


def plot_planar(
    arm: PlanarCableArm,
    solutions: Sequence[PlanarSolution],
    *,
    title: str | None = None,
    profiles: bool = True,
    size: tuple[float, float] | None = None,
    dpi: float | None = None,
    style=None,
):
    """Backbones of the planar cable arm for several tensions, with the arm's outline.

    Args:
        arm: The arm that was solved.
        solutions: Solutions to draw, e.g. one per tension.
        title: Figure title (default: describes the arm).
        profiles: Also draw curvature k(s) and axial strain q(s) panels.
        size: Figure size (width, height) in inches.
        dpi: Resolution (dots per inch).
        style: A matplotlib style name or file.

    Returns:
        The matplotlib figure (axes in millimetres; x along the unloaded arm, y toward the
        cable).
    """
    with figure_style(style):
        return _planar_figure(arm, solutions, title, profiles, size, dpi)


def _planar_figure(arm, solutions, title, profiles, size, dpi):
    import matplotlib.pyplot as plt

    if profiles:
        fig = new_figure(size, (11, 5.2), dpi)
        grid = fig.add_gridspec(2, 2, width_ratios=(1.35, 1))
        ax = fig.add_subplot(grid[:, 0])
        ax_k = fig.add_subplot(grid[0, 1])
        ax_q = fig.add_subplot(grid[1, 1], sharex=ax_k)
    else:
        fig = new_figure(size, (6.5, 5.2), dpi)
        ax = fig.add_subplot()
    cmap = plt.get_cmap("viridis")
    n = max(len(solutions), 1)
    for i, sol in enumerate(solutions):
        color = cmap(0.05 + 0.85 * i / max(n - 1, 1))
        upper, lower = _section_outline(arm, sol)
        poly = np.vstack((upper, lower[::-1]))
        ax.fill(poly[:, 0] * 1e3, poly[:, 1] * 1e3, color=color, alpha=0.12, lw=0)
        ax.plot(sol.x * 1e3, sol.y * 1e3, color=color, lw=2, label=f"T = {sol.tension:g} N")
        ax.plot(sol.tip[0] * 1e3, sol.tip[1] * 1e3, "o", color=color, ms=4)
        if profiles:
            ax_k.plot(sol.s * 1e3, sol.curvature, color=color)
            ax_q.plot(sol.s * 1e3, sol.strain * 100, color=color)
    ax.plot([0, 0], [-arm.base_radius * 1e3, arm.base_radius * 1e3], "k-", lw=4)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (mm), along the unloaded arm")
    ax.set_ylabel("y (mm), toward the cable")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    if profiles:
        ax_k.set_ylabel("curvature k (1/m)")
        ax_k.grid(alpha=0.3)
        ax_q.set_ylabel("axial strain q (%)")
        ax_q.set_xlabel("arc length s (mm)")
        ax_q.grid(alpha=0.3)
    fig.suptitle(
        title
        or (
            f"Tapered cable-driven arm: L = {arm.length * 1e3:g} mm, "
            f"R = {arm.base_radius * 1e3:g} -> {arm.tip_radius * 1e3:g} mm, "
            f"a = {arm.offset_ratio:.3g}, E = {arm.youngs_modulus / 1e3:g} kPa"
        )
    )
    return fig


def _plane_basis(sols) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Origin, in-plane axis along the base tangent and lateral axis of the bending plane."""
    from .views import _lateral

    p0 = np.asarray(sols[0].position)[0]
    e1 = np.asarray(sols[0].rotation)[0][:, 2]
    lat = max((_lateral(s) for s in sols), key=np.linalg.norm)
    if np.linalg.norm(lat) < 1e-12:
        r0 = np.asarray(sols[0].rotation)[0]
        lat = r0[:, 0]
    e2 = lat - np.dot(lat, e1) * e1
    return p0, e1, e2 / np.linalg.norm(e2)


def plot_planar_rod(
    solutions,
    *,
    robot=None,
    geometry=None,
    radius=None,
    labels: Sequence[str] | None = None,
    disks: Sequence[float] | None = None,
    obstacles: Sequence | None = None,
    title: str | None = None,
    ax=None,
    size: tuple[float, float] | None = None,
    dpi: float | None = None,
    style=None,
):
    """2-D figure of a robot that bends in a plane: the outline of its real radius, tendons,
    disks and chambers, drawn in the bending plane (base tangent across, bend upward).

    Args:
        solutions: A :class:`softrod.StaticsSolution` or a sequence of them.
        robot: The :class:`softrod.Robot` that was solved (radius, tendons, chambers).
        geometry: A :class:`softrod.plot.RobotGeometry` (instead of ``robot``).
        radius: Drawn outer radius (m), a number or a function of ``s`` (m).
        labels: One legend label per solution.
        disks: Arc lengths (m) of spacer disks (default: the tendon terminations).
        obstacles: Spheres and planes (m, world) drawn as their sections by the plane.
        title: Figure title (default: the robot's name and the tip in the plane, mm).
        ax: A 2-D matplotlib axes to draw into (default: a new figure).
        size: Figure size (width, height) in inches.
        dpi: Resolution (dots per inch).
        style: A matplotlib style name or file.

    Returns:
        The matplotlib figure; axes in millimetres: horizontal along the base tangent,
        vertical along the tip's lateral displacement (both in the bending plane).
    """
    from ._figure import as_list, figure_style, fmt_vector, new_figure
    from .geometry import RobotGeometry, _as_radius_fn, robot_geometry
    from .obstacles import Plane, Sphere, as_obstacles
    from .tube import disk_polygon, tendon_path

    sols = as_list(solutions)
    if geometry is None and robot is not None:
        geometry = robot_geometry(robot, radius=radius, disks=disks)
    elif geometry is None and radius is not None:
        geometry = RobotGeometry(length=float(sols[0].s[-1]), radius=_as_radius_fn(radius))
    p0, e1, e2 = _plane_basis(sols)
    mm = 1e3

    def to2d(pts):
        rel = np.asarray(pts) - p0
        return np.column_stack((rel @ e1, rel @ e2)) * mm

    with figure_style(style):
        import matplotlib.pyplot as plt

        if ax is None:
            fig = new_figure(size, (7.5, 5.5), dpi)
            ax = fig.add_subplot()
        else:
            fig = ax.figure
        cmap = plt.get_cmap("viridis")
        for i, sol in enumerate(sols):
            color = "#c9a27e" if len(sols) == 1 else cmap(0.1 + 0.8 * i / (len(sols) - 1))
            c = to2d(sol.position)
            if geometry is not None and geometry.radius is not None:
                s = np.asarray(sol.s)
                r = geometry.radius(s) * mm
                tang = np.gradient(c, axis=0)
                tang /= np.linalg.norm(tang, axis=1, keepdims=True)
                nrm = np.column_stack((-tang[:, 1], tang[:, 0]))
                poly = np.vstack((c + r[:, None] * nrm, (c - r[:, None] * nrm)[::-1]))
                (patch,) = ax.fill(
                    poly[:, 0],
                    poly[:, 1],
                    color=color,
                    alpha=0.55,
                    lw=0.8,
                    ec="0.3",
                    label=labels[i] if labels else None,
                )
                patch.set_gid("outline")
            ax.plot(c[:, 0], c[:, 1], color="0.15", lw=1.0, gid="backbone")
            if geometry is not None:
                for k, t in enumerate(geometry.tendons):
                    q = to2d(tendon_path(sol, t))
                    slack = t.tension <= 0
                    ax.plot(
                        q[:, 0],
                        q[:, 1],
                        color="0.55" if slack else "tab:red",
                        ls="--" if slack else "-",
                        lw=1.6,
                        label=t.label if i == 0 else None,
                        gid=f"tendon-{k}",
                    )
                for k, s_d in enumerate(geometry.disks):
                    rim = to2d(disk_polygon(sol, s_d, geometry.disk_radius))
                    ax.plot(rim[:, 0], rim[:, 1], color="0.35", lw=2.5, gid=f"disk-{k}")
                for k, ch in enumerate(geometry.chambers):
                    from .tube import chamber_grid

                    g = chamber_grid(sol, ch, n_around=8)
                    mid = to2d(g.mean(axis=1))
                    ax.plot(
                        mid[:, 0],
                        mid[:, 1],
                        color="tab:orange",
                        lw=3,
                        alpha=0.8,
                        gid=f"chamber-{k}",
                        label=ch.label if i == 0 else None,
                    )
            ax.plot(*c[-1], "o", color="k", ms=3)
        for ob in as_obstacles(obstacles):
            if isinstance(ob, Sphere):
                cc = to2d(np.asarray(ob.center)[None])[0]
                off = float(np.dot(np.asarray(ob.center) - p0, np.cross(e1, e2)))
                if abs(off) < ob.radius:
                    rr = np.sqrt(ob.radius**2 - off**2) * mm
                    ax.add_patch(plt.Circle(cc, rr, color="tab:cyan", alpha=0.45, gid="obstacle"))
            elif isinstance(ob, Plane):
                n2 = to2d(np.asarray(ob.normal)[None] + p0)[0]
                q = to2d(np.asarray(ob.point)[None])[0]
                d = np.array([-n2[1], n2[0]])
                d /= np.linalg.norm(d)
                span = 2e3 * float(sols[0].s[-1])
                ax.plot(
                    *np.column_stack((q - span * d, q + span * d)),
                    color="0.4",
                    lw=2,
                    gid="obstacle",
                )
        ax.set_aspect("equal", adjustable="datalim")
        ax.autoscale_view()
        ax.set_xlabel("along the base tangent (mm)")
        ax.set_ylabel("lateral, toward the bend (mm)")
        ax.grid(alpha=0.3)
        handles, _ = ax.get_legend_handles_labels()
        if handles:
            ax.legend(loc="best", fontsize="small")
        if title is None:
            tip = to2d(np.asarray(sols[-1].tip_position)[None])[0]
            name = getattr(robot, "name", "rod")
            title = f"{name}: tip at {fmt_vector(tip, unit='mm')} in the bending plane"
        ax.set_title(title)
    return fig
