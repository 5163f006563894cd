"""The compliance-methodology paper's study of a pneumatic arm.

Stiffness over the workspace and ``gamma_c`` vs pressure.

For a robot with three chamber pairs (pressures P1, P2, P3 on chambers 0-1, 2-3, 4-5), solved
twice — with its hyperelastic material and with the linear material of the same small-strain
modulus — :func:`compliance_study` sweeps the pair pressures over a grid, takes the tip
compliance of every configuration (the compliance-methodology paper's eq. 6), decomposes it
into eigenscrews and maps the largest translational compliance (the translational
ellipsoid's largest semi-axis) over the workspace (its Fig. 1d); then it computes
``gamma_c(s)`` along the arm as P1 and P2 rise together (its Fig. 1e). ``softrod study
ROBOT.toml`` runs it from the command line.
"""

from __future__ import annotations

import itertools
import os
import sys
import time
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any, Literal, TextIO

import numpy as np

from .. import _args
from .._core import ConvergenceError, ParameterError, UniaxialLaw
from ..io.objects import build_material
from ..robot import Robot, load_robot
from ._sweep_run import STATUS

__all__ = ["StudyResult", "compliance_study", "levels_beyond_limit", "seed001_study"]


def levels_beyond_limit(levels: int) -> str | None:
    """Why ``levels`` pressure levels per pair make too large a study, or None if they do not.

    The study's grid holds ``levels**3`` pressure sets per material; like a sweep's, it may
    hold at most :data:`softrod._args.MAX_GRID_VALUES` (10,000,000) points, so at most 215
    levels. Checked before anything is built.

    Args:
        levels: Pressure levels per pair (an integer >= 2).

    Returns:
        The reason, worded like a sweep's refusal (the number of points and the limit), or
        None for a grid within the limit.
    """
    limit = _args.MAX_GRID_VALUES
    points = int(levels) ** 3
    if points <= limit:
        return None
    most = round(limit ** (1 / 3))
    most -= most**3 > limit
    most += (most + 1) ** 3 <= limit
    return (
        f"{levels}**3 = {points} pressure sets per material: must be at most {limit} points "
        f"(at most {most} levels)"
    )


@dataclass
class StudyResult:
    """Numbers of one material's study.

    Attributes:
        material: ``"hyperelastic"`` or ``"linear"``.
        pressures: Pair pressures of the workspace grid (Pa), shape (n, 3).
        tip_position: Tip positions (m), shape (n, 3); NaN where a solve failed.
        max_compliance: Largest translational tip compliance (m/N, eigenscrew ellipsoid).
        centre_periphery_ratio: Largest compliance at the workspace periphery (tip farthest
            from the axis) over that at its centre (nearest).
        gamma_c_pressures: Pressures of the ``gamma_c`` curves (Pa, P1 = P2).
        gamma_c_tip: ``gamma_c`` at the tip per curve, shape (k, 3).
        elongation: Tip height at equal pressures over the unpressurised one, per grid level.
        status: Per pressure set, how its solve ended: 0 converged, 1 not converged, 2 failed
            with an error (the values of a sweep's ``status``); NaN values unless 0.
        error: Per pressure set, the error (class and message) of a set that did not
            converge, "" if it did.
    """

    material: str
    pressures: np.ndarray
    tip_position: np.ndarray
    max_compliance: np.ndarray
    centre_periphery_ratio: float
    gamma_c_pressures: np.ndarray
    gamma_c_tip: np.ndarray
    compliances: list[Any]
    elongation: np.ndarray
    status: np.ndarray
    error: np.ndarray

    @property
    def failures(self) -> int:
        """Number of pressure sets that did not converge (status not 0)."""
        return int(np.count_nonzero(self.status))


def _linear_twin(robot: Robot) -> tuple[Robot, float]:
    """The same robot with the linear material of its law's small-strain modulus."""
    law = getattr(robot.rod, "material", None)
    if law is None:
        law = build_material(robot.spec.rod.material, [])
    e0 = law.small_strain_modulus if isinstance(law, UniaxialLaw) else law.youngs_modulus
    twin = robot.with_parameters(
        {
            "name": f"{robot.name}-linear",
            "rod.material": {"youngs_modulus": e0, "poisson_ratio": 0.5},
        }
    )
    return twin, e0


def _pair_pressures(p: tuple[float, float, float]) -> list[float]:
    return [p[0], p[0], p[1], p[1], p[2], p[2]]


