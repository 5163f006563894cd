"""The design study of docs/sweeps.md: the planar cable-arm paper's tapered arm, taper ratio x
offset ratio x cable tension, run on a local Dask cluster; writes the page's figures and prints
its tables.

Run from the repository root: ``python docs/sweeps.py [OUT_DIR]`` (default ``docs/figures``).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import softrod
from softrod import plot
from softrod.analysis.sweep import STATUS

BASE_RADIUS = 0.015  # m, the arm's base radius (its file)
TAPER = np.linspace(0.3, 1.0, 15)  # tip radius / base radius
OFFSET = np.append(np.linspace(0.05, 0.65, 13), 1.0)  # cable offset / local radius; 1.0: outside
TENSION = np.linspace(0.0, 4.0, 81)  # N


def run(scheduler=None):
    arm = softrod.examples.load("tapered_cable_arm")
    return softrod.sweep(
        arm,
        design={"rod.section.tip_radius": TAPER * BASE_RADIUS, "tendons[0].ratio": OFFSET},
        actuation={"tendons[0].tension": TENSION},
        outputs=("tip_pose", "translational_compliance", "convergence"),
        scheduler=scheduler,
        progress=False,
    )


def main(out: Path) -> None:
    from distributed import LocalCluster

    out.mkdir(parents=True, exist_ok=True)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
        t0 = time.perf_counter()
        ds = run(cluster)
        t_dask = time.perf_counter() - t0
    t0 = time.perf_counter()
    local = run()
    t_local = time.perf_counter() - t0
    status = ds["status"]
    print(f"samples: {status.size}; dask (2 workers) {t_dask:.2f} s, in process {t_local:.2f} s")
    print(f"identical to the in-process sweep: {ds.identical(local)}")
    counts = {k: int((status == v).sum()) for k, v in STATUS.items()}
    print(f"status: {counts}")
    bad = ds["design_error"].values[ds["design_status"].values == 1]
    print(f"infeasible design points: {len(bad)}; e.g. {bad[0]}")
    summary = softrod.design_summary(ds)
    taper_dim, offset_dim = "rod.section.tip_radius", "tendons[0].ratio"

    # Figure 1: tip paths over the tension for four tapers at one offset.
    fig, ax = plt.subplots(figsize=(6.0, 4.2))
    cmap = plt.get_cmap("viridis")
    for k, taper in enumerate([0.3, 0.5, 0.7, 1.0]):
        sel = ds.sel({taper_dim: taper * BASE_RADIUS, offset_dim: 0.35}, method="nearest")
        tip = sel["tip_position"].where(sel["status"] == 0)
        ax.plot(
            tip.sel(xyz="x") * 1e3,
            tip.sel(xyz="z") * 1e3,
            "-o",
            ms=2,
            color=cmap(k / 3),
            label=f"taper {taper:.1f}",
        )
    ax.set_xlabel("tip x (mm)")
    ax.set_ylabel("tip z (mm)")
    ax.set_aspect("equal")
    ax.set_title("tip path, cable tension 0-4 N, offset ratio 0.35")
    ax.legend(loc="lower left", fontsize=8)
    plot.save_figure(fig, out / "sweep_tips.png", dpi=110, overwrite=True)
    plt.close(fig)

    # Figure 2: workspace area and median tip stiffness over the two design ratios.
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.0), constrained_layout=True)
    feasible = OFFSET < 1.0
    for ax, var, scale, label in [
        (axes[0], "hull_area", 1e4, "workspace area, convex hull (cm$^2$)"),
        (axes[1], "stiffness_median", 1.0, "median tip stiffness $1/c_{max}$ (N/m)"),
    ]:
        v = summary[var].transpose(taper_dim, offset_dim).values[:, feasible] * scale
        im = ax.pcolormesh(OFFSET[feasible], TAPER, v, shading="nearest", cmap="viridis")
        fig.colorbar(im, ax=ax, label=label)
        ax.set_xlabel("cable offset ratio (offset / local radius)")
        ax.set_ylabel("taper ratio (tip / base radius)")
    axes[0].set_title("reachable workspace")
    axes[1].set_title("stiffness over the workspace")
    plot.save_figure(fig, out / "sweep_maps.png", dpi=110, overwrite=True)
    plt.close(fig)

    # Figure 3: the Pareto front of workspace area and stiffness (both better larger).
    area = summary["hull_area"]
    stiff = summary["stiffness_median"]
    front = softrod.Pareto(area, stiff, better=("max", "max"))
    fig, ax = plt.subplots(figsize=(6.0, 4.2))
    ax.scatter(area.values.ravel() * 1e4, stiff.values.ravel(), s=10, c="0.6", label="designs")
    f = front.values
    ax.plot(f[:, 0] * 1e4, f[:, 1], "-o", color="C3", ms=4, label="Pareto front")
    table = front.table()
    for k in sorted({0, len(table) // 2, len(table) - 1}):
        row = table.iloc[k]
        ax.annotate(
            f"taper {row[taper_dim] / BASE_RADIUS:.2f}, offset {row[offset_dim]:.2f}",
            (row["hull_area"] * 1e4, row["stiffness_median"]),
            textcoords="offset points",
            xytext=(-70, -28) if k == 0 else (12, 10) if k < len(table) - 1 else (12, -3),
            fontsize=7,
            arrowprops={"arrowstyle": "-", "color": "0.4", "lw": 0.6},
        )
    ax.set_xlabel("workspace area (cm$^2$)")
    ax.set_ylabel("median tip stiffness (N/m)")
    ax.set_title("workspace vs stiffness of 195 feasible designs")
    ax.legend(fontsize=8)
    plot.save_figure(fig, out / "sweep_pareto.png", dpi=110, overwrite=True)
    plt.close(fig)

    print("Pareto front (taper ratio, offset ratio, area cm^2, median stiffness N/m, ratio):")
    ratio = summary["centre_periphery_ratio"]
    for _, row in table.iterrows():
        c = float(ratio.sel({taper_dim: row[taper_dim], offset_dim: row[offset_dim]}))
        print(
            f"  {row[taper_dim] / BASE_RADIUS:.2f}  {row[offset_dim]:.2f}  "
            f"{row['hull_area'] * 1e4:7.2f}  {row['stiffness_median']:7.4f}  {c:.3f}"
        )


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent / "figures")
