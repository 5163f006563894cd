"""``softrod calibrate``: robot parameters fitted to measured backbones or tips."""

from __future__ import annotations

import os
import sys
import warnings

from ._common import bad, files, resolve_robot, write_json

PLANAR = ("planar", "published-arm", "seed-arm")


def _pairs(items, option: str, count: int | None = None) -> dict[str, tuple[float, ...]]:
    out: dict[str, tuple[float, ...]] = {}
    for item in items or ():
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise bad(option, item, "must be NAME=VALUE" + (":VALUE" if count == 2 else ""))
        try:
            numbers = tuple(float(v) for v in value.split(":"))
        except ValueError:
            raise bad(option, item, "values must be numbers") from None
        if count is not None and len(numbers) != count:
            raise bad(option, item, f"must give {count} number(s) after `=`")
        out[name] = numbers
    return out


def _measurements(items, unit_scale: float, dim: int):
    from ..io import read_backbone_csv

    data = []
    for item in items:
        actuation, sep, path = item.rpartition(":")
        if not sep or not actuation or not path:
            raise bad("--measurements", item, "must be TENSIONS:FILE (tensions comma-separated)")
        try:
            tensions = [float(v) for v in actuation.split(",")]
        except ValueError:
            raise bad("--measurements", item, "tensions must be comma-separated numbers") from None
        if not os.path.isfile(path):
            raise bad("--measurements", item, f"{path!r} is not a file")
        points = read_backbone_csv(path, scale=unit_scale)  # 2 or 3 columns (x, y[, z])
        if points.shape[1] < dim:
            raise bad(
                "--measurements",
                item,
                f"{path!r} has {points.shape[1]} columns: a robot file's backbone needs "
                f"{dim} (x, y, z) per point",
            )
        data.append((tensions, points[:, :dim]))
    return data


def resolve(args) -> None:
    """``ROBOT`` as a robot file (``args.robot_file``) unless it names the planar arm."""
    args.robot_file = None if args.robot in PLANAR else resolve_robot(args.robot)


def _input_paths(args):
    """The files calibrate reads: ROBOT (unless the planar arm) and the FILE of every
    TENSIONS:FILE, for the output checks every command shares (an output equal to any of them
    is refused, even with --overwrite)."""
    resolve(args)
    if args.robot_file:
        yield "ROBOT", args.robot_file
    for item in args.measurements or ():
        path = item.rpartition(":")[2]
        if path:
            yield "--measurements", path


def _cmd_calibrate(args) -> int:
    import numpy as np

    from .. import IdentifiabilityWarning, PlanarCableArm, calibrate
    from ..robot import load_robot

    resolve(args)
    planar = args.robot in PLANAR
    robot = PlanarCableArm.published_arm() if planar else load_robot(args.robot_file)
    if planar and args.write_robot:
        raise bad("--write-robot", args.write_robot, "needs a robot file (not the planar arm)")
    if not 1 <= args.starts <= 1000:
        raise bad("--starts", args.starts, "in [1, 1000]")
    data = _measurements(args.measurements, args.unit_scale, 2 if planar else 3)
    if planar:
        for tensions, _ in data:
            if len(tensions) != 1:
                raise bad("--measurements", tensions, "the planar arm takes one tension")
        data = [(t[0], p) for t, p in data]
    bounds = {k: v for k, v in _pairs(args.bounds, "--bounds", 2).items()}
    initial = {k: v[0] for k, v in _pairs(args.initial, "--initial", 1).items()}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", IdentifiabilityWarning)
        fit = calibrate(
            robot,
            data,
            args.parameters,
            bounds=bounds or None,
            metric=args.metric,
            initial=initial or None,
            starts=args.starts,
        )
    for w in caught:
        print(f"softrod: warning: {w.message}", file=sys.stderr)
    ci = fit.interval(0.95)
    width = max(len(k) for k in fit.values)
    print(
        f"{'parameter':{width}s}  {'start':>12s}  {'fitted':>12s}  {'std error':>10s}  "
        "95 % interval"
    )
    for k, v in fit.values.items():
        lo, hi = ci[k]
        print(
            f"{k:{width}s}  {fit.initial[k]:12.6g}  {v:12.6g}  {fit.standard_errors[k]:10.3g}  "
            f"[{lo:.6g}, {hi:.6g}]"
        )
    if len(fit.starts) > 1:
        fitted = [st for st in fit.starts if "rms" in st]
        best = next(i for i, st in enumerate(fit.starts) if st["initial"] == fit.initial)
        print(
            f"starts: {len(fitted)} of {len(fit.starts)} fitted (the others refused by the "
            f"model), rms from {min(st['rms'] for st in fitted):.3g} to "
            f"{max(st['rms'] for st in fitted):.3g} m; the fit above is from start {best + 1}"
        )
    if len(fit.values) > 1:
        print("correlation:")
        for k, row in zip(fit.values, fit.correlation, strict=True):
            print(f"  {k:{width}s}  " + "  ".join(f"{x:+.3f}" for x in row))
    rms = [float(np.sqrt(np.mean(np.square(r)))) for r in fit.residuals]
    print(
        f"rms residual {fit.rms:.3g} m (per measurement: {', '.join(f'{r:.3g}' for r in rms)}); "
        f"{fit.evaluations} evaluations; identifiable: {fit.identifiable} "
        f"(condition {fit.condition:.3g})"
    )
    if args.json:
        write_json(
            args.json,
            {
                "parameters": list(fit.parameters),
                "values": fit.values,
                "initial": fit.initial,
                "standard_errors": fit.standard_errors,
                "interval_95": {k: list(v) for k, v in ci.items()},
                "correlation": fit.correlation.tolist(),
                "rms": fit.rms,
                "residual_std": fit.residual_std,
                "rms_per_measurement": rms,
                "condition": fit.condition,
                "identifiable": fit.identifiable,
                "metric": fit.metric,
                "evaluations": fit.evaluations,
                "starts": fit.starts,
            },
        )
    if args.write_robot:
        fit.robot.write_toml(args.write_robot, overwrite=args.overwrite)
        print(f"wrote {args.write_robot}", file=sys.stderr)
    return 0