def _run(
    robot: Robot, material: str, levels: np.ndarray, gamma_p: np.ndarray, progress: bool | None
) -> StudyResult:
    from .. import compliance, eigenscrews

    grid = np.array(list(itertools.product(levels, repeat=3)))
    tips = np.full((len(grid), 3), np.nan)
    cmax = np.full(len(grid), np.nan)
    status = np.zeros(len(grid), dtype=np.int8)
    error = np.full(len(grid), "", dtype=object)
    from tqdm.auto import tqdm

    bar = tqdm(
        grid,
        desc=f"study ({material})",
        unit="config",
        disable=None if progress is None else not progress,
        file=sys.stderr,
    )
    for i, p in enumerate(bar):
        try:
            sol = robot.with_pressures(_pair_pressures(tuple(p))).solve()
        except (ConvergenceError, ParameterError) as exc:
            status[i] = STATUS["not_converged" if isinstance(exc, ConvergenceError) else "failed"]
            error[i] = f"{type(exc).__name__}: {' '.join(str(exc).split())}"
            continue
        screws = eigenscrews(compliance(sol).tip_world, "compliance")
        tips[i] = sol.tip_position
        cmax[i] = float(np.max(screws.translational_axes))
    r = np.hypot(tips[:, 0], tips[:, 1])
    ok = np.isfinite(cmax)
    two = np.count_nonzero(ok) >= 2  # a ratio needs a centre and a periphery
    centre = cmax[ok][np.argmin(r[ok])] if two else np.nan
    edge = cmax[ok][np.argmax(r[ok])] if two else np.nan
    comps = [
        compliance(robot.with_pressures(_pair_pressures((p, p, 0.0))).solve()) for p in gamma_p
    ]
    base = np.flatnonzero(np.all(grid == 0.0, axis=1))[0]
    equal = [np.flatnonzero(np.all(grid == lv, axis=1))[0] for lv in levels]
    return StudyResult(
        material=material,
        pressures=grid,
        tip_position=tips,
        max_compliance=cmax,
        centre_periphery_ratio=float(edge / centre),
        gamma_c_pressures=np.asarray(gamma_p),
        gamma_c_tip=np.array([c.gamma_c[-1] for c in comps]),
        compliances=comps,
        elongation=tips[equal, 2] / tips[base, 2],
        status=status,
        error=error,
    )


def compliance_study(
    robot_path: str | os.PathLike[str] | Robot,
    *,
    levels: int = 13,
    max_pressure: float = 60e3,
    gamma_pressures: tuple[float, ...] = (0.0, 10e3, 20e3, 30e3, 40e3),
    out_dir: str | os.PathLike[str] | None = None,
    log: TextIO | Literal["stdout"] | None = "stdout",
    progress: bool | None = False,
    overwrite: bool = False,
) -> dict[str, StudyResult]:
    """Runs the compliance-methodology paper's study (hyperelastic and linear).

    The robot has three chamber pairs.

    Args:
        robot_path: A robot, or its description file, with six chambers (pairs 0-1, 2-3, 4-5) and a
            hyperelastic (or linear) material.
        levels: Pressure levels per pair on ``[0, max_pressure]`` (``levels**3`` configurations
            per material, at most :data:`softrod._args.MAX_GRID_VALUES` (10,000,000): 2 to
            215 levels).
        max_pressure: Largest pair pressure (Pa).
        gamma_pressures: P1 = P2 pressures (Pa) of the ``gamma_c(s)`` curves.
        out_dir: Folder for the figures (``pneumatic_workspace_<material>.png``,
            ``pneumatic_gamma_c_<material>.png``); ``None`` draws nothing.
        overwrite: Replace figures of those names already in ``out_dir`` (default: refuse,
            before any work).
        progress: Progress bars (tqdm) on stderr: True, False, or None for only when stderr
            is a terminal.
        log: Where the summary is printed: ``"stdout"`` (the current ``sys.stdout``, the
            default), an open text file, or ``None`` (silent).

    Returns:
        The results by material, ``"hyperelastic"`` and ``"linear"``. A pressure set whose
        solve fails is counted (``StudyResult.failures``, printed), recorded (``status``,
        ``error``) and NaN; the study goes on.

    Raises:
        ParameterError: A robot without exactly six chambers, or bad arguments (``levels``
            beyond the grid-size limit is refused before anything is built).
        ParameterTypeError: ``levels`` is not an integer.
        FileExistsError: A figure exists in ``out_dir`` and ``overwrite`` is false.
    """
    if isinstance(log, str) and log == "stdout":
        log = sys.stdout
    if not _args._is_int(levels):
        raise _args.type_error("levels", levels, "an integer >= 2")
    if levels < 2:
        raise ParameterError(f"invalid parameter `levels` = {levels}: must be >= 2")
    too_many = levels_beyond_limit(levels)
    if too_many is not None:  # before the levels**3 grid is built
        exc = ParameterError(f"invalid parameter `levels` = {levels}: {too_many}")
        exc.parameter = "levels"
        raise exc
    if not (np.isfinite(max_pressure) and max_pressure > 0):
        raise ParameterError(
            f"invalid parameter `max_pressure` = {max_pressure}: must be finite and > 0 Pa"
        )
    if out_dir is not None and not overwrite:
        for path in _figure_paths(out_dir):
            if os.path.exists(path):
                raise FileExistsError(17, "exists (pass overwrite=True to replace it)", path)
    robot = robot_path if isinstance(robot_path, Robot) else load_robot(robot_path)
    if len(robot.chambers) != 6:
        raise ParameterError(
            f"invalid parameter `robot_path` = {robot.name!r}: the study needs six "
            f"chambers (three pairs), the robot has {len(robot.chambers)}"
        )
    twin, e0 = _linear_twin(robot)
    models = {"hyperelastic": robot, "linear": twin}
    grid = np.linspace(0.0, max_pressure, levels)
    out: dict[str, StudyResult] = {}
    for material, rb in models.items():
        t0 = time.perf_counter()
        res = _run(rb, material, grid, np.asarray(gamma_pressures), progress)
        out[material] = res
        if log is not None:
            print(
                f"{material} ({'E0' if material == 'linear' else 'law'}"
                f"{f' = {e0 / 1e3:.1f} kPa' if material == 'linear' else ''}): "
                f"{len(res.pressures)} pressure sets in {time.perf_counter() - t0:.1f} s; "
                f"largest translational tip compliance centre -> periphery "
                f"x {res.centre_periphery_ratio:.2f}",
                file=log,
            )
            if res.failures:
                not_converged = int(np.count_nonzero(res.status == STATUS["not_converged"]))
                print(
                    f"  {res.failures} of {len(res.pressures)} pressure sets failed "
                    f"({not_converged} not converged, {res.failures - not_converged} with an "
                    "error): NaN in the map, the ratios that need them and the data",
                    file=log,
                )
            for p, g in zip(res.gamma_c_pressures, res.gamma_c_tip, strict=True):
                print(
                    f"  P1 = P2 = {p / 1e3:4.0f} kPa: gamma_c at the tip (body x, y, z) = "
                    f"{np.array2string(g, precision=4)}",
                    file=log,
                )
            ratio = _equal_ratio(res, grid)
            if np.isfinite(res.elongation[-1]) and np.isfinite(ratio):
                change = f"tip height x {res.elongation[-1]:.3f}, largest compliance x {ratio:.3f}"
            else:
                change = "not computed (a pressure set it needs failed)"
            print(f"  equal pressures 0 -> {max_pressure / 1e3:.0f} kPa: {change}", file=log)
    if out_dir is not None:
        _figures(out, grid, out_dir, log)
    return out


