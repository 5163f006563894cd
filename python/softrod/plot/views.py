"""The 3-D robot figure: tube, tendons, disks, chambers, obstacles, in a view chosen from the
shape, with optional orthographic projections.

The view rule (:func:`bending_view`): the camera looks along the normal of the dominant bending
plane, the plane through the base that best fits the backbone points relative to the base
(principal components, SVD). If that plane shows less than ``min_fraction`` (90 %) of the tip's
lateral displacement ``d`` (the tip's offset from the base, less its component along the base
tangent), the normal of the plane spanned by the base tangent and ``d`` is used instead, which
shows all of it. A tilt about ``d`` adds depth without changing what is seen of ``d``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._core import ParameterError
from ._figure import (
    as_list,
    figure_style,
    fmt_vector,
    new_figure,
    set_equal_3d,
)
from .geometry import RobotGeometry, robot_geometry
from .obstacles import Mesh, Plane, as_obstacles, obstacle_surface
from .tube import (
    chamber_grid,
    disk_polygon,
    robot_extent_points,
    tendon_path,
    tube_grid,
)

__all__ = ["BendingView", "bending_view", "plot_robot", "plot_rod", "seen_fraction"]

#: Default share of the tip's lateral displacement a chosen view must show.
MIN_SEEN_FRACTION = 0.9
#: Default tilt of the chosen view about the lateral displacement (deg), for depth.
VIEW_TILT_DEG = 20.0
_STRAIGHT = 1e-6  # lateral displacement / rod extent below which the rod counts as straight

_TENDON_COLORS = ("tab:red", "tab:blue", "tab:green", "tab:purple", "tab:orange", "tab:brown")


@dataclass(frozen=True)
class BendingView:
    """A camera direction chosen from a shape.

    Attributes:
        normal: Unit vector from the scene toward the camera (world frame, shape (3,)).
        elev: Matplotlib elevation of ``normal`` (deg).
        azim: Matplotlib azimuth of ``normal`` (deg).
        lateral: The tip's true lateral displacement from the base axis (m), per solution.
        seen_fraction: Share of ``lateral`` seen in the view (orthographic projection), per
            solution.
        rule: ``"bending-plane"`` (principal components), ``"tip-plane"`` (base tangent and
            lateral displacement) or ``"straight"`` (nothing bends: a default view).
    """

    normal: np.ndarray
    elev: float
    azim: float
    lateral: tuple[float, ...]
    seen_fraction: tuple[float, ...]
    rule: str

    def apply(self, ax) -> None:
        """Sets this view (orthographic) on a 3-D matplotlib axes."""
        ax.set_proj_type("ortho")
        ax.view_init(elev=self.elev, azim=self.azim)


def _lateral(sol) -> np.ndarray:
    p = np.asarray(sol.position)
    t0 = np.asarray(sol.rotation)[0][:, 2]
    d = p[-1] - p[0]
    return d - np.dot(d, t0) * t0


def seen_fraction(d: np.ndarray, normal: np.ndarray) -> float:
    """Share of a displacement ``d`` (shape (3,)) seen looking along ``normal`` (unit), in
    [0, 1] (1 when ``d`` is zero)."""
    nd = float(np.linalg.norm(d))
    if nd == 0:
        return 1.0
    return float(np.linalg.norm(d - np.dot(d, normal) * normal) / nd)


def _unit(v: np.ndarray) -> np.ndarray | None:
    n = float(np.linalg.norm(v))
    return v / n if n > 0 else None


def _tilted(normal: np.ndarray, d: np.ndarray, tilt_deg: float) -> np.ndarray:
    """``normal`` rotated by ``tilt_deg`` about ``d`` toward +z (what is seen of ``d`` is kept)."""
    axis = _unit(d)
    if axis is None or tilt_deg == 0:
        return normal
    a = np.radians(tilt_deg)
    side = np.cross(axis, normal)
    cands = [
        normal * np.cos(a) + side * np.sin(a) + axis * np.dot(axis, normal) * (1 - np.cos(a)),
        normal * np.cos(a) - side * np.sin(a) + axis * np.dot(axis, normal) * (1 - np.cos(a)),
    ]
    return max(cands, key=lambda v: v[2])


def _off_axis(normal: np.ndarray, lat: list[np.ndarray], min_fraction: float) -> np.ndarray:
    """Turns a view that looks straight along a world axis plane by 15 deg about z (axis
    ticks otherwise pile up), if every tip displacement stays seen by ``min_fraction``."""
    azim = np.degrees(np.arctan2(normal[1], normal[0]))
    if abs((azim + 45.0) % 90.0 - 45.0) > 5.0 or abs(normal[2]) > 0.95:
        return normal
    for beta in (15.0, -15.0, 8.0, -8.0):
        b = np.radians(beta)
        rz = np.array([[np.cos(b), -np.sin(b), 0], [np.sin(b), np.cos(b), 0], [0, 0, 1]])
        cand = rz @ normal
        if min(seen_fraction(d, cand) for d in lat) >= min_fraction + 0.02:
            return cand
    return normal


def bending_view(
    solutions,
    *,
    min_fraction: float = MIN_SEEN_FRACTION,
    tilt: float = VIEW_TILT_DEG,
) -> BendingView:
    """Chooses a camera normal to the dominant bending plane of one or more solutions.

    Args:
        solutions: A statics solution (``position`` (n, 3) m, ``rotation`` (n, 3, 3)) or a
            sequence of them (one view for all).
        min_fraction: Share of each tip's lateral displacement the view must show, in (0, 1].
        tilt: Rotation of the camera about the lateral displacement toward +z (deg), for depth;
            it leaves the seen share unchanged.

    Returns:
        The view, with the seen share of every solution's tip displacement.
    """
    if not 0 < min_fraction <= 1:
        err = ParameterError(
            f"invalid parameter `min_fraction` = {min_fraction!r}: must be in (0, 1]"
        )
        err.parameter = "min_fraction"
        raise err
    sols = as_list(solutions)
    rel = np.vstack([np.asarray(s.position) - np.asarray(s.position)[0] for s in sols])
    extent = max(float(np.linalg.norm(rel, axis=1).max()), 1e-12)
    lat = [_lateral(s) for s in sols]
    biggest = max(lat, key=np.linalg.norm)
    if np.linalg.norm(biggest) <= _STRAIGHT * extent:
        normal = np.array([np.cos(np.radians(-60)), np.sin(np.radians(-60)), 0.0])
        normal = normal * np.cos(np.radians(20)) + np.array([0, 0, np.sin(np.radians(20))])
        rule = "straight"
    else:
        _, _, vt = np.linalg.svd(rel, full_matrices=False)
        candidates = [("bending-plane", vt[2])]
        for d, s in zip(lat, sols, strict=True):
            n = _unit(np.cross(np.asarray(s.rotation)[0][:, 2], d))
            if n is not None:
                candidates.append(("tip-plane", n))

        def worst(n):
            return min(seen_fraction(d, n) for d in lat)

        rule, normal = next(
            ((r, n) for r, n in candidates if worst(n) >= min_fraction),
            max(candidates, key=lambda c: worst(c[1])),
        )
        normal = _tilted(normal, biggest, tilt)
        if normal[2] < 0:  # look from above when the plane allows it
            normal = -normal
        normal = _off_axis(normal, lat, min_fraction)
    normal = normal / np.linalg.norm(normal)
    elev = float(np.degrees(np.arcsin(np.clip(normal[2], -1, 1))))
    azim = float(np.degrees(np.arctan2(normal[1], normal[0])))
    return BendingView(
        normal=normal,
        elev=elev,
        azim=azim,
        lateral=tuple(float(np.linalg.norm(d)) for d in lat),
        seen_fraction=tuple(seen_fraction(d, normal) for d in lat),
        rule=rule,
    )


def _light_dir(normal: np.ndarray) -> tuple[float, float]:
    from matplotlib.colors import LightSource  # noqa: F401  (checked import)

    az = float(np.degrees(np.arctan2(normal[1], normal[0]))) + 35.0
    alt = float(np.degrees(np.arcsin(np.clip(normal[2], -1, 1)))) + 30.0
    return az, min(alt, 85.0)


def _draw_robot_3d(ax, sol, geom: RobotGeometry | None, *, color, light, alpha, mm, options):
    """Draws one solution (tube, tendons, disks, chambers) on a 3-D axes; returns artists."""
    from matplotlib.colors import LightSource
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    drawn = {"tube": [], "tendons": [], "disks": [], "chambers": []}
    p = np.asarray(sol.position) * mm
    ls = LightSource(*light)
    if geom is not None and geom.radius is not None:
        r = geom.radius(np.asarray(sol.s))
        g = tube_grid(sol, r, n_around=32) * mm
        surf = ax.plot_surface(
            g[..., 0],
            g[..., 1],
            g[..., 2],
            color=color,
            alpha=alpha,
            shade=True,
            lightsource=ls,
            linewidth=0,
            antialiased=alpha < 1,  # smooth translucent tubes; no hairline gaps when opaque
            rstride=1,
            cstride=1,
        )
        surf.set_gid("tube")
        drawn["tube"].append(surf)
    bare = geom is None or geom.radius is None
    line = ax.plot(
        p[:, 0],
        p[:, 1],
        p[:, 2],
        color=color if bare else "0.15",
        lw=2.2 if bare else 1.0,
        label=options.get("label") if bare else None,
        zorder=5,
    )[0]
    line.set_gid("backbone")
    if geom is None:
        return drawn
    if options["tendons"]:
        for i, t in enumerate(geom.tendons):
            q = tendon_path(sol, t) * mm
            slack = t.tension <= 0
            c = "0.55" if slack else _TENDON_COLORS[i % len(_TENDON_COLORS)]
            (ln,) = ax.plot(
                q[:, 0],
                q[:, 1],
                q[:, 2],
                color=c,
                lw=1.0 if slack else 1.8,
                ls="--" if slack else "-",
                label=t.label if options["label_tendons"] else None,
                zorder=6,
            )
            ln.set_gid(f"tendon-{i}")
            drawn["tendons"].append(ln)
    if options["disks"] and geom.disk_radius > 0:
        for k, s in enumerate(geom.disks):
            rim = disk_polygon(sol, s, geom.disk_radius) * mm
            poly = Poly3DCollection(
                [rim], facecolor=(0.75, 0.75, 0.78, 0.45), edgecolor="0.35", linewidths=0.8
            )
            poly.set_gid(f"disk-{k}")
            ax.add_collection3d(poly)
            drawn["disks"].append(poly)
    if options["chambers"] and geom.chambers:
        import matplotlib.pyplot as plt

        cmap = plt.get_cmap("YlOrRd")
        pmax = max(max(c.pressure for c in geom.chambers), 1.0)
        for k, c in enumerate(geom.chambers):
            cg = chamber_grid(sol, c) * mm
            shade = 0.15 + 0.8 * max(c.pressure, 0.0) / pmax
            surf = ax.plot_surface(
                cg[..., 0],
                cg[..., 1],
                cg[..., 2],
                color=cmap(shade),
                alpha=0.9,
                shade=True,
                lightsource=ls,
                linewidth=0,
                antialiased=False,
            )
            surf.set_gid(f"chamber-{k}")
            drawn["chambers"].append(surf)
    return drawn


def _draw_obstacles(ax, obstacles, pts_mm: np.ndarray, mm: float, projected=None):
    out = []
    centre = pts_mm.mean(axis=0) / mm
    extent = float(np.ptp(pts_mm, axis=0).max()) / mm * 1.2
    for k, ob in enumerate(obstacles):
        x, y, z = obstacle_surface(ob, centre, extent)
        if projected is None and isinstance(ob, Mesh):
            surf = ax.plot_trisurf(
                x.ravel() * mm,
                y.ravel() * mm,
                z.ravel() * mm,
                triangles=ob.faces,
                color="tab:cyan",
                alpha=0.45,
                linewidth=0,
            )
            surf.set_gid(f"obstacle-{k}")
            out.append(surf)
        elif projected is None:
            surf = ax.plot_surface(
                x * mm,
                y * mm,
                z * mm,
                color="tab:gray" if isinstance(ob, Plane) else "tab:cyan",
                alpha=0.25 if isinstance(ob, Plane) else 0.45,
                linewidth=0,
                shade=not isinstance(ob, Plane),
            )
            surf.set_gid(f"obstacle-{k}")
            out.append(surf)
    return out


def _triad(ax, p, r, size, gid: str):
    lines = []
    for axis, c in zip(range(3), ("tab:red", "tab:green", "tab:blue"), strict=True):
        d = r[:, axis] * size
        (ln,) = ax.plot(*np.column_stack((p, p + d)), color=c, lw=1.4, zorder=7)
        ln.set_gid(gid)
        lines.append(ln)
    return lines


def _projection_panels(fig, grid_spec, sols, geoms, colors, mm, obstacles, limits=None):
    """Three orthographic projections (top x-y, front x-z, side y-z) as 2-D axes."""
    from matplotlib.collections import PolyCollection

    axes = []
    planes = (((0, 1), "top (x-y)"), ((0, 2), "front (x-z)"), ((1, 2), "side (y-z)"))
    for k, ((i, j), name) in enumerate(planes):
        ax = fig.add_subplot(grid_spec[k])
        for sol, geom, color in zip(sols, geoms, colors, strict=True):
            if geom is not None and geom.radius is not None:
                g = tube_grid(sol, geom.radius(np.asarray(sol.s)), n_around=24) * mm
                quads = np.stack((g[:-1, :-1], g[:-1, 1:], g[1:, 1:], g[1:, :-1]), axis=2).reshape(
                    -1, 4, 3
                )[..., [i, j]]
                pc = PolyCollection(quads, facecolor=color, edgecolor="none", alpha=1.0)
                pc.set_gid("tube")
                ax.add_collection(pc)
            p = np.asarray(sol.position) * mm
            ax.plot(p[:, i], p[:, j], color="0.15", lw=1.0)
            if geom is not None:
                for n_t, t in enumerate(geom.tendons):
                    q = tendon_path(sol, t) * mm
                    c = "0.55" if t.tension <= 0 else _TENDON_COLORS[n_t % len(_TENDON_COLORS)]
                    ax.plot(q[:, i], q[:, j], color=c, lw=1.0, ls="--" if t.tension <= 0 else "-")
        for ob in obstacles:
            if hasattr(ob, "center"):
                from matplotlib.patches import Circle

                c = np.asarray(ob.center) * mm
                ax.add_patch(Circle((c[i], c[j]), ob.radius * mm, color="tab:cyan", alpha=0.4))
        if limits is not None:
            ax.set_xlim(*limits[i])
            ax.set_ylim(*limits[j])
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel(f"{'xyz'[i]} (mm)")
        ax.set_ylabel(f"{'xyz'[j]} (mm)")
        ax.set_title(name, fontsize="small")
        ax.grid(alpha=0.3)
        axes.append(ax)
    return axes


def plot_rod(
    solutions,
    *,
    labels: Sequence[str] | None = None,
    frames: int | None = None,
    title: str | None = None,
    ax=None,
    robot=None,
    geometry: RobotGeometry | None = None,
    radius=None,
    tendons: bool = True,
    disks: Sequence[float] | None = None,
    chambers: bool = True,
    obstacles: Sequence | None = None,
    view: str | tuple[float, float] = "auto",
    projections: bool = False,
    alpha: float | None = None,
    size: tuple[float, float] | None = None,
    dpi: float | None = None,
    style=None,
):
    """3-D figure of one or more statics solutions: the backbone, or with ``robot`` (or
    ``radius``) the rod as a shaded tube of its real radius with its tendons, disks and
    chambers.

    Args:
        solutions: A :class:`softrod.StaticsSolution` or a sequence of them.
        labels: One legend label per solution.
        frames: Body-frame triads (x red, y green, z = tangent blue) drawn along each
            backbone; default 5 for a bare backbone, the tip frame only with a tube.
        title: Figure title (default: the robot's name and the tip position in mm).
        ax: A 3-D matplotlib axes to draw into (default: a new figure).
        robot: The :class:`softrod.Robot` that was solved: gives the section radius, the
            tendon routings and the chambers (see :func:`robot_geometry`).
        geometry: A precomputed :class:`RobotGeometry` (instead of ``robot``).
        radius: Drawn outer radius (m), a number or a function of arc length ``s`` (m).
        tendons: Draw the tendons along their routing ``p + R r(s)`` (tensioned solid and
            coloured, slack dashed grey).
        disks: Arc lengths (m) of spacer disks; default: at the tendon terminations.
        chambers: Draw the pneumatic chambers (colour: pressure).
        obstacles: Obstacles to draw (see :mod:`softrod.plot.obstacles`), m, world frame.
        view: ``"auto"`` (normal to the dominant bending plane, :func:`bending_view`),
            ``"default"`` (matplotlib's), or ``(elev, azim)`` in degrees.
        projections: Add the three orthographic projections (top, front, side) beside it.
        alpha: Tube opacity (default: 0.35 when tendons or chambers run inside it, else 0.9).
        size: Figure size (width, height) in inches.
        dpi: Figure resolution (dots per inch).
        style: A matplotlib style name or file used while drawing.

    Returns:
        The matplotlib figure (axes in millimetres, world frame). The chosen view is on the
        3-D axes as ``ax.softrod_view`` (a :class:`BendingView`).
    """
    sols = as_list(solutions)
    if not sols:
        raise ParameterError("invalid parameter `solutions`: at least one solution is needed")
    if ax is not None and projections:
        raise ParameterError(
            "invalid parameter `projections` = True: needs a new figure (do not pass `ax`)"
        )
    given = geometry
    if geometry is None and robot is not None:
        geometry = robot_geometry(robot, radius=radius, disks=disks)
    geoms: list[RobotGeometry | None] = []
    for sol in sols:
        if given is None and robot is not None:
            # Each solution's tendons and chambers drawn at its own tensions and pressures.
            actuated = _actuated(robot, sol)
            if actuated is not robot:
                geoms.append(robot_geometry(actuated, radius=radius, disks=disks))
                continue
        if geometry is None and radius is not None:
            from .geometry import _as_radius_fn

            geoms.append(RobotGeometry(length=float(sols[0].s[-1]), radius=_as_radius_fn(radius)))
        else:
            geoms.append(geometry)
    obs = as_obstacles(obstacles)
    mm = 1e3
    with figure_style(style):
        import matplotlib.pyplot as plt

        if ax is None:
            default = (11.5, 6.8) if projections else (7.0, 7.0)
            fig = new_figure(size, default, dpi)
            if projections:
                gs = fig.add_gridspec(3, 2, width_ratios=(1.7, 1))
                ax = fig.add_subplot(gs[:, 0], projection="3d")
            else:
                ax = fig.add_subplot(projection="3d")
        else:
            fig = ax.figure
        if view == "auto":
            chosen = bending_view(sols)
            chosen.apply(ax)
        elif view == "default":
            chosen = None
        else:
            try:
                elev, azim = (float(v) for v in view)
            except (TypeError, ValueError):
                raise ParameterError(
                    f"invalid parameter `view` = {view!r}: must be 'auto', 'default' or "
                    "(elev, azim) in degrees"
                ) from None
            ax.set_proj_type("ortho")
            ax.view_init(elev=elev, azim=azim)
            chosen = None
        normal = chosen.normal if chosen is not None else np.array([0.43, -0.75, 0.5])
        light = _light_dir(normal)
        cmap = plt.get_cmap("viridis")
        base_colors = (
            ["#c9a27e" if geoms[0] is not None else cmap(0.1)]
            if len(sols) == 1
            else [cmap(0.1 + 0.8 * i / (len(sols) - 1)) for i in range(len(sols))]
        )
        pts = []
        ax.softrod_artists = []
        for i, (sol, geom) in enumerate(zip(sols, geoms, strict=True)):
            inside = geom is not None and (
                bool(geom.chambers)
                or any(
                    np.all(
                        np.linalg.norm(t.offset(np.asarray(sol.s)), axis=1)
                        < geom.radius(np.asarray(sol.s))
                    )
                    for t in geom.tendons
                    if geom.radius is not None
                )
            )
            a = alpha if alpha is not None else (0.35 if inside else 0.9)
            if len(sols) > 1:
                a = min(a, 0.5)
            drawn = _draw_robot_3d(
                ax,
                sol,
                geom,
                color=base_colors[i],
                light=light,
                alpha=a,
                mm=mm,
                options={
                    "tendons": tendons,
                    "disks": True,
                    "chambers": chambers,
                    "label_tendons": i == 0,
                    "label": labels[i] if labels else None,
                },
            )
            ax.softrod_artists.append(drawn)
            p = np.asarray(sol.position) * mm
            pts.append(robot_extent_points(sol, geom) * mm)
            if labels and geom is not None and geom.radius is not None:
                ax.plot([], [], color=base_colors[i], lw=6, alpha=0.8, label=labels[i])
            ax.scatter(*p[-1], color="k", s=10, zorder=8)
            n_frames = frames if frames is not None else (0 if geom is not None else 5)
            size_triad = 0.08 * max(float(np.ptp(np.vstack(pts), axis=0).max()), 1e-6)
            rot = np.asarray(sol.rotation)
            if n_frames:
                for k in np.linspace(0, len(p) - 1, n_frames).round().astype(int):
                    _triad(ax, p[k], rot[k], size_triad, "frame")
            elif geom is not None:
                _triad(ax, p[-1], rot[-1], 1.6 * size_triad, "tip-frame")
        allpts = np.vstack(pts)
        for ob in obs:
            if isinstance(ob, Plane):
                continue
            x, y, z = obstacle_surface(ob, allpts.mean(0) / mm, 1.0)
            allpts = np.vstack((allpts, np.column_stack((x.ravel(), y.ravel(), z.ravel())) * mm))
        ax.softrod_obstacles = _draw_obstacles(ax, obs, allpts, mm)
        limits = set_equal_3d(ax, allpts)
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_zlabel("z (mm)")
        handles, _ = ax.get_legend_handles_labels()
        if handles:
            ax.legend(loc="upper left", fontsize="small", framealpha=0.8)
        if geometry is not None and geometry.chambers:
            from matplotlib.cm import ScalarMappable
            from matplotlib.colors import Normalize

            pmax = max(max(c.pressure for c in geometry.chambers), 1.0)
            sm = ScalarMappable(norm=Normalize(0, pmax / 1e3 / 0.95), cmap="YlOrRd")
            cb = fig.colorbar(sm, ax=ax, shrink=0.55, pad=0.08, label="chamber pressure (kPa)")
            cb.ax.set_gid("chamber-colorbar")
        ax.softrod_view = chosen
        if projections:
            _projection_panels(
                fig, [gs[0, 1], gs[1, 1], gs[2, 1]], sols, geoms, base_colors, mm, obs, limits
            )
        if title is None and robot is not None:
            tip = np.asarray(sols[-1].tip_position)
            where = fmt_vector(tip, scale=mm, unit="mm")
            title = f"{getattr(robot, 'name', 'robot')}: tip at {where}"
        if title:
            (fig.suptitle if projections else ax.set_title)(title)
    return fig


def _actuated(robot, solution):
    """``robot`` at the tensions and pressures of ``solution`` (its tendons' colours and
    legend), or ``robot`` itself when they are its own or cannot be read."""

    def differ(objects, values, attr):
        return (
            values is not None
            and len(values) == len(objects) > 0
            and any(
                float(getattr(o, attr)) != float(v) for o, v in zip(objects, values, strict=True)
            )
        )

    out = robot
    try:
        tensions = getattr(solution, "tendon_tensions", None)
        if differ(robot.tendons, tensions, "tension"):
            out = out.with_tensions(list(tensions))
        pressures = getattr(solution, "pressures", None)
        if differ(robot.chambers, pressures, "pressure"):
            out = out.with_pressures(list(pressures))
    except (AttributeError, TypeError, ValueError):
        return robot
    return out


def plot_robot(robot, solution=None, **options):
    """Figure of a :class:`softrod.Robot` solved as it is (or of a given solution of it).

    Args:
        robot: The robot (its tendons, chambers, section and obstacles are drawn).
        solution: A :class:`softrod.StaticsSolution` of it (default: ``robot.solve()``).
        **options: Keyword arguments of :func:`plot_rod` (``view``, ``projections``,
            ``disks``, ``obstacles`` (default the robot's), ``size``, ``dpi``, ``style``, ...).

    Returns:
        The matplotlib figure (millimetres, world frame).
    """
    sol = robot.solve() if solution is None else solution
    options.setdefault("obstacles", tuple(getattr(robot, "obstacles", ())) or None)
    return plot_rod(sol, robot=robot, **options)