def register(sub) -> None:
    """Adds the ``calibrate`` subcommand to the ``softrod`` parser."""
    p = sub.add_parser(
        "calibrate",
        help="fit robot parameters to measured backbones (values, standard errors, correlation)",
        description=(
            "Fits named parameters of a robot to measured backbones by bounded least squares "
            "with exact Jacobians. ROBOT is a robot file or example name, or `planar` for the "
            "planar cable-arm paper's arm. Each measurement is TENSIONS:FILE, the tensions (N, "
            "comma-separated, one per tendon) and a CSV of backbone points (x, y for the planar "
            "arm, x, y, z for a robot file: the first columns; base first; metres, or see "
            "--unit-scale), e.g. the CSV of `softrod backbone --scale`."
        ),
    )
    p.add_argument("robot", metavar="ROBOT", help="robot file, example name, or `planar`")
    p.add_argument(
        "--measurements",
        nargs="+",
        required=True,
        metavar="TENSIONS:FILE",
        help="actuation and backbone CSV of each measurement",
    )
    p.add_argument(
        "--parameters",
        nargs="+",
        required=True,
        metavar="NAME",
        help="parameters to fit (robot-file paths such as rod.material.youngs_modulus, or "
        "youngs_modulus, offset_ratio, tension_scale, ...; see docs/calibration.md)",
    )
    p.add_argument(
        "--metric", choices=("arm-index", "nearest"), default="arm-index", help="residual metric"
    )
    p.add_argument("--bounds", nargs="+", metavar="NAME=LO:HI", help="bounds of parameters")
    p.add_argument("--initial", nargs="+", metavar="NAME=VALUE", help="starting values")
    p.add_argument(
        "--starts",
        type=int,
        default=1,
        metavar="N",
        help="starts of the fit: the first from the robot (or --initial), the others drawn in "
        "the bounds; the best fit is reported (default 1)",
    )
    p.add_argument(
        "--unit-scale",
        type=float,
        default=1.0,
        metavar="FACTOR",
        help="factor on the CSV coordinates (1e-3 for millimetres)",
    )
    p.add_argument("--json", metavar="FILE", help="write the fit to JSON")
    p.add_argument("--write-robot", metavar="FILE", help="write the calibrated robot file")
    p.add_argument("--overwrite", action="store_true", help="replace existing output files")
    p.set_defaults(func=_cmd_calibrate, robot_file=None)
    files(p, outputs=("json", "write_robot"), input_paths=_input_paths)
