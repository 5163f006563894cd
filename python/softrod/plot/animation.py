"""Animation of an actuation sweep (GIF with Pillow, MP4 with ffmpeg), axes fixed across frames."""

from __future__ import annotations

import os
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._core import ParameterError
from ._figure import apply_limits_3d, check_dpi, figure_style, fmt_vector, new_figure, set_equal_3d
from .geometry import robot_geometry
from .tube import robot_extent_points
from .views import BendingView, _draw_robot_3d, _light_dir, _triad, bending_view

__all__ = ["ANIMATION_FORMATS", "SweepAnimation", "animate_sweep"]

#: Output formats of :func:`animate_sweep`, chosen from the file's extension.
ANIMATION_FORMATS = ("gif", "mp4")


@dataclass(frozen=True)
class SweepAnimation:
    """What :func:`animate_sweep` wrote.

    Attributes:
        path: The file written.
        frames: Number of frames.
        limits: Axis limits of every frame (mm, rows x, y, z, columns low, high), shape (3, 2).
        frame_limits: The limits read back from the axes after drawing each frame, shape
            (frames, 3, 2) (equal to ``limits`` in every frame).
        view: The camera, one for the whole sweep.
        solutions: The solved frames (:class:`softrod.StaticsSolution`).
    """

    path: str
    frames: int
    limits: np.ndarray
    frame_limits: np.ndarray
    view: BendingView | None
    solutions: list


def _bad(parameter: str, value: object, why: str) -> ParameterError:
    err = ParameterError(f"invalid parameter `{parameter}` = {value!r}: {why}")
    err.parameter = parameter
    return err


def _check_path(path) -> str:
    ext = Path(path).suffix.lower().lstrip(".")
    if ext not in ANIMATION_FORMATS:
        raise _bad("path", os.fspath(path), "the extension must be .gif or .mp4")
    if not Path(path).resolve().parent.is_dir():
        raise _bad("path", os.fspath(path), "its folder does not exist")
    if ext == "mp4":
        from matplotlib import animation

        if not animation.writers.is_available("ffmpeg") and shutil.which("ffmpeg") is None:
            raise _bad(
                "path",
                os.fspath(path),
                "MP4 needs the ffmpeg program, which is not on PATH; install it (e.g. "
                "`apt-get install ffmpeg`) or write a .gif",
            )
    return ext


def _actuation(robot, tensions, pressures) -> tuple[list, list]:
    """Rows of tensions and pressures (one per frame), validated against the robot."""
    n_t, n_c = len(robot.tendons), len(robot.chambers)
    rows_t = rows_p = None
    if tensions is not None:
        rows_t = np.asarray(tensions, dtype=float)
        if rows_t.ndim == 1 and n_t == 1:
            rows_t = rows_t[:, None]
        if rows_t.ndim != 2 or rows_t.shape[1] != n_t:
            raise _bad("tensions", rows_t.shape, f"must have shape (frames, {n_t}) in N")
    if pressures is not None:
        rows_p = np.asarray(pressures, dtype=float)
        if rows_p.ndim == 1 and n_c == 1:
            rows_p = rows_p[:, None]
        if rows_p.ndim != 2 or rows_p.shape[1] != n_c:
            raise _bad("pressures", rows_p.shape, f"must have shape (frames, {n_c}) in Pa")
    if rows_t is None and rows_p is None:
        raise _bad("tensions", None, "give tensions (N), pressures (Pa) or solutions to animate")
    k = len(rows_t) if rows_t is not None else len(rows_p)
    if rows_t is not None and rows_p is not None and len(rows_p) != k:
        raise _bad("pressures", rows_p.shape, f"must have as many rows as tensions ({k})")
    if k < 2:
        raise _bad("tensions" if rows_t is not None else "pressures", k, "needs >= 2 frames")
    return (
        list(rows_t) if rows_t is not None else [None] * k,
        list(rows_p) if rows_p is not None else [None] * k,
    )