def _figure_paths(out_dir) -> list[str]:
    """The figures the study writes in ``out_dir``, per material: workspace map, gamma_c."""
    return [
        os.path.join(out_dir, f"pneumatic_{kind}_{material}.png")
        for material in ("hyperelastic", "linear")
        for kind in ("workspace", "gamma_c")
    ]


def _equal_ratio(res: StudyResult, grid: np.ndarray) -> float:
    base = np.flatnonzero(np.all(res.pressures == 0.0, axis=1))[0]
    top = np.flatnonzero(np.all(res.pressures == grid[-1], axis=1))[0]
    return float(res.max_compliance[top] / res.max_compliance[base])


def _figures(out: dict[str, StudyResult], grid, out_dir, log) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..plot import plot_gamma_c, plot_workspace_map

    os.makedirs(out_dir, exist_ok=True)
    for material, res in out.items():
        ok = np.isfinite(res.max_compliance)
        wmap = SimpleNamespace(
            tip_position=res.tip_position,
            max_translational_compliance=res.max_compliance,
            converged=ok,
        )
        f1 = plot_workspace_map(
            wmap,
            title=f"{material}: largest translational tip compliance (m/N), "
            f"P1, P2, P3 in 0-{grid[-1] / 1e3:.0f} kPa",
        )
        p1 = os.path.join(out_dir, f"pneumatic_workspace_{material}.png")
        f1.savefig(p1, dpi=110)
        plt.close(f1)
        f2 = plot_gamma_c(
            res.compliances,
            labels=[f"P1 = P2 = {p / 1e3:.0f} kPa" for p in res.gamma_c_pressures],
            title=f"{material}: dimensionless flexural compliance along the arm",
        )
        p2 = os.path.join(out_dir, f"pneumatic_gamma_c_{material}.png")
        f2.savefig(p2, dpi=110)
        plt.close(f2)
        if log is not None:
            print(f"wrote {p1}\nwrote {p2}", file=log)


#: The earlier name of :func:`compliance_study`, kept working.
seed001_study = compliance_study
