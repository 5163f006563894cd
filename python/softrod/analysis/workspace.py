"""Workspace maps (the compliance-methodology paper, Fig. 1d).

Tendon-tension sweeps with tip stiffness measures.

The compliance itself is computed in the compiled core: :func:`softrod.compliance`,
:func:`softrod.tangent_compliance`, :func:`softrod.eigenscrews`. This module sweeps tendon
tensions in blocks (for a progress bar) over :func:`softrod._core._workspace_map`, which solves
each block in parallel across cores with warm starts.
"""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass

import numpy as np

from .. import _args
from .._core import Loads, ParameterError, Rod, Tendon, _workspace_map


@dataclass(frozen=True)
class WorkspaceMap:
    """Tip positions and stiffness measures over a sweep of tendon tensions.

    Attributes:
        tensions: The tensions of every sample (N), shape (M, n_tendons).
        converged: Whether each sample converged (other fields NaN otherwise), shape (M,).
        tip_position: Tip positions (m, world), shape (M, 3).
        max_translational_compliance: Largest eigenvalue of the force-to-translation block of
            the integrated tip compliance (m/N), shape (M,).
        min_translational_compliance: Smallest one (m/N), shape (M,).
        eigen_stiffness: Eigenstiffnesses of the tip stiffness (world frame at the tip),
            decreasing, shape (M, 6).
        condition: 1-norm condition number of the tip compliance, shape (M,).
        tangent_max_translational_compliance: Largest translational compliance (m/N) of the
            exact tangent tip compliance when requested (``tangent=``), NaN otherwise, (M,).
    """

    tensions: np.ndarray
    converged: np.ndarray
    tip_position: np.ndarray
    max_translational_compliance: np.ndarray
    min_translational_compliance: np.ndarray
    eigen_stiffness: np.ndarray
    condition: np.ndarray
    tangent_max_translational_compliance: np.ndarray


def tension_grid(n_tendons: int, axes: dict[int, np.ndarray]) -> np.ndarray:
    """Tensions on a grid in boustrophedon order (neighbours stay close, for warm starts).

    Args:
        n_tendons: Number of tendons of the robot.
        axes: Tendon index -> 1-D array of its tensions (N); other tendons stay at 0. At most
            two axes.

    Returns:
        Tensions, shape (product of the axis lengths, n_tendons).
    """
    n_tendons = _args.count(n_tendons, "n_tendons", 1, _args.MAX_SAMPLES)
    if not isinstance(axes, dict):
        raise _args.type_error("axes", axes, "a dict: tendon index -> 1-d array of tensions")
    keys = list(axes)
    if not 1 <= len(keys) <= 2:
        raise ParameterError("invalid parameter `axes`: must name one or two tendons")
    for k in keys:
        _args.count(k, "axes", 0, n_tendons - 1)
    a, b = (
        _args.finite_array(axes[k], f"axes[{k}]", ndim=1) if k is not None else np.zeros(1)
        for k in (keys[0], keys[1] if len(keys) == 2 else None)
    )
    if a.size * b.size * n_tendons > _args.MAX_GRID_VALUES:
        raise ParameterError(
            f"invalid parameter `axes`: {a.size * b.size} rows of {n_tendons} tensions: must be "
            f"at most {_args.MAX_GRID_VALUES} values"
        )
    rows = []
    for i, ta in enumerate(a):
        for tb in b if i % 2 == 0 else b[::-1]:
            t = np.zeros(n_tendons)
            t[keys[0]] = ta
            if len(keys) == 2:
                t[keys[1]] = tb
            rows.append(t)
    return np.array(rows)


def workspace_map(
    rod: Rod,
    tendons,
    tensions,
    loads: Loads | None = None,
    *,
    chunk: int = 64,
    block: int = 2000,
    progress: bool | None = False,
    tangent: str | None = None,
    **options,
) -> WorkspaceMap:
    """Solves the robot for every row of tensions and measures the tip stiffness.

    Args:
        rod: The rod.
        tendons: Its tendons (their tensions are replaced by each row of ``tensions``).
        tensions: Tensions (N), shape (M, n_tendons); order rows along a path (e.g.
            :func:`tension_grid`) so that warm starts help.
        loads: External loads (default none).
        chunk: Samples solved in order on one thread, each warm-started from the previous.
        block: Samples per call into the core (the progress bar advances per block).
        progress: Draw a progress bar (tqdm) on stderr: True, False, or None for only when
            stderr is a terminal.
        tangent: Also compute the exact tangent tip compliance with the tendons at fixed
            ``"tension"`` or ``"length"`` (about four times the cost of a tendon-only solve).
        **options: Solver options of :func:`softrod.solve_statics` (``integrator``,
            ``steps``, ``rtol``, ``atol``, ``tolerance``).

    Returns:
        The map; failed samples have ``converged`` False and NaN measures.
    """
    from tqdm.auto import tqdm

    if isinstance(tendons, (str, bytes)) or not hasattr(tendons, "__iter__"):
        raise _args.type_error("tendons", tendons, "a sequence of Tendon")
    tendons: list[Tendon] = list(tendons)
    t = np.ascontiguousarray(np.atleast_2d(_args.finite_array(tensions, "tensions")))
    parts = []
    total = len(t)
    block = _args.count(block, "block", 1, 2**62)
    if progress is not None:
        progress = _args.flag(progress, "progress")
    bar = tqdm(
        total=total,
        desc="workspace",
        unit="config",
        disable=(None if progress is None else not progress),
        file=sys.stderr,
    )
    for start in range(0, total, int(block)):
        try:
            part = _workspace_map(
                rod,
                tendons,
                t[start : start + block],
                loads,
                chunk=chunk,
                tangent=tangent,
                **options,
            )
        except ParameterError as exc:
            # (The core names a row of the block it was given: named by its row in `tensions`.)
            found = re.match(r"tensions\[(\d+), (\d+)\]$", getattr(exc, "parameter", "") or "")
            if not found or start == 0:
                raise
            row, col = int(found.group(1)) + start, found.group(2)
            raise _args.bad(str(exc).replace(exc.parameter, f"tensions[{row}, {col}]", 1)) from None
        parts.append(part)
        bar.update(min(start + block, total) - start)
    bar.close()
    if not parts:
        raise ParameterError("invalid parameter `tensions`: must have at least one row")

    def cat(key):
        return np.concatenate([np.asarray(p[key]) for p in parts])

    return WorkspaceMap(
        tensions=t,
        converged=cat("converged").astype(bool),
        tip_position=cat("tip_position"),
        max_translational_compliance=cat("max_translational_compliance"),
        min_translational_compliance=cat("min_translational_compliance"),
        eigen_stiffness=cat("eigen_stiffness"),
        condition=cat("condition"),
        tangent_max_translational_compliance=cat("tangent_max_translational_compliance"),
    )
