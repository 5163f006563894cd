"""Seed 001's study on the pneumatic arm: stiffness over the workspace, gamma_c vs pressure.

Run from the repository root: ``python examples/seed001_study.py``. Writes
``docs/figures/pneumatic_workspace.png`` and ``docs/figures/pneumatic_gamma_c.png`` and prints
the numbers quoted in ``docs/pneumatic.md``.
"""

import itertools
import time
from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")
import numpy as np

import softrod
from softrod.plot import plot_gamma_c, plot_workspace_map

robot = softrod.load_robot("examples/robots/seed001_pneumatic_arm.toml")


def pair_pressures(p1, p2, p3):
    """Chamber pressures (Pa) for pair pressures P1, P2, P3."""
    return [p1, p1, p2, p2, p3, p3]


# Workspace: every (P1, P2, P3) on a grid of 0-60 kPa, the tip compliance at each.
levels = np.linspace(0.0, 60e3, 13)
t0 = time.perf_counter()
tips, cmax, cmin, ok = [], [], [], []
for p in itertools.product(levels, repeat=3):
    try:
        sol = robot.with_pressures(pair_pressures(*p)).solve()
    except (softrod.ConvergenceError, softrod.ParameterError):
        tips.append([np.nan] * 3)
        cmax.append(np.nan)
        cmin.append(np.nan)
        ok.append(False)
        continue
    eig = np.linalg.eigvalsh(softrod.compliance(sol).tip_world[:3, :3])
    tips.append(sol.tip_position)
    cmax.append(eig[-1])
    cmin.append(eig[0])
    ok.append(True)
elapsed = time.perf_counter() - t0
wmap = SimpleNamespace(
    tip_position=np.array(tips),
    max_translational_compliance=np.array(cmax),
    min_translational_compliance=np.array(cmin),
    converged=np.array(ok),
)
n = len(ok)
print(f"workspace: {n} pressure sets (P1, P2, P3 in 0-60 kPa) solved in {elapsed:.1f} s")
r = np.hypot(wmap.tip_position[:, 0], wmap.tip_position[:, 1])
c = wmap.max_translational_compliance
centre = c[np.nanargmin(r)]
edge = c[np.nanargmax(r)]
print(
    f"largest translational tip compliance: centre {centre:.4f} m/N, "
    f"periphery {edge:.4f} m/N (x {edge / centre:.2f})"
)
fig = plot_workspace_map(
    wmap,
    title="Pneumatic arm (Dragon Skin 10): largest tip compliance over P1, P2, P3 in 0-60 kPa",
)
fig.savefig("docs/figures/pneumatic_workspace.png", dpi=110)

# gamma_c(s) with P1 and P2 actuated together (seed Fig. 1e).
pressures = [0.0, 10e3, 20e3, 30e3, 40e3]
comps = [
    softrod.compliance(robot.with_pressures(pair_pressures(p, p, 0.0)).solve()) for p in pressures
]
fig = plot_gamma_c(
    comps,
    labels=[f"P1 = P2 = {p / 1e3:.0f} kPa" for p in pressures],
    title="Pneumatic arm: dimensionless flexural compliance along the arm",
)
fig.savefig("docs/figures/pneumatic_gamma_c.png", dpi=110)
for p, comp in zip(pressures, comps, strict=True):
    print(f"P1 = P2 = {p / 1e3:4.0f} kPa: gamma_c at the tip = {np.round(comp.gamma_c[-1], 4)}")
