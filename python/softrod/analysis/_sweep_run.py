"""Running a sweep: the plan of tasks, the task itself, and the schedulers.

A *piece* is a contiguous range ``[a0, a1)`` of the actuation samples (in solve order) of one
design point ``d``, cut at multiples of the warm-start block so that the results do not
depend on the cut (``docs/sweeps.md``). A *task* is a list of pieces of at most ``chunk``
samples; it ships the robot (pickled) and its pieces' samples and returns arrays. The same
task function runs in-process (all cores, rayon inside the core) and on Dask workers (one
core per task).
"""

from __future__ import annotations

import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _core
from .._core import ConvergenceError, ParameterError

#: Samples per task in-process (the progress bar advances per task).
LOCAL_CHUNK = 4096
#: Most samples per task on a cluster, and tasks per worker thread aimed at by default.
CLUSTER_MAX_CHUNK = 16384
CLUSTER_TASKS_PER_THREAD = 16
#: Times a failed Dask task is retried (a lost worker is handled by the scheduler).
TASK_RETRIES = 3

#: Values of a sweep's ``status`` variable.
STATUS = {"converged": 0, "not_converged": 1, "failed": 2, "infeasible_design": 3}


@dataclass(frozen=True)
class Piece:
    """Samples ``[a0, a1)`` (solve order) of design point ``d`` with parameters ``values``;
    ``rows`` are the actuation values of those samples, shape (a1 - a0, n_axes)."""

    d: int
    values: dict
    a0: int
    a1: int
    rows: np.ndarray


@dataclass(frozen=True)
class TaskSpec:
    """What every task needs besides its pieces.

    Attributes:
        axes: ``(kind, index)`` of each actuation column (``"tension"``, ``"pressure"``,
            ``"tip_force"``, ``"tip_moment"``).
        outputs: Output names understood by the core.
        arc_lengths: Arc lengths (m), or None to use ``arm_index``.
        arm_index: Fractions of each design's length (with ``arc_lengths`` None).
        block: Rows per warm-started block.
    """

    axes: tuple[tuple[str, int], ...]
    outputs: tuple[str, ...]
    arc_lengths: tuple[float, ...] | None
    arm_index: tuple[float, ...]
    block: int