def animate_sweep(
    robot,
    path: str | os.PathLike[str],
    *,
    tensions=None,
    pressures=None,
    fps: float = 10.0,
    view: str = "auto",
    title: str | None = None,
    size: tuple[float, float] | None = None,
    dpi: float | None = None,
    style=None,
) -> SweepAnimation:
    """Solves a sweep of actuations (warm-started) and writes it as an animation.

    Every frame is drawn like :func:`plot_rod` with the robot's tube, tendons and chambers,
    one camera (:func:`bending_view` over all frames) and the same axis limits in every frame.

    Args:
        robot: A :class:`softrod.Robot`.
        path: Output file, ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg); checked first.
        tensions: Tendon tensions per frame (N), shape (frames, n_tendons).
        pressures: Chamber pressures per frame (Pa, gauge), shape (frames, n_chambers).
        fps: Frames per second.
        view: ``"auto"`` (bending plane of the whole sweep) or ``"default"``.
        title: Prefix of every frame's title (default: the robot's name).
        size: Figure size (width, height) in inches.
        dpi: Resolution (dots per inch).
        style: A matplotlib style name or file.

    Returns:
        What was written, with the limits of every frame.

    Raises:
        ParameterError: A bad path (extension, folder, MP4 without ffmpeg), shapes, or fps.
        ConvergenceError: A frame's solve did not converge.
    """
    fmt = _check_path(path)
    if not (isinstance(fps, (int, float)) and 0 < fps <= 120):
        raise _bad("fps", fps, "must be in (0, 120] frames per second")
    dpi = check_dpi(dpi)
    rows_t, rows_p = _actuation(robot, tensions, pressures)
    robots, sols, prev = [], [], None
    for t, p in zip(rows_t, rows_p, strict=True):
        r = robot
        if t is not None:
            r = r.with_tensions(t)
        if p is not None:
            r = r.with_pressures(p)
        sol = r.solve(warm_start=prev) if prev is not None else r.solve()
        robots.append(r)
        sols.append(sol)
        prev = sol
    geoms = [robot_geometry(r) for r in robots]
    mm = 1e3
    chosen = bending_view(sols) if view == "auto" else None
    from matplotlib import animation

    with figure_style(style):
        fig = new_figure(size, (6.4, 6.4), dpi)
        ax = fig.add_subplot(projection="3d")
        pts = np.vstack([robot_extent_points(s, g) * mm for s, g in zip(sols, geoms, strict=True)])
        limits = set_equal_3d(ax, pts)
        normal = chosen.normal if chosen is not None else np.array([0.43, -0.75, 0.5])
        light = _light_dir(normal)
        head = title or getattr(robot, "name", "sweep")
        seen: list[np.ndarray] = []
        triad = 0.1 * float(np.ptp(limits, axis=1).max())

        def draw(k: int):
            ax.cla()
            sol, geom = sols[k], geoms[k]
            _draw_robot_3d(
                ax,
                sol,
                geom,
                color="#c9a27e",
                light=light,
                alpha=0.35 if geom.chambers else 0.9,
                mm=mm,
                options={"tendons": True, "disks": True, "chambers": True, "label_tendons": True},
            )
            tip, tip_r = np.asarray(sol.tip_position) * mm, np.asarray(sol.tip_rotation)
            _triad(ax, tip, tip_r, triad, "tip")
            apply_limits_3d(ax, limits)
            if chosen is not None:
                chosen.apply(ax)
            ax.set_xlabel("x (mm)")
            ax.set_ylabel("y (mm)")
            ax.set_zlabel("z (mm)")
            parts = []
            if rows_t[k] is not None:
                parts.append(f"T = {fmt_vector(rows_t[k], unit='N')}")
            if rows_p[k] is not None:
                parts.append(f"P = {fmt_vector(rows_p[k], scale=1e-3, unit='kPa')}")
            ax.set_title(f"{head}: {', '.join(parts)}\nframe {k + 1}/{len(sols)}", fontsize="small")
            seen.append(np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()]))
            return []

        anim = animation.FuncAnimation(fig, draw, frames=len(sols), blit=False, repeat=False)
        if fmt == "gif":
            writer = animation.PillowWriter(fps=fps)
        else:
            writer = animation.FFMpegWriter(fps=fps)
        anim.save(os.fspath(path), writer=writer, **({"dpi": dpi} if dpi else {}))
        import matplotlib.pyplot as plt

        plt.close(fig)
    frame_limits = np.array(seen[-len(sols) :])
    return SweepAnimation(
        path=os.fspath(path),
        frames=len(sols),
        limits=limits,
        frame_limits=frame_limits,
        view=chosen,
        solutions=sols,
    )
