"""``softrod backbone``: the backbone of an arm in a top-view photograph."""

from __future__ import annotations

import json
import os
import sys

import numpy as np

from ._common import add_figure_options, bad, figure_options, files, save_figure, use_agg


def _same_file(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def _check_outputs(args) -> None:
    """Refuses an output that is the photo itself, or an existing file without --overwrite
    (the checks every command shares, :func:`softrod.cli._common.check_files`, ran before)."""
    for flag in ("csv", "json", "plot"):
        path = getattr(args, flag)
        if not path:
            continue
        if _same_file(path, args.photo):
            raise bad(f"--{flag}", path, "is the input PHOTO; refusing to overwrite it")
        if not args.overwrite and os.path.exists(path):
            raise bad(f"--{flag}", path, "exists (pass --overwrite to replace it)")


def _summary(bb) -> str:
    q = bb.quality
    u = bb.unit
    lines = [
        f"backbone: {len(bb)} points, base to tip, length {bb.length:.6g} {u}",
        f"base (px): ({bb.base[0]:.2f}, {bb.base[1]:.2f}) [{q.base_source}]"
        + (f", extrapolated over {q.extrapolated_length:.1f} px" if q.base_extrapolated else ""),
        f"tip: ({bb.tip[0]:.6g}, {bb.tip[1]:.6g}) {u}; tip (px): "
        f"({bb.pixels[-1, 0]:.2f}, {bb.pixels[-1, 1]:.2f}) [{q.tip_source}]",
        f"direction (px): ({bb.direction[0]:.4f}, {bb.direction[1]:.4f}) [{q.direction_source}]",
        f"half-width: base {bb.half_width[0]:.4g} {u}, tip {bb.half_width[-1]:.4g} {u}",
        f"arm {q.polarity}, contrast {q.contrast:.3g}, noise {q.noise:.2g}; "
        f"coverage {q.coverage:.1%}, tube fill {q.tube_fill:.1%}, fit residual "
        f"{q.fit_residual:.3f} px, {q.edge_outliers} one-edge sections, "
        f"{q.discarded_components} discarded components",
    ]
    lines += [f"warning: {w}" for w in q.warnings]
    return "\n".join(lines)


def _cmd_backbone(args) -> int:
    from ..vision import extract_backbone, read_image

    if not os.path.isfile(args.photo):
        raise bad("PHOTO", args.photo, "is not a file")
    _check_outputs(args)
    image = read_image(args.photo)
    if args.base is not None and np.all(np.isfinite(args.base)):  # NaN: named by the library
        from ..vision.extract import base_out_of_reach

        why = base_out_of_reach(np.asarray(args.base, dtype=float), image.shape)
        if why is not None:
            raise bad("--base", args.base, why)
    bb = extract_backbone(
        image,
        scale=args.scale,
        base=args.base,
        direction=args.direction,
        n_points=args.points,
    )
    print(_summary(bb))
    if args.csv:
        bb.to_csv(args.csv, overwrite=args.overwrite)
        print(f"wrote {args.csv}", file=sys.stderr)
    if args.json:
        with open(args.json, "w" if args.overwrite else "x", encoding="utf-8") as fh:
            json.dump({"photo": os.path.abspath(args.photo), **bb.to_dict()}, fh)
        print(f"wrote {args.json}", file=sys.stderr)
    if args.plot:
        from ..vision import plot_backbone_overlay

        use_agg()
        fig = plot_backbone_overlay(bb, image, **figure_options(args))
        save_figure(fig, args.plot, args=args)
    return 0


def register(sub) -> None:
    """Adds the ``backbone`` subcommand to the ``softrod`` parser."""
    p = sub.add_parser(
        "backbone",
        help="extract an arm's backbone from a top-view photo (CSV, JSON, overlay PNG)",
        description=(
            "Extracts the backbone of an arm from a top-view photo on a contrasting background. "
            "Pixel coordinates are (column, row), rows downward. With --scale the points are in "
            "metres in the arm's frame: origin at the base, x along --direction, y turned +90 "
            "degrees from it as seen on the image (toward the top for a rightward direction)."
        ),
    )
    p.add_argument("photo", metavar="PHOTO", help="image file (PNG, JPEG, TIFF, ...)")
    p.add_argument(
        "--scale", type=float, metavar="M_PER_PX", help="metres per pixel (default: pixels)"
    )
    p.add_argument(
        "--base",
        type=float,
        nargs=2,
        metavar=("COL", "ROW"),
        help="base point in pixels, within one image diagonal outside the photo (default: the "
        "end at the image border, else the wider end)",
    )
    p.add_argument(
        "--direction",
        type=float,
        nargs=2,
        metavar=("DX", "DY"),
        help="unloaded arm direction in pixels, DX along columns, DY along rows "
        "(default: the tangent at the base)",
    )
    p.add_argument("--points", type=int, metavar="N", help="number of output points")
    p.add_argument("--csv", metavar="FILE", help="write the points (and half-widths) to CSV")
    p.add_argument("--json", metavar="FILE", help="write the backbone and its report to JSON")
    p.add_argument("--plot", metavar="FILE", help="figure of the curve and edges over the photo")
    p.add_argument(
        "--overwrite", action="store_true", help="replace existing output files (never PHOTO)"
    )
    p.set_defaults(func=_cmd_backbone)
    files(p, outputs=("csv", "json", "plot"), figures=("plot",))
    add_figure_options(p, "plot")