def align(chunk: int, block: int) -> int:
    """``chunk`` rounded up to a whole number of blocks."""
    return max(1, -(-int(chunk) // block)) * block


def plan(n_design: int, n_act: int, chunk: int, block: int) -> list[list[tuple[int, int, int]]]:
    """Tasks of pieces ``(d, a0, a1)``: each design's samples cut every ``chunk`` (a multiple
    of ``block``), consecutive pieces packed into tasks of at most ``chunk`` samples."""
    chunk = align(chunk, block)
    tasks: list[list[tuple[int, int, int]]] = []
    current: list[tuple[int, int, int]] = []
    size = 0
    for d in range(n_design):
        for a0 in range(0, n_act, chunk):
            a1 = min(a0 + chunk, n_act)
            if current and size + (a1 - a0) > chunk:
                tasks.append(current)
                current, size = [], 0
            current.append((d, a0, a1))
            size += a1 - a0
    if current:
        tasks.append(current)
    return tasks


def design_robot(robot, values: dict):
    """The robot of a design point and the message of its infeasibility (None if feasible):
    ``with_parameters`` and the core's model validation, without a solve."""
    # (A grid is of floats: whole values go in as integers, which an integer parameter such as
    # solver.steps needs and a float parameter reads exactly; a fractional value for an
    # integer parameter is left for the robot file to refuse.)
    values = {k: int(v) if float(v).is_integer() else v for k, v in values.items()}
    try:
        r = robot.with_parameters(values) if values else robot
        _core._sweep([_job(r, np.zeros((0, 0)), TaskSpec((), (), (), (), 1))], outputs=[])
    except (ParameterError, ConvergenceError) as exc:
        # (The design's values are the axes' own, not an argument `values` of the user's.)
        message = " ".join(str(exc).split()).removeprefix("`values`: ")
        return None, message
    return r, None


def _job(robot, rows: np.ndarray, spec: TaskSpec) -> dict:
    """The core's job dict of ``robot`` for actuation ``rows``."""
    n = len(rows)
    tendons, chambers = list(robot.tendons), list(robot.chambers)
    tensions = np.tile([t.tension for t in tendons], (n, 1)).reshape(n, len(tendons))
    pressures = np.tile([c.pressure for c in chambers], (n, 1)).reshape(n, len(chambers))
    loads = {"tip_force": None, "tip_moment": None}
    for col, (kind, index) in enumerate(spec.axes):
        if kind == "tension":
            tensions[:, index] = rows[:, col]
        elif kind == "pressure":
            pressures[:, index] = rows[:, col]
        else:
            if loads[kind] is None:
                loads[kind] = np.tile(np.asarray(getattr(robot.loads, kind), float), (n, 1))
            loads[kind][:, index] = rows[:, col]
    if spec.arc_lengths is not None:
        arcs = np.asarray(spec.arc_lengths, float)
    else:
        arcs = np.asarray(spec.arm_index, float) * robot.rod.length
    return {
        "rod": robot.rod,
        "tendons": tendons,
        "chambers": chambers,
        "loads": robot.loads,
        "options": robot.solver,
        "samples": n,
        "tensions": np.ascontiguousarray(tensions, float),
        "pressures": np.ascontiguousarray(pressures, float),
        "tip_force": loads["tip_force"],
        "tip_moment": loads["tip_moment"],
        "arc_lengths": arcs,
        "obstacles": list(robot.obstacles) or None,
        "tip_constraint": robot.tip_constraint,
    }


def run_task(robot, spec: TaskSpec, pieces: Sequence[Piece], parallel: bool) -> list[dict]:
    """Solves the pieces of one task; one result dict per piece (``infeasible``: the message
    of an infeasible design, else the core's arrays)."""
    robots: dict[int, tuple[Any, str | None]] = {}
    results: list[dict] = [{} for _ in pieces]
    jobs, where = [], []
    for k, piece in enumerate(pieces):
        if piece.d not in robots:
            robots[piece.d] = design_robot(robot, piece.values)
        r, message = robots[piece.d]
        if message is not None:
            results[k] = {"infeasible": message}
            continue
        jobs.append(_job(r, piece.rows, spec))
        where.append(k)
    if jobs:
        out = _core._sweep(jobs, outputs=list(spec.outputs), block=spec.block, parallel=parallel)
        for k, arrays in zip(where, out, strict=True):
            results[k] = arrays
    return results


def _progress(total: int, progress: bool | None, desc: str):
    from tqdm.auto import tqdm

    return tqdm(
        total=total,
        desc=desc,
        unit="config",
        disable=(None if progress is None else not progress),
        file=sys.stderr,
    )


def run_local(robot, spec, tasks, pieces_of, progress):
    """Runs the tasks in this process, in order (all cores inside each task)."""
    total = sum(a1 - a0 for t in tasks for (_, a0, a1) in t)
    bar = _progress(total, progress, "sweep")
    try:
        for t in tasks:
            pieces = pieces_of(t)
            yield t, run_task(robot, spec, pieces, True)
            bar.update(sum(p.a1 - p.a0 for p in pieces))
    finally:
        bar.close()


def client_of(scheduler):
    """A Dask client for ``scheduler`` and whether this call owns it (and must close it).

    Raises:
        ParameterError: Not a Client, a cluster, or an address string.
    """
    try:
        from distributed import Client
    except ImportError as exc:  # pragma: no cover - dask is a dependency
        raise ImportError("scheduler= needs dask: pip install 'dask[distributed]'") from exc
    if isinstance(scheduler, Client):
        return scheduler, False
    if isinstance(scheduler, str) and re.match(r"[a-z][a-z0-9+.-]*://\S+\Z", scheduler):
        return Client(scheduler), True
    if not isinstance(scheduler, str) and hasattr(scheduler, "scheduler_address"):
        return Client(scheduler), True
    exc = ParameterError(
        f"invalid parameter `scheduler` = {scheduler!r}: must be None (all cores of this "
        "process), a distributed.Client, a cluster (e.g. LocalCluster) or an address "
        "'tcp://host:port'"
    )
    exc.parameter = "scheduler"
    raise exc


def cluster_threads(client) -> int:
    """Worker threads of the cluster (at least 1)."""
    try:
        info = client.scheduler_info()
        return max(1, sum(w.get("nthreads", 1) for w in info.get("workers", {}).values()))
    except Exception:  # the number is only a default for the chunk size
        return 1


def worker_version() -> str:
    """The softrod version of the process (run on each Dask worker)."""
    return _core.__version__


def run_dask(client, robot, spec, tasks, pieces_of, progress, token: str):
    """Submits every task (retried on failure; a lost worker's tasks are rescheduled by the
    scheduler) and yields results as they complete."""
    from distributed import as_completed

    versions = client.run(worker_version)
    other = {a: v for a, v in versions.items() if v != _core.__version__}
    if other:
        addr, v = next(iter(other.items()))
        raise RuntimeError(
            f"the Dask worker {addr} runs softrod {v}, this process {_core.__version__}: "
            "install the same softrod on every worker (results would differ)"
        )
    if progress is not False:
        link = getattr(client, "dashboard_link", None)
        print(
            f"softrod sweep: {len(tasks)} tasks on {client.scheduler.address}"
            + (f"; dashboard: {link}" if link else ""),
            file=sys.stderr,
        )
    futures = {}
    for i, t in enumerate(tasks):
        fut = client.submit(
            run_task,
            robot,
            spec,
            pieces_of(t),
            False,
            key=f"softrod-sweep-{token}-{i}",
            retries=TASK_RETRIES,
            pure=False,
        )
        futures[fut] = t
    total = sum(a1 - a0 for t in tasks for (_, a0, a1) in t)
    bar = _progress(total, progress, "sweep (dask)")
    try:
        for fut in as_completed(futures):
            t = futures[fut]
            yield t, fut.result()
            bar.update(sum(a1 - a0 for (_, a0, a1) in t))
            fut.release()
    finally:
        bar.close()
