"""Robot description files (TOML): the schema, reading with located errors, and writing.

The schema is a tree of pydantic models, one per table of the file (:class:`RobotFile` at the
top). Validation is strict: numbers are numbers (``true`` or ``"3"`` are not), integers are
integers, floats are finite, tables are tables, unknown keys are errors with a suggestion for
the closest known key. Every error carries its location in the file's own notation
(``tendons[2].distance``), and all errors of a file are reported together: a
:class:`softrod.ParameterError` whose ``errors`` attribute lists :class:`FieldError` records
and whose ``parameter`` is the first location. ``softrod schema`` prints the JSON Schema
(:func:`robot_file_json_schema`), also published in ``docs/robot-file.schema.json``.

Rules that tie fields together (a tendon ending past the rod's tip, gravity without a density)
are checked once the fields are valid, with the same kind of errors.

The schema is in :mod:`softrod.io.robot_schema`, the error messages in
:mod:`softrod.io.robot_errors`; both are re-exported here.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from typing import Any

from pydantic import BaseModel, ValidationError  # noqa: F401 (BaseModel re-exported)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

from .robot_errors import (  # noqa: F401 (re-exported)
    _TYPE_WORDS,
    _UNION_FIELDS,
    _UNITS,
    FieldError,
    _all_tags,
    _choices,
    _clean_loc,
    _descriptions,
    _models_at,
    _nonzero,
    _short,
    _suggest,
    _tagged,
    _toml_text,
    _translate,
    _unit,
    _unwrap,
    _unwrap_meta,
    consistency_errors,
    format_location,
    raise_errors,
    robot_file_errors,
)
from .robot_schema import (  # noqa: F401 (re-exported)
    MAX_ITERATIONS,
    MAX_LOAD_STEPS,
    MAX_STEPS,
    BasePoseSpec,
    Bool,
    CapsuleSpec,
    ChamberSpec,
    CircularSectionSpec,
    ConstantTendonSpec,
    CylinderSpec,
    Float,
    HelicalTendonSpec,
    HookeanSpec,
    Int,
    LinearisedSpec,
    LinearMaterialSpec,
    LoadsSpec,
    MaterialSpec,
    MeshSpec,
    MooneyRivlinSpec,
    NeoHookeanSpec,
    ObstacleSpec,
    OgdenSpec,
    PlaneSpec,
    PointLoadSpec,
    RadiusProportionalTendonSpec,
    RobotFile,
    RodSpec,
    SectionSpec,
    SiliconeSpec,
    SolverSpec,
    SphereSpec,
    Str,
    TableSectionSpec,
    TaperedSectionSpec,
    TendonSpec,
    TipConstraintSpec,
    TubeSectionSpec,
    Vec2,
    Vec3,
    YeohSpec,
    _exclusive,
    _num,
    _Positives,
    _silicone_key,
    _Table,
    _tag_of,
    _TendonBase,
    _union,
    _vec,
)

# The schema (robot_schema.py) and the errors (robot_errors.py) are re-exported above: every
# name this module had keeps its path (``softrod.io.robot_file.RodSpec``).

__all__ = [
    "ChamberSpec",
    "FieldError",
    "LoadsSpec",
    "RobotFile",
    "RodSpec",
    "SolverSpec",
    "dump_robot_toml",
    "read_robot_toml",
    "robot_file_errors",
    "robot_file_json_schema",
    "validate_robot_dict",
]


# ----------------------------------------------------------------------------- entry points


def validate_robot_dict(data: Any, source: str | None = None) -> RobotFile:
    """Validates a parsed description (the TOML file's tables) against the schema.

    Args:
        data: The tables, as :mod:`tomllib` reads them.
        source: The file it came from, for the message.

    Returns:
        The validated, immutable description.

    Raises:
        ParameterError: With every error in ``errors`` (:class:`FieldError`).
    """
    if not isinstance(data, Mapping):
        raise_errors([FieldError("", "must be a table of tables", data, "type")], source)
    try:
        spec = RobotFile.model_validate(dict(data))
    except ValidationError as exc:
        raise_errors(robot_file_errors(exc), source)
    errs = consistency_errors(spec)
    if errs:
        raise_errors(errs, source)
    return spec


#: Largest robot file read (bytes): the largest shipped example is a few kilobytes; tables of
#: thousands of sections or routing points stay far below it.
MAX_ROBOT_FILE_BYTES = 64 * 2**20


def read_robot_toml(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Parses a robot file into its tables (no validation).

    Raises:
        OSError: If the file cannot be read.
        ParameterError: If it is not UTF-8 text or not valid TOML (with the line).
    """
    name = os.fspath(path)
    # (A device or a pipe, e.g. /dev/zero, would be read, or waited for, forever: a robot
    # file is a regular file, and far smaller than the bound below.)
    if os.path.exists(path) and not os.path.isfile(path):
        raise_errors([FieldError("", "not a regular file", kind="type")], name)
    with open(path, "rb") as fh:
        # (Its size first: read(n) would allocate the n bytes however short the file.)
        too_large = os.fstat(fh.fileno()).st_size > MAX_ROBOT_FILE_BYTES
        raw = b"" if too_large else fh.read()
    if too_large:
        raise_errors(
            [
                FieldError(
                    "",
                    f"larger than {MAX_ROBOT_FILE_BYTES // 2**20} MiB: not a robot file",
                    kind="type",
                )
            ],
            name,
        )
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise_errors(
            [
                FieldError(
                    "",
                    f"not UTF-8 text (byte 0x{raw[exc.start]:02x} on line {line}): "
                    "a robot file is TOML, which is UTF-8",
                    kind="type",
                )
            ],
            name,
        )
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise_errors([FieldError("", f"not valid TOML: {exc}", kind="type")], name)


def robot_file_json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a robot description file."""
    schema = RobotFile.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "softrod robot description file"
    return schema


def _toml_item(value: Any) -> Any:
    import tomlkit

    if isinstance(value, Mapping):
        table = tomlkit.table()
        for k, v in value.items():
            table.add(k, _toml_item(v))
        return table
    if isinstance(value, list) and value and all(isinstance(v, Mapping) for v in value):
        aot = tomlkit.aot()
        for v in value:
            aot.append(_toml_item(v))
        return aot
    return value


def dump_robot_toml(spec: RobotFile) -> str:
    """The TOML text of a description (the keys given or set; comments are not kept).

    Tables are written as ``[rod.section]``, arrays of tables as ``[[tendons]]``, numbers
    exactly (``load_robot`` reads back the same floats).
    """
    import tomlkit

    data = spec.model_dump(mode="python", exclude_unset=True, exclude_none=True)
    doc = tomlkit.document()
    for key, value in data.items():
        if value == []:
            continue
        doc.add(key, _toml_item(value))
    return tomlkit.dumps(doc)
