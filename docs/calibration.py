"""The experiment of docs/calibration.md: photographs of the planar cable-arm paper's arm at three
cable tensions (rendered from known solutions, with shading, blur, noise and floats) ->
extracted backbones -> fitted E and a -> distances at equal arm index before and after; writes
the page's figures and prints its tables.

Run from the repository root: ``python docs/calibration.py [OUT_DIR]`` (default
``docs/figures``).
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import softrod

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from arm_photos import render_published_arm

TENSIONS = (1.0, 2.0, 3.0)  # N
TRUE = {"youngs_modulus": 110e3, "offset_ratio": 1 / 3}  # the rendered arm (published_arm)
START = softrod.PlanarCableArm(0.27, 0.015, 0.0074, 0.25, 70e3)  # a guessed model


def photographs(seed: int = 0):
    photos, backbones = [], []
    for i, t in enumerate(TENSIONS):
        photo = render_published_arm(t, seed=seed + i)
        bb = softrod.extract_backbone(
            photo.image, scale=photo.scale, base=photo.base, direction=photo.direction
        )
        photos.append(photo)
        backbones.append(bb)
    return photos, backbones


def to_pixels(photo, x, y):
    d = photo.direction
    n = np.array([d[1], -d[0]])
    return photo.base + (np.outer(x, d) + np.outer(y, n)) / photo.scale


def figures(out: Path, photos, backbones, fit) -> None:
    fig, axes = plt.subplots(1, 3, figsize=(13.5, 3.9), constrained_layout=True)
    for ax, photo, bb, t in zip(axes, photos, backbones, TENSIONS, strict=True):
        ax.imshow(photo.image, cmap="gray")
        before = START.solve(t, 300)
        after = fit.robot.solve(t, 300)
        for sol, style, label in ((before, "r--", "guessed model"), (after, "c-", "calibrated")):
            px = to_pixels(photo, sol.x, sol.y)
            ax.plot(px[:, 0], px[:, 1], style, lw=1.3, label=label)
        ax.plot(bb.pixels[:, 0], bb.pixels[:, 1], "y:", lw=1.6, label="extracted")
        ax.set_title(f"T = {t:g} N")
        ax.set_axis_off()
    axes[0].legend(loc="lower left", fontsize=8)
    fig.savefig(out / "calibration_photos.png", dpi=110)
    plt.close(fig)

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for bb, t, c in zip(backbones, TENSIONS, ("C0", "C1", "C2"), strict=True):
        p = bb.points * 1e3
        a1.plot(p[:, 0], p[:, 1], color=c, lw=3, alpha=0.35, label=f"extracted, {t:g} N")
        for robot, style in ((START, "--"), (fit.robot, "-")):
            sol = robot.solve(t, 300)
            a1.plot(sol.x * 1e3, sol.y * 1e3, style, color=c, lw=1)
            d = softrod.backbone_distance(sol, bb, 200)
            a2.plot(
                d.index,
                d.distance * 1e3,
                style,
                color=c,
                label=f"{t:g} N, {'guessed' if robot is START else 'calibrated'}",
            )
    a1.set_aspect("equal")
    a1.set_xlabel("x (mm)")
    a1.set_ylabel("y (mm)")
    a1.set_title("backbones: extracted (wide), guessed (dashed), calibrated (solid)")
    a1.legend(fontsize=8)
    a2.set_yscale("log")
    a2.set_xlabel("arm index")
    a2.set_ylabel("distance at equal arm index (mm)")
    a2.legend(fontsize=7, ncol=2)
    fig.savefig(out / "calibration_distances.png", dpi=110)
    plt.close(fig)


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    photos, backbones = photographs()
    data = list(zip(TENSIONS, backbones, strict=True))
    t0 = time.perf_counter()
    fit = softrod.calibrate(START, data, ["youngs_modulus", "offset_ratio"])
    dt = time.perf_counter() - t0
    print(f"fit in {dt * 1e3:.0f} ms, {fit.evaluations} evaluations, rms {fit.rms * 1e3:.3f} mm")
    print("| parameter | start | fitted | standard error | true | error |")
    print("|---|---|---|---|---|---|")
    for k, v in fit.values.items():
        print(
            f"| `{k}` | {fit.initial[k]:.6g} | {v:.6g} | {fit.standard_errors[k]:.2g} | "
            f"{TRUE[k]:.6g} | {100 * (v / TRUE[k] - 1):+.3f} % |"
        )
    print(f"correlation(E, a) = {fit.correlation[0, 1]:+.3f}")
    print("| tension (N) | max before (mm) | mean before (mm) | max after (mm) | mean after (mm) |")
    print("|---|---|---|---|---|")
    for t, bb in data:
        b = softrod.backbone_distance(START.solve(t, 400), bb)
        a = softrod.backbone_distance(fit.robot.solve(t, 400), bb)
        print(
            f"| {t:g} | {b.max * 1e3:.2f} | {b.mean * 1e3:.2f} | {a.max * 1e3:.3f} | "
            f"{a.mean * 1e3:.3f} |"
        )
    nearest = softrod.calibrate(START, data, ["E", "a"], metric="nearest")
    print("nearest:", {k: f"{100 * (v / TRUE[k] - 1):+.3f} %" for k, v in nearest.values.items()})
    figures(out, photos, backbones, fit)

    # The scatter over repeated photo sets against the reported standard errors.
    errs, ses = [], []
    for seed in range(10, 90, 10):
        _, bbs = photographs(seed)
        f = softrod.calibrate(START, list(zip(TENSIONS, bbs, strict=True)), ["E", "a"])
        errs.append([f.values[k] / TRUE[k] - 1 for k in TRUE])
        ses.append([f.standard_errors[k] / TRUE[k] for k in TRUE])
    errs, ses = np.array(errs), np.array(ses)
    print("photo sets:", len(errs))
    print("rms relative error E, a:", np.sqrt(np.mean(errs**2, axis=0)))
    print("median relative standard error E, a:", np.median(ses, axis=0))

    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        softrod.calibrate(START, data, ["youngs_modulus", "tension_scale"])
    print("E with a tension scale:", [str(x.message) for x in w])


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("docs/figures"))
