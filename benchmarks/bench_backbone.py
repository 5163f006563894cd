"""Benchmark of backbone extraction from photos; prints a table of medians and accuracies.

Run: ``python benchmarks/bench_backbone.py`` (after ``pip install .``). The photos are the
tests' renders of the planar cable-arm paper's arm (``tests/arm_photos.py``): shading, blur,
noise, uneven lighting and five distractors. Side by side, the same photos through a plain
pipeline that stops at the skeleton (global Otsu threshold, largest component, full-resolution
skeleton, longest path), to show what the tube fit costs and buys.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from _timing import median_time

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from arm_photos import centreline_errors, render_published_arm
from scipy import ndimage
from skimage.filters import threshold_otsu

import softrod
from softrod.vision.centreline import _skeleton_path
from softrod.vision.segment import segment, to_grey


def skeleton_only(image: np.ndarray) -> np.ndarray:
    """The plain pipeline: Otsu, largest component, skeleton, longest path (col, row)."""
    g = to_grey(image)
    t = threshold_otsu(g)
    fg = g > t if np.median(g) < t else g < t
    lab, _ = ndimage.label(fg)
    areas = np.bincount(lab.ravel())
    areas[0] = 0
    arm = ndimage.binary_fill_holes(lab == np.argmax(areas))
    return _skeleton_path(arm)  # skeletonize, then the longest path


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--repeats", type=int, default=9)
    p.add_argument("--quick", action="store_true", help="fewer repeats (smoke run)")
    args = p.parse_args()
    reps = 3 if args.quick else args.repeats

    rows: list[tuple[str, float, str, str]] = []
    for size, tension, kw in [
        ("0.3MP", 2.0, {}),
        ("1MP", 2.0, {}),
        ("1MP", 4.0, {"background": "light"}),
        ("1MP", 1.0, {"clamp": 0.04}),
    ]:
        photo = render_published_arm(tension, size, seed=1, **kw)
        h, w = photo.image.shape
        label = f"{size} ({w}x{h}), T = {tension:g} N" + "".join(
            f", {k} {v}" for k, v in kw.items()
        )

        def run(photo=photo):
            return softrod.extract_backbone(
                photo.image, scale=photo.scale, base=photo.base, direction=photo.direction
            )

        keep = (0.045, 0.975) if kw.get("clamp") else (0.025, 0.975)
        t = median_time(run, calls=1, repeats=reps)
        e = centreline_errors(photo, run().pixels, keep=keep)
        acc = f"{e['rms']:.3f} / {e['max']:.3f} / {e['tip']:.3f}"
        rows.append((f"extract_backbone, {label}", t * 1e3, "ms", acc))
        if not kw:
            g = to_grey(photo.image)
            t = median_time(lambda g=g: segment(g), calls=1, repeats=reps)
            rows.append(("  of which segmentation", t * 1e3, "ms", ""))
            t = median_time(lambda photo=photo: skeleton_only(photo.image), calls=1, repeats=reps)
            e = centreline_errors(photo, skeleton_only(photo.image).astype(float), keep=keep)
            acc = f"{e['rms']:.3f} / {e['max']:.3f} / {e['tip']:.3f}"
            rows.append(("  plain skeleton pipeline, same photo", t * 1e3, "ms", acc))

    width = max(len(r[0]) for r in rows)
    print(f"softrod {softrod.__version__} backbone benchmark (median of {reps} repeats)")
    print("accuracy: centreline RMS / max over 95 % of the length / tip distance, in px")
    print(f"{'case':<{width}}  {'median':>8}  unit  accuracy (px)")
    print("-" * (width + 40))
    for name, value, unit, acc in rows:
        print(f"{name:<{width}}  {value:8.1f}  {unit:<4}  {acc}")


if __name__ == "__main__":
    main()
