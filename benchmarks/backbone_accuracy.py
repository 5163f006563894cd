"""Accuracy of backbone extraction on rendered photos, and the figure of docs/backbone.md.

Run from the repository root: ``python benchmarks/backbone_accuracy.py`` (a minute or two).
Prints, for every case of the tests (``tests/test_backbone.py``, same renders and seeds), the
centreline's RMS and maximum distance (px) from the true backbone over 95 % of the arm
length, the tip distance (px) and the half-width error (px, mean and max over the middle
90 %); writes ``docs/figures/backbone_overlay.png`` and the sample photo of the docs,
``photos/cable-arm-2N.jpg`` of the package data (the arm at 2 N, 0.3 MP, JPEG quality 90).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import imageio.v3 as iio
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from arm_photos import SIZES, centreline_errors, render_published_arm, thin_radius  # noqa: E402

import softrod  # noqa: E402


def _row(name, photo, bb, keep=(0.025, 0.975)):
    e = centreline_errors(photo, bb.pixels, keep=keep)
    u = photo.s / photo.length
    mid = (bb.arm_index > 0.05) & (bb.arm_index < 0.95)
    dh = bb.half_width_px[mid] - np.interp(bb.arm_index[mid], u, photo.radius)
    print(
        f"| {name} | {e['rms']:.3f} | {e['max']:.3f} | {e['tip']:.3f} | "
        f"{dh.mean():+.2f} / {np.abs(dh).max():.2f} |"
    )
    return e


def main() -> None:
    print("| case | RMS (px) | max (px) | tip (px) | half-width error, mean / max (px) |")
    print("| --- | ---: | ---: | ---: | ---: |")
    worst = {"rms": 0.0, "max": 0.0, "tip": 0.0}
    for size in SIZES:
        for background in ("dark", "light"):
            for tension in (0.5, 1.0, 2.0, 3.0, 4.0):
                photo = render_published_arm(tension, size, background=background, seed=11)
                bb = softrod.extract_backbone(
                    photo.image, scale=photo.scale, base=photo.base, direction=photo.direction
                )
                e = _row(f"{size}, {background} floor, T = {tension:g} N", photo, bb)
                worst = {k: max(worst[k], e[k]) for k in worst}
    print(f"worst of the 20 cases: {worst}")
    for size in SIZES:
        for background in ("dark", "light"):
            photo = render_published_arm(1.0, size, background=background, clamp=0.04, seed=8)
            bb = softrod.extract_backbone(
                photo.image, scale=photo.scale, base=photo.base, direction=photo.direction
            )
            _row(
                f"{size}, {background} floor, clamp over 4 %, hidden part included",
                photo,
                bb,
                keep=(0.0, 0.975),
            )
    for background in ("dark", "light"):
        photo = render_published_arm(2.0, "1MP", background=background, touching=True, seed=9)
        bb = softrod.extract_backbone(
            photo.image, scale=photo.scale, base=photo.base, direction=photo.direction
        )
        _row(f"1MP, {background} floor, float touching the arm", photo, bb)
    scale = SIZES["0.3MP"][1]
    for background in ("dark", "light"):
        photo = render_published_arm(
            2.0, radius=lambda s: thin_radius(s, scale), background=background, blur=1.0, seed=3
        )
        bb = softrod.extract_backbone(photo.image, base=photo.base)
        _row(f"thin arm (5 to 3 px wide), {background} floor", photo, bb)
    for background in ("dark", "light"):
        photo = render_published_arm(
            3.0, "1MP", background=background, blur=2.0, noise=0.05, seed=7
        )
        bb = softrod.extract_backbone(photo.image, base=photo.base)
        _row(f"1MP, {background} floor, blur 2 px, noise 5 %", photo, bb)

    # The docs' sample photo, saved as a camera would (JPEG), and what comes out of it.
    photo = render_published_arm(2.0, "0.3MP", seed=11)
    out = ROOT / "python" / "softrod" / "examples" / "data" / "photos" / "cable-arm-2N.jpg"
    out.parent.mkdir(exist_ok=True)
    iio.imwrite(out, photo.image, quality=90)
    bb = softrod.extract_backbone(
        out, scale=photo.scale, base=photo.base, direction=photo.direction
    )
    _row("the sample photo, read back from JPEG", photo, bb)
    print(
        f"sample photo: scale {photo.scale!r} m/px, base {photo.base.tolist()} px, "
        f"direction {photo.direction.tolist()}"
    )

    # The figure: a photo with a clamp over the base and a float on the arm.
    photo = render_published_arm(3.0, "0.3MP", clamp=0.04, touching=True, seed=9)
    bb = softrod.extract_backbone(
        photo.image, scale=photo.scale, base=photo.base, direction=photo.direction
    )
    fig, axes = plt.subplots(
        1, 2, figsize=(12, 4.9), layout="constrained", gridspec_kw={"width_ratios": [1.45, 1]}
    )
    softrod.vision.plot_backbone_overlay(bb, photo.image, ax=axes[0])
    axes[0].set_title(
        "the cable arm at T = 3 N, rendered: clamp over the base, float on the "
        "arm, four distractors",
        fontsize=9,
    )
    ax = axes[1]
    c = photo.blobs[0][1]
    ax.imshow(photo.image, cmap="gray", interpolation="nearest")
    ax.plot(photo.centre[:, 0], photo.centre[:, 1], color="#00e676", lw=2.5, label="true")
    ax.plot(bb.pixels[:, 0], bb.pixels[:, 1], color="#ff006e", lw=1.0, label="extracted")
    d = np.gradient(bb.pixels, axis=0)
    n = np.column_stack([d[:, 1], -d[:, 0]]) / np.hypot(*d.T)[:, None]
    for sgn in (1, -1):
        e = bb.pixels + sgn * bb.half_width_px[:, None] * n
        ax.plot(e[:, 0], e[:, 1], color="#00b4d8", lw=0.9)
    j = int(np.argmin(np.hypot(*(photo.centre - c).T)))
    mid, half = 0.5 * (c + photo.centre[j]), 0.6 * np.hypot(*(c - photo.centre[j])) + 20
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] + half, mid[1] - half)
    err = centreline_errors(photo, bb.pixels)
    ax.set_title(
        f"zoom on the float: RMS {err['rms']:.2f} px, max {err['max']:.2f} px over "
        "95 % of the length",
        fontsize=9,
    )
    ax.legend(loc="lower right", fontsize=8)
    out = ROOT / "docs" / "figures" / "backbone_overlay.png"
    fig.savefig(out, dpi=110)
    print(f"wrote {out.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
