"""Robots: a rod with tendons, chambers, loads and solver options, from a file or from code.

A robot file (TOML) has the tables ``[rod]`` (with ``[rod.section]`` and ``[rod.material]``),
arrays of ``[[tendons]]`` and ``[[chambers]]``, ``[loads]`` and ``[solver]``; SI units
throughout. Its schema is :class:`softrod.io.robot_file.RobotFile` (``docs/robot-files.md``);
every error names its location in the file (``tendons[2].distance``), all errors at once.

A :class:`Robot` is immutable: :meth:`Robot.solve` takes the actuation (tendon tensions,
chamber pressures) as input, :meth:`Robot.with_parameters` returns a new validated robot with
design parameters changed (named by their path in the file), :meth:`Robot.to_toml` writes it
back, and it pickles.
"""

from __future__ import annotations

import math
import numbers
import os
import pickle
import re
from collections.abc import Mapping, Sequence
from contextlib import contextmanager
from typing import Any

import numpy as np

from . import _args
from ._core import (
    Chamber,
    Loads,
    ParameterError,
    ParameterTypeError,
    Rod,
    StaticsSolution,
    Tendon,
    _RobotModel,
    _solve_robot,
    solve_statics,
)
from .io import objects as _objects
from .io import robot_file as _rf
from .io.robot_file import FieldError, RobotFile

__all__ = ["Robot", "load_robot", "solve_path"]

# Most spacer disks ``Robot.with_disk_guides`` puts on one tendon (the guided solve is Newton
# on three force unknowns per disk; real robots carry tens).
MAX_DISKS = 1000

_PATH_PART = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)\Z")


@contextmanager
def _argument(name: str):
    """Prefixes the errors of a description given as the argument ``name`` with its name
    (their ``parameter`` and ``errors`` keep the locations inside it)."""
    try:
        yield
    except ParameterError as exc:
        if exc.args and not str(exc.args[0]).startswith(f"`{name}`"):
            exc.args = (f"`{name}`: {exc.args[0]}", *exc.args[1:])
        raise


def _parse_path(path: str) -> list[str | int]:
    """``"tendons[2].distance"`` -> ``["tendons", 2, "distance"]``."""
    if not isinstance(path, str) or not path:
        raise _bad_path(path, "a path such as `tendons[0].tension`")
    out: list[str | int] = []
    for part in path.split("."):
        m = _PATH_PART.match(part)
        if m is None:
            raise _bad_path(path, "names and [index] joined by dots, e.g. `tendons[0].tension`")
        out.append(m.group(1))
        out.extend(int(i) for i in re.findall(r"\[(\d+)\]", m.group(2)))
    return out


def canonical_path(path: str) -> str:
    """The canonical spelling of a parameter path: ``"tendons[02].tension"`` ->
    ``"tendons[2].tension"`` (indices without leading zeros).

    Raises:
        ParameterError: Not a path (see :func:`_parse_path`).
    """
    return _rf.format_location(_parse_path(path))


def _parts_or_none(path: Any) -> tuple[str | int, ...] | None:
    try:
        return tuple(_parse_path(path))
    except ParameterError:
        return None


def _conflict(pa: tuple[str | int, ...], pb: tuple[str | int, ...]) -> str | None:
    short, long = sorted((pa, pb), key=len)
    if long[: len(short)] != short:
        return None
    where = _rf.format_location(short)
    if len(short) == len(long):
        return f"both name `{where}`"
    return f"`{_rf.format_location(long)}` is inside `{where}`"


def path_conflict(a: str, b: str) -> str | None:
    """Why the paths ``a`` and ``b`` name the same parameter, or None if they do not (or one
    does not parse): the same path spelt two ways (``tendons[0].tension``,
    ``tendons[00].tension``: "both name `tendons[0].tension`") or one inside the other
    (``rod.material``, ``rod.material.youngs_modulus``)."""
    pa, pb = _parts_or_none(a), _parts_or_none(b)
    return None if pa is None or pb is None else _conflict(pa, pb)


def same_parameter(paths: Sequence[str], name: str) -> None:
    """Refuses two paths of ``paths`` that name the same parameter (see
    :func:`path_conflict`). Paths that do not parse are left to the caller's own check.

    Raises:
        ParameterError: Naming ``name`` and both paths.
    """
    seen: list[tuple[Any, tuple[str | int, ...]]] = []
    for path in paths:
        parts = _parts_or_none(path)
        if parts is None:
            continue
        for other, known in seen:
            why = _conflict(known, parts)
            if why is not None:
                raise _args.value_error(
                    name, [other, path], f"paths naming different parameters ({why})"
                )
        seen.append((path, parts))


def _bad_path(path: Any, expected: str) -> ParameterError:
    exc = ParameterError(f"invalid parameter path {path!r}: must be {expected}")
    exc.parameter = str(path)
    return exc


