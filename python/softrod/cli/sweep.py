"""``softrod sweep``: a design study of a robot file, written to NetCDF.

Grids on the command line: ``PATH=start:stop:count`` (``count`` values from ``start`` to
``stop``, both included), ``PATH=v1,v2,...`` (a list) or ``PATH=v`` (one value). Actuation:
``--tensions I=GRID`` (tendon ``I``), ``--pressures I=GRID`` (chamber ``I``) and
``--actuation PATH=GRID`` (any actuation path, e.g. ``loads.tip_force[1]``); design:
``--design PATH=GRID`` (any robot-file path).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

from .. import _args
from ._common import NoResultError, bad, files, finite_float

_GRID_HELP = "GRID: start:stop:count, v1,v2,... or one value"


def parse_grid(option: str, text: str) -> tuple[str, list[float]]:
    """``"PATH=GRID"`` -> ``(PATH, values)``.

    Raises:
        ParameterError: Naming the option: no ``=``, an empty path, a grid that is not
            numbers, a count < 1 or more than :data:`softrod._args.MAX_GRID_VALUES` points
            (refused before the grid is built).
    """
    if "=" not in text:
        raise bad(option, text, f"PATH=GRID ({_GRID_HELP})")
    path, grid = (part.strip() for part in text.split("=", 1))
    if not path:
        raise bad(option, text, "a path before `=`")
    span: tuple[float, float, int] | None = None
    try:
        if ":" in grid:
            start, stop, count = grid.split(":")
            span = (float(start), float(stop), int(count))
        else:
            values = [float(v) for v in grid.split(",")]
    except ValueError:
        raise bad(option, text, f"PATH=GRID with numbers ({_GRID_HELP})") from None
    if span is not None:
        a, b, n = span
        if n < 1:
            raise bad(option, text, "a count >= 1 after the second `:`")
        if n > _args.MAX_GRID_VALUES:  # before the grid is built
            raise bad(option, text, _too_many(f"a grid of {n} points"))
        values = [a] if n == 1 else [a + (b - a) * k / (n - 1) for k in range(n)]
    if not all(math.isfinite(v) for v in values):
        raise bad(option, text, "finite numbers")
    return path, values


def _too_many(count: str) -> str:
    """Worded like the library's refusal (``softrod.sweep``, ``softrod workspace``)."""
    return f"{count}: must be at most {_args.MAX_GRID_VALUES} points"


def _axes(args) -> tuple[dict, dict]:
    """The actuation and design grids of the options, each path given once, at most
    :data:`softrod._args.MAX_GRID_VALUES` points in all (checked as each grid is read)."""
    from ..robot import path_conflict

    actuation: dict[str, list[float]] = {}
    design: dict[str, list[float]] = {}
    given: list[tuple[str, str]] = []  # (option, path as given)
    points = 1

    def add(target: dict, option: str, text: str, path: str, values: list[float]) -> None:
        nonlocal points
        for first_option, first in given:
            why = path_conflict(first, path) if first != path else f"both name `{path}`"
            if why is not None:
                raise bad(option, path, f"a path given once ({first_option} gave {first!r}: {why})")
        points *= len(values)
        if points > _args.MAX_GRID_VALUES:
            raise bad(option, text, _too_many(f"{points} points with the grids before it"))
        given.append((option, path))
        target[path] = values

    for text in args.tensions or ():
        key, values = parse_grid("--tensions", text)
        if not key.isdigit():
            raise bad("--tensions", text, "I=GRID with a tendon index I (0, 1, ...)")
        add(actuation, "--tensions", text, f"tendons[{int(key)}].tension", values)
    for text in args.pressures or ():
        key, values = parse_grid("--pressures", text)
        if not key.isdigit():
            raise bad("--pressures", text, "I=GRID with a chamber index I (0, 1, ...)")
        add(actuation, "--pressures", text, f"chambers[{int(key)}].pressure", values)
    for text in args.actuation or ():
        add(actuation, "--actuation", text, *parse_grid("--actuation", text))
    for text in args.design or ():
        add(design, "--design", text, *parse_grid("--design", text))
    return actuation, design


def _scheduler(text: str | None):
    """``None``, ``local:N`` (a LocalCluster of N worker processes, closed after) or an
    address."""
    if text is None:
        return None, None
    if text.startswith("local:"):
        try:
            n = int(text.split(":", 1)[1])
        except ValueError:
            n = 0
        if n < 1:
            raise bad("--scheduler", text, "local:N with N >= 1 worker processes")
        from distributed import LocalCluster

        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True)
        return cluster, cluster
    if "://" not in text:
        raise bad("--scheduler", text, "an address tcp://host:port, or local:N")
    return text, None


