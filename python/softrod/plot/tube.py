"""Meshes around a solved backbone (NumPy only, shared by the figures and the live view).

Every point is ``p(s) + R(s) [x, y, 0]`` with ``p`` (m, world) and ``R`` (body -> world) the
solution's ``position`` and ``rotation`` at arc length ``s``, and ``(x, y)`` a body-frame
offset: the tube's surface, a tendon's path ``p + R r(s)``, a chamber's bore, a disk.
"""

from __future__ import annotations

import numpy as np

from .geometry import ChamberGeometry, RobotGeometry, TendonGeometry

__all__ = [
    "chamber_grid",
    "disk_polygon",
    "frames_at",
    "tendon_path",
    "tube_grid",
    "tube_mesh",
]


def _orthonormal(r: np.ndarray) -> np.ndarray:
    """The rotation nearest to each 3x3 matrix of ``r`` (..., 3, 3)."""
    u, _, vt = np.linalg.svd(r)
    out = u @ vt
    det = np.linalg.det(out)
    u[..., :, -1] *= np.sign(det)[..., None]
    return u @ vt


def frames_at(solution, s) -> tuple[np.ndarray, np.ndarray]:
    """Positions (m, shape (n, 3)) and rotations (shape (n, 3, 3)) at arc lengths ``s`` (m).

    Linear between the solution's samples (rotations re-orthonormalised); ``s`` is clipped to
    the rod.
    """
    s = np.clip(np.atleast_1d(np.asarray(s, dtype=float)), solution.s[0], solution.s[-1])
    grid = np.asarray(solution.s)
    p = np.column_stack([np.interp(s, grid, solution.position[:, k]) for k in range(3)])
    rot = np.asarray(solution.rotation)
    r = np.empty((len(s), 3, 3))
    for i in range(3):
        for j in range(3):
            r[:, i, j] = np.interp(s, grid, rot[:, i, j])
    return p, _orthonormal(r)


def _ring(p, r, offsets_xy: np.ndarray) -> np.ndarray:
    """World points ``p + R [x, y, 0]``: p (n, 3), R (n, 3, 3), offsets (n, m, 2) -> (n, m, 3)."""
    return p[:, None, :] + np.einsum("nij,nmj->nmi", r[:, :, :2], offsets_xy)


def tube_grid(
    solution, radius: np.ndarray | float, n_around: int = 28, s: np.ndarray | None = None
) -> np.ndarray:
    """Surface points of the tube of ``radius`` (m) around the backbone, shape (n, m + 1, 3).

    Args:
        solution: A statics solution (``s``, ``position``, ``rotation``).
        radius: Outer radius (m) at each ``s``, shape (n,) or a number.
        n_around: Points around the circumference (the last column repeats the first).
        s: Arc lengths (m), default the solution's samples.
    """
    s = np.asarray(solution.s if s is None else s, dtype=float)
    p, r = frames_at(solution, s)
    theta = np.linspace(0.0, 2.0 * np.pi, n_around + 1)
    rad = np.broadcast_to(np.asarray(radius, dtype=float), s.shape)
    circle = np.stack((np.cos(theta), np.sin(theta)), axis=-1)  # (m+1, 2)
    return _ring(p, r, rad[:, None, None] * circle[None])


def tube_mesh(grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangle mesh of a grid from :func:`tube_grid`: vertices (n m, 3), faces (k, 3) ints."""
    n, m1, _ = grid.shape
    m = m1 - 1
    vertices = grid[:, :m, :].reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(m), indexing="ij")
    a = i * m + j
    b = i * m + (j + 1) % m
    c = (i + 1) * m + j
    d = (i + 1) * m + (j + 1) % m
    faces = np.concatenate(
        (np.stack((a, b, d), -1).reshape(-1, 3), np.stack((a, d, c), -1).reshape(-1, 3))
    )
    return vertices, faces.astype(np.uint32)


def tendon_path(solution, tendon: TendonGeometry, n: int | None = None) -> np.ndarray:
    """World points of a tendon, ``p(s) + R(s) r(s)`` for ``s`` from 0 to its end (m), (k, 3)."""
    grid = np.asarray(solution.s)
    if n is None:
        s = np.append(grid[grid < tendon.end], tendon.end)
    else:
        s = np.linspace(0.0, tendon.end, n)
    p, r = frames_at(solution, s)
    off = np.asarray(tendon.offset(s), dtype=float).reshape(-1, 1, 2)
    return _ring(p, r, off)[:, 0, :]


def chamber_grid(solution, chamber: ChamberGeometry, n_around: int = 16) -> np.ndarray:
    """Surface of a chamber's bore (m, world), shape (n, n_around + 1, 3)."""
    grid = np.asarray(solution.s)
    inside = grid[(grid > chamber.start) & (grid < chamber.end)]
    s = np.concatenate(([chamber.start], inside, [chamber.end]))
    p, r = frames_at(solution, s)
    theta = np.linspace(0.0, 2.0 * np.pi, n_around + 1)
    circle = chamber.offset + chamber.radius * np.stack((np.cos(theta), np.sin(theta)), -1)
    return _ring(p, r, np.broadcast_to(circle, (len(s), *circle.shape)))


def disk_polygon(solution, s: float, radius: float, n: int = 48) -> np.ndarray:
    """Rim of a spacer disk at arc length ``s`` (m), in the body x-y plane, shape (n, 3)."""
    p, r = frames_at(solution, [s])
    theta = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    circle = radius * np.stack((np.cos(theta), np.sin(theta)), -1)
    return _ring(p, r, circle[None])[0]


def robot_extent_points(solution, geometry: RobotGeometry | None) -> np.ndarray:
    """Points bounding everything drawn of one solution (m, world), for the axis limits."""
    pts = [np.asarray(solution.position)]
    if geometry is not None:
        rmax = geometry.max_radius()
        if rmax > 0:
            pts.append(tube_grid(solution, rmax, n_around=8).reshape(-1, 3))
    return np.vstack(pts)