def _plain(value: Any) -> Any:
    """NumPy scalars and arrays as Python numbers and lists (the schema is strict)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def _check_sequence(value: Any, kind: type, name: str) -> tuple:
    if isinstance(value, kind):
        value = (value,)
    try:
        items = tuple(value)
    except TypeError:
        raise TypeError(
            f"invalid parameter `{name}`: must be a sequence of {kind.__name__}"
        ) from None
    for i, item in enumerate(items):
        if not isinstance(item, kind):
            raise TypeError(
                f"invalid parameter `{name}[{i}]` = {item!r}: must be a softrod.{kind.__name__}"
            )
    return items


class Robot:
    """A robot: rod, tendons, chambers, external loads and solver options (immutable).

    Build one in code, ``Robot(rod, tendons=[...], chambers=[...], loads=Loads(...))``, or
    read a file with :func:`load_robot`. Actuation is an input of :meth:`solve`.

    SI units throughout (m, N, Pa, rad); tensions in N, pressures in Pa (gauge).

    Attributes:
        name: A label (a file's ``name``, or its file name).
        rod: The rod model.
        tendons: Tendons, in order (their tensions are the default actuation).
        chambers: Pneumatic chambers, in order (their pressures are the default actuation).
        loads: External loads.
        solver: Keyword arguments for :func:`softrod.solve_statics` (a copy).
        description: Free text.
        spec: The validated description (:class:`softrod.io.robot_file.RobotFile`).
        source: The description as the file's tables (a dict, ``spec`` dumped).
    """

    __slots__ = (
        "_chambers",
        "_description",
        "_loads",
        "_loads_given",
        "_model",
        "_name",
        "_obstacles",
        "_rod",
        "_solver",
        "_spec",
        "_tendons",
        "_tip_constraint",
    )

    def __init__(
        self,
        rod: Rod,
        tendons: Sequence[Tendon] = (),
        chambers: Sequence[Chamber] = (),
        loads: Loads | None = None,
        solver: Mapping[str, Any] | None = None,
        name: str = "robot",
        description: str = "",
        source: Mapping[str, Any] | None = None,
        obstacles: Sequence[Any] = (),
        tip_constraint: Any = None,
    ) -> None:
        """Builds a robot from model objects.

        Args:
            rod: The rod.
            tendons: Its tendons.
            chambers: Its pneumatic chambers.
            loads: External loads (default none).
            solver: Options of :func:`softrod.solve_statics` (``integrator``, ``steps``, ...),
                checked like a file's ``[solver]`` table.
            name: A label.
            description: Free text.
            source: A description (the file's tables) to adopt as the robot's ``spec``
                instead of reading one back from the objects; it must describe them: the
                robot it describes has the same rod, tendons, chambers, loads, solver
                options, obstacles and tip constraint (numbers equal to a relative 1e-9 of
                their vector; its ``name`` is replaced by ``name``).
            obstacles: Rigid obstacles the rod's surface touches (``softrod.Plane``,
                ``Sphere``, ``Capsule``, ``Cylinder`` or dicts with ``type``), passed to
                :func:`softrod.solve_statics` as ``obstacles=``.
            tip_constraint: ``softrod.Clamp(pose)``, ``Pin(point)`` or ``Slide(point,
                normal)`` (default a free tip), passed as ``tip_constraint=``.

        Raises:
            TypeError: An argument of the wrong type (named).
            ParameterError: Bad solver options (located, e.g. ``solver.steps``); a
                ``source`` that is invalid or does not describe the objects (naming
                ``source``, the first field that differs and both values).
        """
        if not isinstance(rod, Rod):
            raise _args.type_error("rod", rod, "a softrod.Rod")
        if loads is not None and not isinstance(loads, Loads):
            raise _args.type_error("loads", loads, "a softrod.Loads")
        if not isinstance(name, str):
            raise _args.type_error("name", name, "a string")
        if not isinstance(description, str):
            raise _args.type_error("description", description, "a string")
        if solver is not None and not isinstance(solver, Mapping):
            raise _args.type_error("solver", solver, "a dict of solver options")
        if source is not None and not isinstance(source, Mapping):
            raise _args.type_error("source", source, "a dict (a robot file's tables)")
        options = _plain(dict(solver or {}))
        if options:
            _rf.validate_robot_dict({"rod": _MINIMAL_ROD, "solver": options})
        self._set(
            name,
            description,
            rod,
            _check_sequence(tendons, Tendon, "tendons"),
            _check_sequence(chambers, Chamber, "chambers"),
            loads if loads is not None else Loads(),
            loads is not None,
            options,
            None,
        )
        from .plot.obstacles import as_obstacles

        object.__setattr__(self, "_obstacles", tuple(as_obstacles(obstacles)))
        from .contact import Clamp, Pin, Slide

        if tip_constraint is not None and not isinstance(tip_constraint, (Clamp, Pin, Slide)):
            exc = ParameterTypeError(
                f"tip_constraint = {tip_constraint!r} is invalid: must be softrod.Clamp(pose), "
                "softrod.Pin(point), softrod.Slide(point, normal) or None"
            )
            exc.parameter = "tip_constraint"
            raise exc
        object.__setattr__(self, "_tip_constraint", tip_constraint)
        if source:
            with _argument("source"):
                spec = _rf.validate_robot_dict(_plain(dict(source)))
            _check_source(self, spec)
            object.__setattr__(self, "_spec", spec.model_copy(update={"name": name}))

    def _set(self, name, description, rod, tendons, chambers, loads, given, solver, spec):
        for key, value in (
            ("_name", name),
            ("_description", description),
            ("_rod", rod),
            ("_tendons", tendons),
            ("_chambers", chambers),
            ("_loads", loads),
            ("_loads_given", given),
            ("_solver", solver),
            ("_spec", spec),
            ("_obstacles", ()),
            ("_tip_constraint", None),
            ("_model", None),
        ):
            object.__setattr__(self, key, value)

    def __setattr__(self, key: str, value: Any) -> None:
        raise AttributeError("Robot is immutable (use with_parameters, with_tensions, ...)")

    # ------------------------------------------------------------------ construction

    @classmethod
    def from_spec(cls, spec: RobotFile, *, name: str = "robot", source: str | None = None) -> Robot:
        """Builds the robot of a validated description (``name`` if it has none).

        Raises:
            ParameterError: Every constructor error, located in the file (``errors``).
        """
        if not isinstance(spec, RobotFile):
            raise _args.type_error("spec", spec, "a RobotFile (softrod.io.robot_file)")
        if not isinstance(name, str):
            raise _args.type_error("name", name, "a string")
        if spec.name is None:
            spec = spec.model_copy(update={"name": name})
        parts = _objects.build(spec, source)
        robot = object.__new__(cls)
        robot._set(
            spec.name,
            spec.description,
            parts.rod,
            parts.tendons,
            parts.chambers,
            parts.loads,
            spec.loads is not None,
            parts.solver,
            spec,
        )
        object.__setattr__(robot, "_obstacles", parts.obstacles)
        object.__setattr__(robot, "_tip_constraint", parts.tip_constraint)
        return robot

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], name: str = "robot") -> Robot:
        """Builds a robot from a parsed description (the TOML file's tables).

        Raises:
            ParameterError: Every error of the description (``errors``, each located).
        """
        if not isinstance(data, Mapping):
            raise _args.type_error("data", data, "a dict (a robot file's tables)")
        with _argument("data"):
            spec = _rf.validate_robot_dict(_plain(data))
        return cls.from_spec(spec, name=name)

    @classmethod
    def from_toml(cls, text: str, name: str = "robot") -> Robot:
        """Builds a robot from the text of a robot file."""
        if not isinstance(text, str):
            raise _args.type_error("text", text, "the text of a robot file (a string)")
        with _argument("text"):
            try:
                data = _rf.tomllib.loads(text)
            except _rf.tomllib.TOMLDecodeError as exc:
                _rf.raise_errors([FieldError("", f"not valid TOML: {exc}", kind="type")])
            spec = _rf.validate_robot_dict(_plain(data))
        return cls.from_spec(spec, name=name)

    # ------------------------------------------------------------------ attributes

    name = property(lambda self: self._name, doc="A label.")
    description = property(lambda self: self._description, doc="Free text.")
    rod = property(lambda self: self._rod, doc="The rod model.")
    tendons = property(lambda self: self._tendons, doc="Tendons, in order.")
    chambers = property(lambda self: self._chambers, doc="Pneumatic chambers, in order.")
    loads = property(lambda self: self._loads, doc="External loads.")
    obstacles = property(lambda self: self._obstacles, doc="Obstacles the rod touches.")
    tip_constraint = property(
        lambda self: self._tip_constraint, doc="The tip constraint (None: a free tip)."
    )

    @property
    def solver(self) -> dict[str, Any]:
        """Keyword arguments for :func:`softrod.solve_statics` (a copy)."""
        return dict(self._solver)

    @property
    def spec(self) -> RobotFile:
        """The validated description of this robot.

        Raises:
            ParameterError: For a robot built in code whose objects cannot be described (a
                Python callable, or properties the model objects do not expose yet).
        """
        if self._spec is None:
            spec = _objects.describe(*self._parts())
            extra: dict[str, Any] = {}
            if self._obstacles:
                extra["obstacles"] = [_objects.obstacle_spec(o) for o in self._obstacles]
            if self._tip_constraint is not None:
                extra["tip_constraint"] = _objects.tip_constraint_spec(self._tip_constraint)
            if extra:
                checked = _rf.validate_robot_dict({"rod": _MINIMAL_ROD, **extra})
                spec = spec.model_copy(update={k: getattr(checked, k) for k in extra})
            object.__setattr__(self, "_spec", spec)
        return self._spec

    @property
    def source(self) -> dict[str, Any]:
        """The description as the file's tables (empty if the robot cannot be described)."""
        try:
            spec = self.spec
        except ParameterError:
            return {}
        return spec.model_dump(mode="python", exclude_unset=True, exclude_none=True)

    # ------------------------------------------------------------------ solving

    def solve(
        self,
        tensions: Sequence[float] | np.ndarray | None = None,
        pressures: Sequence[float] | np.ndarray | None = None,
        *,
        displacements: Sequence[float | None] | np.ndarray | None = None,
        tendon_stiffness: float | Sequence[float] | np.ndarray | None = None,
        **options: Any,
    ) -> StaticsSolution:
        """Solves the statics under an actuation.

        Args:
            tensions: Tendon tensions (N), one per tendon; default the robot's.
            pressures: Chamber pressures (Pa, gauge), one per chamber; default the robot's.
            displacements: Tendon displacement control: one entry per tendon, a number (m)
                holds the tendon's base end at that shortening of its path relative to the
                robot at zero actuation (negative: paid out), ``None`` (or NaN) keeps it
                tension-controlled at ``tensions``. A held tendon that would be compressed goes
                slack (tension 0); the solved tensions are ``solution.tendon_tensions``.
            tendon_stiffness: Axial stiffness of the held tendons (N/m; one number or one per
                tendon; default inextensible).
            **options: Options of :func:`softrod.solve_statics` overriding the robot's
                (``steps``, ``warm_start``, ``throw``, ...); ``previous``: the frictional
                solution this actuation follows (stick and slip depend on it; see
                :func:`solve_path`).

        Returns:
            The solution.

        Raises:
            ParameterError: Bad actuation (wrong count) or options.
            ConvergenceError: The solver did not converge (unless ``throw=False``).
        """
        if options and not _MODEL_KEYS.isdisjoint(options):
            return self._solve_objects(
                tensions, pressures, displacements, tendon_stiffness, options
            )
        # The core model is validated once and shared; the actuation is an input of the core.
        merged = {**self._solver, **options} if options else self._solver
        if self._obstacles or self._tip_constraint is not None:
            merged = dict(merged)
            if self._obstacles:
                merged.setdefault("obstacles", list(self._obstacles))
            if self._tip_constraint is not None:
                merged.setdefault("tip_constraint", self._tip_constraint)
        try:
            return _solve_robot(
                self._model or self._core_model(),
                tensions,
                pressures,
                displacements=displacements,
                tendon_stiffness=tendon_stiffness,
                **merged,
            )
        except TypeError as err:
            # A misspelt option: name the method the user called, not the core function.
            text = str(err)
            if type(err) is TypeError and text.startswith("_solve_robot()"):
                raise TypeError("Robot.solve()" + text.removeprefix("_solve_robot()")) from None
            raise

    def _core_model(self) -> _RobotModel:
        """The validated core model of the rod, tendons, loads and chambers (built once)."""
        model = _RobotModel(self._rod, self._tendons, self._loads, self._chambers)
        object.__setattr__(self, "_model", model)
        return model

    def _solve_objects(self, tensions, pressures, displacements, tendon_stiffness, options):
        """``solve`` with model objects among the options (``chambers=``): the objects at
        this actuation, solved by :func:`softrod.solve_statics`."""
        tendons = self._tendons if tensions is None else self._tensioned(tensions)
        chambers = self._chambers if pressures is None else self._pressurised(pressures)
        merged = {**self._solver, **options}
        if chambers:
            merged.setdefault("chambers", chambers)
        if self._obstacles:
            merged.setdefault("obstacles", list(self._obstacles))
        if self._tip_constraint is not None:
            merged.setdefault("tip_constraint", self._tip_constraint)
        if displacements is not None:
            merged["displacements"] = displacements
        if tendon_stiffness is not None:
            merged["tendon_stiffness"] = tendon_stiffness
        return solve_statics(self._rod, tendons, self._loads, **merged)

    def _tensioned(self, tensions: Any) -> tuple[Tendon, ...]:
        values = _actuation(tensions, len(self._tendons), "tensions", "tendon")
        return tuple(t.with_tension(x) for t, x in zip(self._tendons, values, strict=True))

    def _pressurised(self, pressures: Any) -> tuple[Chamber, ...]:
        values = _actuation(pressures, len(self._chambers), "pressures", "chamber")
        return tuple(c.with_pressure(p) for c, p in zip(self._chambers, values, strict=True))

    def _replace(self, **changes: Any) -> Robot:
        new = object.__new__(Robot)
        state = {k: getattr(self, k) for k in Robot.__slots__}
        state.update({f"_{k}": v for k, v in changes.items()})
        state["_model"] = None  # built again from the new objects
        for k, v in state.items():
            object.__setattr__(new, k, v)
        return new

    def _with_actuation(self, field: str, key: str, items: tuple) -> Robot:
        """A copy with new tendons or chambers, their tensions or pressures also written into
        the description (when there is one)."""
        spec = self._spec
        if spec is not None:
            tables = [
                t.model_copy(update={key: float(getattr(new, key))})
                for t, new in zip(getattr(spec, field), items, strict=True)
            ]
            spec = spec.model_copy(update={field: tables})
        return self._replace(**{field: items, "spec": spec})

    def with_tensions(self, tensions: Sequence[float] | np.ndarray) -> Robot:
        """The same robot with new tendon tensions.

        Args:
            tensions: Tensions (N), one per tendon: a 1-D list, tuple or array of real
                numbers (NumPy scalars included).

        Returns:
            The new robot, its description updated.

        Raises:
            ParameterTypeError: Not 1-D (naming ``tensions``, the shape given and the one
                expected), or an entry that is a string, a boolean or None (naming
                ``tensions[i]``).
            ParameterError: Another count than one per tendon, or a tension out of range.
        """
        return self._with_actuation("tendons", "tension", self._tensioned(tensions))

    def with_pressures(self, pressures: Sequence[float] | np.ndarray) -> Robot:
        """The same robot with new chamber pressures.

        Args:
            pressures: Gauge pressures (Pa), one per chamber: a 1-D list, tuple or array of
                real numbers (NumPy scalars included).

        Returns:
            The new robot, its description updated.

        Raises:
            ParameterTypeError: Not 1-D (naming ``pressures``, the shape given and the one
                expected), or an entry that is a string, a boolean or None (naming
                ``pressures[i]``).
            ParameterError: Another count than one per chamber, or a pressure out of range.
        """
        return self._with_actuation("chambers", "pressure", self._pressurised(pressures))

    def with_disk_guides(
        self,
        spacing: float,
        *,
        friction: float = 0.0,
        tendons: Sequence[int] | None = None,
    ) -> Robot:
        """The same robot with its tendons run through spacer disks instead of channels.

        Disks stand every ``spacing`` along the rod, at ``s = spacing, 2 spacing, ...``; each
        chosen tendon passes through the disks strictly between the base and its end, in
        straight chords between the base, the disks and its termination, with capstan
        coefficient ``friction`` at each disk (``docs/friction.md``, "Disk-guided tendons").
        Where ``spacing`` divides a tendon's span, its disks are at ``end * k / n`` exactly
        (``n = end / spacing``).

        Args:
            spacing: Disk spacing (m), > 0 and below every chosen tendon's span, with at most
                1,000 disks on a span.
            friction: Capstan coefficient at each disk (>= 0).
            tendons: Indices of the tendons to guide (default: all); each must be a
                ``constant`` routing (a fixed offset from the backbone).

        Returns:
            The new robot (this one is unchanged), its description updated.

        Raises:
            ParameterError: Naming ``spacing``, ``friction`` or ``tendons`` (an index out of
                range, a repeated index, or a routing other than ``constant``).
        """
        spacing = _args.number(spacing, "spacing", positive=True, unit="m")
        friction = _args.number(friction, "friction")
        if friction < 0:
            raise _args.value_error("friction", friction, ">= 0")
        n = len(self._tendons)
        if tendons is None:
            chosen = list(range(n))
        else:
            if isinstance(tendons, (str, bytes)) or not isinstance(tendons, Sequence):
                raise _args.type_error("tendons", tendons, "a sequence of tendon indices")
            chosen = [_args.count(i, f"tendons[{k}]", 0, n - 1) for k, i in enumerate(tendons)]
            if len(set(chosen)) != len(chosen):
                raise _args.value_error("tendons", list(tendons), "distinct tendon indices")
        spec = self.spec
        length = float(spec.rod.length)
        values: dict[str, Any] = {}
        for i in chosen:
            table = spec.tendons[i]
            if table.routing != "constant":
                raise _args.value_error(
                    f"tendons[{i}].routing",
                    table.routing,
                    "`constant` (disk guides hold a tendon at a fixed offset)",
                )
            end = length if table.end is None else float(table.end)
            ratio = end / spacing
            if ratio > MAX_DISKS + 1:
                raise _args.value_error(
                    "spacing",
                    spacing,
                    f">= {end / (MAX_DISKS + 1):g} m (at most {MAX_DISKS} disks on the "
                    f"{end:g} m span of tendon {i})",
                )
            whole = round(ratio)
            if whole >= 1 and abs(ratio - whole) <= 1e-9 * ratio:
                guides = [end * k / whole for k in range(1, whole)]
            else:
                guides = [k * spacing for k in range(1, math.floor(ratio) + 1)]
            if not guides:
                raise _args.value_error(
                    "spacing", spacing, f"< {end:g} m (the span of tendon {i}) for one disk"
                )
            values[f"tendons[{i}].guides"] = guides
            values[f"tendons[{i}].guide_friction"] = friction
        return self.with_parameters(values)

    # ------------------------------------------------------------------ design parameters

    def parameter(self, path: str) -> Any:
        """One value of the robot's description, by its path in the file.

        Args:
            path: E.g. ``"rod.material.youngs_modulus"``, ``"tendons[2].distance"``,
                ``"chambers[1].pressure"``, ``"loads.tip_force"``, ``"rod.length"``.

        Returns:
            The value (defaults filled in; ``None`` for an optional value not given).

        Raises:
            ParameterError: A path that is not in the description (with a suggestion).
        """
        node: Any = self.spec
        walked: list[str | int] = []
        for part in _parse_path(path):
            if isinstance(part, int):
                if not isinstance(node, list) or not 0 <= part < len(node):
                    size = len(node) if isinstance(node, list) else 0
                    raise _bad_path(
                        path, f"an index in [0, {size}) for `{_rf.format_location(walked)}`"
                    )
                node = node[part]
            else:
                fields = type(node).model_fields if isinstance(node, _rf.BaseModel) else {}
                if part not in fields:
                    hint = _rf._suggest(part, list(fields))
                    where = _rf.format_location(walked) or "the robot"
                    known = (
                        f"; did you mean `{hint}`?" if hint else f" (known: {', '.join(fields)})"
                    )
                    raise _bad_path(path, f"a key of {where}{known}")
                node = getattr(node, part)
            walked.append(part)
        if isinstance(node, _rf.BaseModel):
            return node.model_dump(mode="python", exclude_none=True)
        return node

    def with_parameters(self, values: Mapping[str, Any]) -> Robot:
        """A new robot with parameters of the description changed, validated and rebuilt.

        Args:
            values: Path -> new value, paths as in the robot file: ``rod.section.tip_radius``,
                ``tendons[2].distance``, ``rod.material.youngs_modulus``,
                ``tendons[0].tension``, ``chambers[1].pressure``, a whole table
                (``rod.material``) or a list entry (``loads.tip_force[2]``).

        Returns:
            The new robot (this one is unchanged).

        Raises:
            ParameterError: Any invalid value, unknown key (with a suggestion) or index out
                of range, all reported at once at their paths; two paths naming the same
                parameter (``tendons[0].tension`` and ``tendons[00].tension``, or a table
                and a value inside it), both named.
        """
        if not isinstance(values, Mapping):
            raise _args.type_error("values", values, "a dict: parameter path -> value")
        if len(values) > 1:
            same_parameter(list(values), "values")
        data = self.spec.model_dump(mode="python", exclude_unset=True, exclude_none=True)
        errors: list[FieldError] = []
        for path, value in values.items():
            try:
                _set_path(data, _parse_path(path), _plain(value))
            except ParameterError as exc:
                errors.append(FieldError(str(path), str(exc), None, "unknown_key"))
        with _argument("values"):
            try:
                spec = _rf.validate_robot_dict(data)
            except ParameterError as exc:
                _rf.raise_errors([*errors, *exc.errors])
            if errors:
                _rf.raise_errors(errors)
        return Robot.from_spec(spec, name=self._name)

    # ------------------------------------------------------------------ files

    def to_toml(self) -> str:
        """The robot as the text of a robot file (``load_robot`` reads it back equal).

        Raises:
            ParameterError: For a robot built in code that cannot be described (named).
        """
        return _rf.dump_robot_toml(self.spec)

    def write_toml(self, path: str | os.PathLike[str], *, overwrite: bool = False) -> None:
        """Writes the robot file.

        Args:
            path: The ``.toml`` file.
            overwrite: Replace an existing file (default: refuse).

        Raises:
            FileExistsError: ``path`` exists and ``overwrite`` is false.
            ParameterError: The robot cannot be described (see :meth:`to_toml`).
        """
        path = _args.path(path)
        overwrite = _args.flag(overwrite, "overwrite")
        text = self.to_toml()
        with open(path, "w" if overwrite else "x", encoding="utf-8") as fh:
            fh.write(text)

    # ------------------------------------------------------------------ protocol

    def _described(self) -> RobotFile | None:
        try:
            return self.spec
        except ParameterError:
            return None

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Robot):
            return NotImplemented
        a, b = self._described(), other._described()
        if a is not None and b is not None:
            return a == b
        return (
            self._name == other._name
            and self._description == other._description
            and _same_object(self._rod, other._rod)
            and len(self._tendons) == len(other._tendons)
            and all(map(_same_object, self._tendons, other._tendons))
            and len(self._chambers) == len(other._chambers)
            and all(map(_same_object, self._chambers, other._chambers))
            and _same_object(self._loads, other._loads)
            and self._solver == other._solver
            and self._obstacles == other._obstacles
            and _same_object(self._tip_constraint, other._tip_constraint)
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return (
            f"Robot(name={self._name!r}, rod={self._rod!r}, tendons={len(self._tendons)}, "
            f"chambers={len(self._chambers)})"
        )

    def _parts(self) -> tuple:
        """The constructor arguments: rod, tendons, chambers, loads, solver, name,
        description."""
        loads = self._loads if self._loads_given else None
        return (
            self._rod,
            self._tendons,
            self._chambers,
            loads,
            self._solver,
            self._name,
            self._description,
        )

    def __reduce__(self):
        # A mesh read from a file travels as its vertices (the file may not be there).
        meshes = any(type(o).__name__ == "Mesh" for o in self._obstacles)
        if self._tip_constraint is not None or (self._obstacles and (self._spec is None or meshes)):
            return (_rebuild, (self._parts(), self._obstacles, self._tip_constraint))
        if self._spec is not None:
            return (_from_pickled_spec, (self._spec,))
        parts = self._parts()
        try:
            pickle.dumps(parts)
        except (TypeError, pickle.PicklingError, AttributeError):
            try:
                return (_from_pickled_spec, (self.spec,))
            except ParameterError as exc:
                raise pickle.PicklingError(f"cannot pickle this Robot: {exc}") from None
        return (Robot, parts)


def _same_object(a: Any, b: Any) -> bool:
    """Whether two model objects of the core (which compare by identity) are one object or
    hold the same data: the same type and equal pickles (their constructor arguments; a
    Python callable by its qualified name). An object that does not pickle (a lambda) equals
    itself only."""
    if a is b:
        return True
    if type(a) is not type(b):
        return False
    try:
        return pickle.dumps(a) == pickle.dumps(b)
    except (TypeError, pickle.PicklingError, AttributeError):
        return False


# Relative difference (to the largest magnitude of the vector) within which a number of a
# ``source`` equals the objects' (the degrees and polar offsets of a file round to it).
_SOURCE_RTOL = 1e-9

# The arguments of ``Robot`` each top-level table of a description describes.
_SOURCE_TABLES = ("rod", "tendons", "chambers", "loads", "solver", "obstacles", "tip_constraint")


def _described_objects(parts: Sequence[Any]) -> dict[str, Any]:
    """The tables of a robot's objects (rod, tendons, chambers, loads, solver, obstacles,
    tip constraint), read back from the objects and filled with defaults.

    Raises:
        ParameterError: Objects a robot file cannot describe (``missing``,
            ``unserialisable``).
    """
    rod, tendons, chambers, loads, solver, obstacles, tip = parts
    spec = _objects.describe(rod, tendons, chambers, loads, solver, "robot", "")
    tables = spec.model_dump(mode="python", exclude_none=True)
    out = {k: tables.get(k) for k in _SOURCE_TABLES}
    out["obstacles"] = [_objects.obstacle_spec(o) for o in obstacles]
    out["tip_constraint"] = None if tip is None else _objects.tip_constraint_spec(tip)
    return out


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _is_numeric(v: Any) -> bool:
    if isinstance(v, list):
        return bool(v) and all(_is_numeric(x) for x in v)
    return _is_number(v)


def _first_difference(a: Any, b: Any, where: list[str | int]) -> tuple | None:
    """The first location where two described tables differ, and both values there."""
    if isinstance(a, dict) or isinstance(b, dict):
        if (a is None or isinstance(a, dict)) and (b is None or isinstance(b, dict)):
            a, b = a or {}, b or {}
            for key in [*a, *(k for k in b if k not in a)]:
                found = _first_difference(a.get(key), b.get(key), [*where, key])
                if found is not None:
                    return found
            return None
        return where, a, b
    if _is_numeric(a) and _is_numeric(b):
        try:
            x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        except ValueError:  # ragged
            return None if a == b else (where, a, b)
        if x.shape != y.shape:
            return where, a, b
        scale = max(float(np.max(np.abs(x))), float(np.max(np.abs(y))))
        return None if np.all(np.abs(x - y) <= _SOURCE_RTOL * scale) else (where, a, b)
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return where, _Count(len(a)), _Count(len(b))
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            found = _first_difference(x, y, [*where, i])
            if found is not None:
                return found
        return None
    return None if a == b else (where, a, b)


class _Count(int):
    def __repr__(self) -> str:
        return f"{int(self)} {'entry' if self == 1 else 'entries'}"


def _shown(value: Any) -> str:
    if value is None:
        return "not given"
    text = " ".join(repr(value).split())
    return text if len(text) <= 80 else text[:77] + "..."


def _source_error(detail: str) -> ParameterError:
    exc = ParameterError(
        f"invalid parameter `source`: must describe the objects given with it; {detail} "
        "(Robot.from_dict(source) builds the robot a description describes)"
    )
    exc.parameter = "source"
    return exc


def _check_source(robot: Robot, spec: RobotFile) -> None:
    """Refuses a ``source`` that does not describe the robot's objects: the robot it
    describes is built and both sets of objects are read back as tables, then compared.

    Raises:
        ParameterError: Naming ``source``, the first field that differs and both values.
    """
    with _argument("source"):
        parts = _objects.build(spec)
    ours = (
        robot._rod,
        robot._tendons,
        robot._chambers,
        robot._loads,
        robot._solver,
        robot._obstacles,
        robot._tip_constraint,
    )
    theirs = (
        parts.rod,
        parts.tendons,
        parts.chambers,
        parts.loads,
        parts.solver,
        parts.obstacles,
        parts.tip_constraint,
    )
    try:
        want = _described_objects(theirs)
        have = _described_objects(ours)
    except ParameterError as exc:
        if getattr(exc, "unserialisable", None) or not getattr(exc, "missing", None):
            why = str(exc).split(": ", 1)[-1]
            raise _source_error(f"a robot file cannot describe these objects: {why}") from None
        # Properties the objects do not expose: compare the objects themselves.
        for key, a, b in zip(_SOURCE_TABLES, theirs, ours, strict=True):
            if isinstance(a, tuple):
                same = len(a) == len(b) and all(map(_same_object, a, b))
            else:
                same = a == b if isinstance(a, dict) else _same_object(a, b)
            if not same:
                raise _source_error(f"its `{key}` is not the `{key}` given") from None
        return
    for key in _SOURCE_TABLES:
        found = _first_difference(want[key], have[key], [key])
        if found is not None:
            where, a, b = found
            raise _source_error(
                f"`{_rf.format_location(where)}` is {_shown(a)} in `source` but {_shown(b)} "
                f"in `{key}`"
            )


def _rebuild(parts: tuple, obstacles: tuple, tip_constraint: Any) -> Robot:
    robot = Robot(*parts)
    object.__setattr__(robot, "_obstacles", obstacles)
    object.__setattr__(robot, "_tip_constraint", tip_constraint)
    return robot


def _from_pickled_spec(spec: RobotFile) -> Robot:
    return Robot.from_spec(spec)


# Options that replace the robot's objects: solved by ``solve_statics`` with the objects.
_MODEL_KEYS = frozenset(("rod", "tendons", "loads", "chambers"))

_MINIMAL_ROD = {
    "length": 1.0,
    "section": {"radius": 1.0},
    "material": {"youngs_modulus": 1.0},
}


_UNITS = {"tendon": "N", "chamber": "Pa"}


def _shape_text(values: Any) -> str:
    try:
        return str(np.shape(values))
    except ValueError:  # ragged nesting
        return "a ragged nesting"


def _nested(v: Any) -> bool:
    if isinstance(v, np.ndarray):
        return v.ndim > 0
    return isinstance(v, Sequence) and not isinstance(v, (str, bytes))


def _actuation(values: Any, n: int, name: str, what: str) -> list[float]:
    """One real number per tendon or chamber (``what``), as floats: a 1-D list, tuple or
    array of ints and floats (NumPy scalars included).

    Raises:
        ParameterTypeError: Not a 1-D sequence (naming ``name``, the shape given and the one
            expected), or an entry that is a string, a boolean, None or not real (naming
            ``name[i]``).
        ParameterError: A 1-D sequence of another length.
    """
    unit = _UNITS.get(what, "")
    expected = f"one number per {what} ({unit}), shape ({n},)"
    if values is None or isinstance(values, (str, bytes, Mapping)):
        raise _args.type_error(name, values, expected)
    if isinstance(values, np.ndarray):
        if values.ndim != 1:
            raise _args.type_error(name, values, f"{expected}, not shape {values.shape}")
        items: list[Any] = values.tolist() if values.dtype.kind in "iuf" else list(values)
    else:
        try:
            items = list(values)
        except TypeError:
            raise _args.type_error(
                name, values, f"{expected}, not shape {_shape_text(values)}"
            ) from None
        if any(_nested(v) for v in items):
            raise _args.type_error(name, values, f"{expected}, not shape {_shape_text(values)}")
    for i, v in enumerate(items):
        if isinstance(v, np.ndarray) and v.dtype.kind in "iuf":  # 0-d
            items[i] = v = v.item()
        if (
            v is None
            or isinstance(v, (bool, np.bool_, str, bytes))
            or not isinstance(v, numbers.Real)
        ):
            raise _args.type_error(f"{name}[{i}]", v, f"a number ({unit})")
    if len(items) != n:
        exc = ParameterError(
            f"invalid parameter `{name}` = {len(items)} values: must be one value per {what} ({n})"
        )
        exc.parameter = name
        raise exc
    return [float(v) for v in items]


def _set_path(data: dict[str, Any], parts: list[str | int], value: Any) -> None:
    """Sets ``value`` at a path of nested tables and arrays, creating missing tables."""
    node: Any = data
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        where = _rf.format_location(parts[: i + 1])
        if isinstance(part, int):
            if not isinstance(node, list) or not 0 <= part < len(node):
                size = len(node) if isinstance(node, list) else 0
                raise ParameterError(f"no entry `{where}` (the robot has {size})")
        elif not isinstance(node, dict):
            raise ParameterError(f"`{_rf.format_location(parts[:i])}` is not a table")
        if last:
            node[part] = value
        else:
            if isinstance(part, str) and part not in node:
                node[part] = {}
            node = node[part]


def load_robot(path: str | os.PathLike[str]) -> Robot:
    """Reads a robot description file (TOML).

    Args:
        path: The ``.toml`` file (see :mod:`softrod.examples` for the shipped ones).

    Returns:
        The robot, ready to :meth:`Robot.solve`; named by the file's ``name`` or its stem.

    Raises:
        OSError: The file cannot be read.
        ParameterError: A file that is not UTF-8 TOML, or every missing, unknown or invalid
            field of it, located (``errors`` lists them, ``parameter`` is the first).
    """
    name = os.fspath(_args.path(path))
    data = _rf.read_robot_toml(path)
    stem = os.path.splitext(os.path.basename(name))[0]
    spec = _rf.validate_robot_dict(data, source=name)
    return Robot.from_spec(spec, name=stem, source=name)


def solve_path(
    robot: Robot,
    actuations: Sequence[Sequence[float]] | np.ndarray,
    pressures: Sequence[Sequence[float]] | np.ndarray | None = None,
    **options: Any,
) -> list[StaticsSolution]:
    """Solves a quasi-static actuation path: each step from the equilibrium of the one before.

    With tendon friction (a tendon with ``friction > 0``) the tension along each tendon
    depends on the history: every tendon element slides toward the base, toward the tip, or
    sticks, according to the change of its tension from the previous step
    (``docs/friction.md``). The first step starts from rest (every element sliding toward
    the base). Without friction every step is the frictionless equilibrium.

    Args:
        robot: The robot.
        actuations: Tendon tensions (N), shape (n_steps, n_tendons).
        pressures: Chamber pressures (Pa), shape (n_steps, n_chambers); default the robot's.
        **options: Options of :meth:`Robot.solve` (not ``previous``).

    Returns:
        One solution per step.

    Raises:
        ParameterError: Bad actuations (shape, values) or options.
        ConvergenceError: A step did not converge (unless ``throw=False``).
    """
    if not isinstance(robot, Robot):
        raise ParameterError(f"robot = {robot!r}: expected a softrod.Robot")
    if "previous" in options:
        raise ParameterError("previous: not an option of solve_path (each step follows the last)")
    try:
        table = np.asarray(actuations, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(
            f"actuations = {actuations!r}: expected tensions (N), shape (n_steps, n_tendons)"
        ) from None
    nt = len(robot.tendons)
    if table.ndim != 2 or table.shape[1] != nt:
        raise ParameterError(
            f"actuations.shape = {table.shape}: expected (n_steps, {nt}) tensions (N)"
        )
    if pressures is not None:
        try:
            ptable = np.asarray(pressures, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(
                f"pressures = {pressures!r}: expected pressures (Pa), shape (n_steps, n_chambers)"
            ) from None
        if ptable.ndim != 2 or ptable.shape[0] != table.shape[0]:
            raise ParameterError(
                f"pressures.shape = {ptable.shape}: expected ({table.shape[0]}, n_chambers)"
            )
    out: list[StaticsSolution] = []
    for k, row in enumerate(table):
        p = None if pressures is None else ptable[k]
        previous = out[-1] if out and out[-1].frictional else None
        out.append(robot.solve(row, p, previous=previous, **options))
    return out