def _cmd_sweep(args) -> int:
    from ..analysis.sweep import STATUS, sweep
    from ..robot import load_robot

    if not args.out.endswith(".nc"):
        raise bad("--out", args.out, "a NetCDF file name ending in .nc")
    if os.path.exists(args.out) and not args.overwrite:
        raise bad("--out", args.out, "exists (pass --overwrite to replace it)")
    actuation, design = _axes(args)
    robot = load_robot(args.robot)
    outputs = [o.strip() for o in args.outputs.split(",") if o.strip()]
    scheduler, cluster = _scheduler(args.scheduler)
    t0 = time.perf_counter()
    try:
        ds = sweep(
            robot,
            actuation=actuation or None,
            design=design or None,
            outputs=outputs,
            arc_lengths=args.arc_lengths,
            arm_index=args.arm_index,
            scheduler=scheduler,
            chunk=args.chunk,
            block=args.block,
            progress=True if args.progress else None,
        )
    finally:
        if cluster is not None:
            cluster.close()
    elapsed = time.perf_counter() - t0
    status = ds["status"].values
    n = status.size
    counts = {k: int((status == v).sum()) for k, v in STATUS.items()}
    infeasible = int(ds["design_status"].values.sum())
    where = "in this process" if scheduler is None else f"on {args.scheduler}"
    print(f"robot: {robot.name} ({args.robot})")
    n_design = ds["design_status"].size
    print(
        f"sweep: {n} samples = {n_design} design points x {n // n_design} actuations "
        f"in {elapsed:.3f} s {where}"
    )
    print(f"  design: {ds.attrs['design_dims'] or '(the robot)'}")
    print(f"  actuation: {ds.attrs['actuation_dims'] or '(the robot file)'}")
    print(
        f"status: {counts['converged']} converged, {counts['not_converged']} not converged, "
        f"{counts['failed']} failed, {counts['infeasible_design']} in {infeasible} infeasible "
        "design points"
    )
    if counts["converged"] + counts["not_converged"] == 0:
        errors = [str(e) for e in np.ravel(ds["design_error"].values) if e]
        if "error" in ds:
            errors += [str(e) for e in np.ravel(ds["error"].values) if e]
        first = f"; the first: {errors[0]}" if errors else ""
        raise NoResultError(
            f"sweep of {robot.name}: no sample was solved (every one failed or is in an "
            f"infeasible design){first}; nothing written"
        )
    folder = os.path.dirname(os.path.abspath(args.out))
    tmp = os.path.join(folder, f".{os.path.basename(args.out)}.{os.getpid()}.tmp")
    try:
        ds.to_netcdf(tmp, engine="netcdf4")
        if os.path.exists(args.out) and not args.overwrite:  # appeared meanwhile
            raise bad("--out", args.out, "exists (pass --overwrite to replace it)")
        os.replace(tmp, args.out)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    print(f"wrote {args.out}", file=sys.stderr)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Adds ``sweep``."""
    from ..analysis.sweep import DEFAULT_BLOCK

    sw = sub.add_parser(
        "sweep",
        help="design study: sweep design parameters and actuation, write NetCDF",
        description="Solves a robot file over design and actuation grids (their outer "
        "product) and writes the labelled result (xarray Dataset) to NetCDF. "
        f"{_GRID_HELP}. Results do not depend on --scheduler or --chunk.",
    )
    sw.add_argument("robot", metavar="ROBOT", help="robot file (.toml) or example name")
    sw.add_argument(
        "--design",
        action="append",
        metavar="PATH=GRID",
        help="a design axis, e.g. rod.section.tip_radius=0.004:0.012:9 (repeatable)",
    )
    sw.add_argument(
        "--tensions",
        action="append",
        metavar="I=GRID",
        help="tensions of tendon I (N), e.g. 0=0:2:21 (repeatable)",
    )
    sw.add_argument(
        "--pressures",
        action="append",
        metavar="I=GRID",
        help="pressures of chamber I (Pa, gauge), e.g. 0=0:3e4:7 (repeatable)",
    )
    sw.add_argument(
        "--actuation",
        action="append",
        metavar="PATH=GRID",
        help="any actuation axis, e.g. loads.tip_force[1]=0:0.1:5 (repeatable)",
    )
    sw.add_argument(
        "--outputs",
        default="tip_pose,convergence",
        metavar="NAMES",
        help="outputs separated by commas (default: %(default)s): tip_pose, tendon_lengths, "
        "backbone, compliance, stiffness, gamma_c, eigen_stiffness, translational_compliance, "
        "convergence",
    )
    at = sw.add_mutually_exclusive_group()
    at.add_argument(
        "--arc-lengths",
        type=finite_float,
        nargs="+",
        metavar="S",
        help="arc lengths (m) of the outputs along the rod",
    )
    at.add_argument(
        "--arm-index",
        type=finite_float,
        nargs="+",
        metavar="U",
        help="instead, fractions of the rod's length (default: 1, the tip)",
    )
    sw.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="a Dask scheduler tcp://host:port, or local:N for N local worker processes "
        "(default: this process, all cores)",
    )
    sw.add_argument("--chunk", type=int, help="samples per task (default: automatic)")
    sw.add_argument(
        "--block",
        type=int,
        default=DEFAULT_BLOCK,
        help="samples per warm-started block (default: %(default)s)",
    )
    sw.add_argument("--out", required=True, metavar="FILE.nc", help="the NetCDF file to write")
    sw.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    sw.add_argument(
        "--progress",
        action="store_true",
        help="progress bar on stderr (default: only when stderr is a terminal)",
    )
    files(sw, inputs=("robot",), outputs=("out",), folders=())
    sw.set_defaults(func=_cmd_sweep)
