"""The errors of a robot description file: the located records (:class:`FieldError`), their
translation from pydantic's validation errors in the file's own notation
(``tendons[2].distance``) with units, choices and suggestions for misspelt keys, and the
rules that tie fields together (:func:`consistency_errors`). :mod:`softrod.io.robot_file`
re-exports every name of this module.
"""

from __future__ import annotations

import difflib
import math
import typing
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Annotated, Any, Union

from pydantic import BaseModel, Discriminator, Tag, ValidationError

from .._core import ParameterError
from .robot_schema import (
    RobotFile,
    TableSectionSpec,
)


@dataclass(frozen=True)
class FieldError:
    """One error of a robot description.

    Attributes:
        location: Where, in the file's notation (``tendons[2].distance``; ``""`` for the
            whole file).
        message: What is wrong and what is valid (``must be > 0``).
        value: The offending value (``None`` when the key is missing or unknown).
        kind: A short machine-readable kind: ``missing``, ``unknown_key``, ``type``,
            ``range``, ``choice``, ``rule`` or ``model`` (rejected by the model itself).
        suggestion: For a misspelt key or choice, the closest valid one.
    """

    location: str
    message: str
    value: Any = None
    kind: str = "rule"
    suggestion: str | None = None

    def __str__(self) -> str:
        where = f"`{self.location}`" if self.location else "the file"
        if self.value is not None and self.kind not in ("missing", "unknown_key"):
            return f"{where} = {_short(self.value)}: {self.message}"
        return f"{where}: {self.message}"


def _toml_text(value: Any) -> str:
    """A value as it reads in a TOML file (``true``, ``"2"``, ``inf``, ``[1.0, 2.0]``)."""
    import json

    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, list):
        return "[" + ", ".join(_toml_text(v) for v in value) + "]"
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{k} = {_toml_text(v)}" for k, v in value.items()) + " }"
    return repr(value)


def _short(value: Any, limit: int = 60) -> str:
    text = _toml_text(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def format_location(loc: Sequence[Any]) -> str:
    """``("tendons", 2, "distance")`` -> ``"tendons[2].distance"``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


def raise_errors(errors: Sequence[FieldError], source: str | None = None) -> typing.NoReturn:
    """Raises one :class:`ParameterError` carrying every error (``errors``), the first
    location (``parameter``) and the file (``source``)."""
    errors = list(errors)
    head = f"{source}: " if source else ""
    if len(errors) == 1 and not errors[0].location:
        text = f"{head}invalid robot file: {errors[0].message}"
    elif len(errors) == 1:
        text = f"{head}invalid field {errors[0]}"
    else:
        lines = "\n".join(f"  {e}" for e in errors)
        text = f"{head}{len(errors)} invalid fields:\n{lines}"
    exc = ParameterError(text)
    exc.errors = errors
    exc.parameter = errors[0].location if errors else ""
    exc.source = source
    raise exc


# Tags of the unions, which pydantic inserts in error locations after the union's field.
_UNION_FIELDS = {"section", "material"}


def _clean_loc(loc: Sequence[Any]) -> tuple[Any, ...]:
    """Drops the union tags pydantic adds to a location (``rod.material.yeoh.c10``)."""
    out: list[Any] = []
    for i, part in enumerate(loc):
        prev = loc[i - 1] if i else None
        under_union = prev in _UNION_FIELDS or (
            isinstance(prev, int) and i >= 2 and loc[i - 2] == "tendons"
        )
        if under_union and isinstance(part, str) and not out[-1:] == [part]:
            if part in _all_tags():
                continue
        out.append(part)
    return tuple(out)


def _all_tags() -> set[str]:
    return {
        "circular",
        "tapered",
        "tube",
        "table",
        "linear",
        "neo_hookean",
        "mooney_rivlin",
        "yeoh",
        "ogden",
        "hookean",
        "linearised",
        "silicone",
        "constant",
        "radius_proportional",
        "helical",
    }


def _unwrap(tp: Any) -> list[Any]:
    """The candidate types of an annotation (Annotated, Optional and unions unwrapped)."""
    origin = typing.get_origin(tp)
    if origin is Annotated:
        return _unwrap(typing.get_args(tp)[0])
    if origin is Union or type(tp).__name__ == "UnionType":
        return [t for a in typing.get_args(tp) for t in _unwrap(a) if t is not type(None)]
    return [tp]


def _tagged(tp: Any) -> dict[str, type]:
    """Members of a tagged union by tag (empty if ``tp`` is not one)."""
    if typing.get_origin(tp) is Annotated:
        inner = typing.get_args(tp)[0]
        if typing.get_origin(inner) is Union:
            out = {}
            for member in typing.get_args(inner):
                args = typing.get_args(member)
                tags = [m for m in args[1:] if isinstance(m, Tag)]
                if tags:
                    out[tags[0].tag] = args[0]
            return out
    return {}


def _models_at(raw_loc: Sequence[Any]) -> list[type[BaseModel]]:
    """The models a raw pydantic location (with union tags) points into."""
    current: list[Any] = [RobotFile]
    for part in raw_loc:
        nxt: list[Any] = []
        for tp in current:
            tagged = _tagged(tp)
            if tagged:
                if isinstance(part, str) and part in tagged:
                    nxt.append(tagged[part])
                continue
            for t in _unwrap(tp):
                if isinstance(t, type) and issubclass(t, BaseModel) and isinstance(part, str):
                    field = t.model_fields.get(part)
                    if field is not None:
                        nxt.append(field.annotation)
                        nxt.extend(_unwrap_meta(field))
                elif typing.get_origin(t) is list and isinstance(part, int):
                    nxt.extend(typing.get_args(t))
        current = nxt
    out = []
    for tp in current:
        tagged = _tagged(tp)
        members = list(tagged.values()) if tagged else _unwrap(tp)
        out.extend(t for t in members if isinstance(t, type) and issubclass(t, BaseModel))
    return out


def _unwrap_meta(field: Any) -> list[Any]:
    """A field's annotation with its ``Annotated`` metadata restored (tagged unions keep the
    discriminator in the metadata pydantic moves out of the annotation)."""
    disc = [m for m in field.metadata if isinstance(m, Discriminator)]
    if disc and typing.get_origin(field.annotation) is Union:
        return [Annotated[(field.annotation, *disc)]]
    return []


def _suggest(word: str, candidates: Sequence[str]) -> str | None:
    """The closest candidate (case-insensitive), if close enough."""
    lower = {str(c).lower(): str(c) for c in candidates}
    close = difflib.get_close_matches(word.lower(), list(lower), n=1, cutoff=0.6)
    return lower[close[0]] if close else None


_TYPE_WORDS = {
    "float_type": "must be a number",
    "int_type": "must be an integer",
    "bool_type": "must be true or false",
    "string_type": "must be a string",
    "list_type": "must be an array",
    "model_type": "must be a table",
    "model_attributes_type": "must be a table",
    "dict_type": "must be a table",
    "finite_number": "must be a finite number",
    "float_parsing": "must be a number",
    "int_from_float": "must be an integer",
}


def _translate(err: Mapping[str, Any]) -> tuple[tuple[Any, ...], str, str, Any]:
    """(location, message, kind, value) of one pydantic error."""
    raw_loc, typ, ctx = tuple(err["loc"]), err["type"], err.get("ctx") or {}
    value = err.get("input")
    if typ in _TYPE_WORDS:
        return raw_loc, _TYPE_WORDS[typ], "type", value
    bounds = {
        "greater_than": ("> ", "gt"),
        "greater_than_equal": (">= ", "ge"),
        "less_than": ("< ", "lt"),
        "less_than_equal": ("<= ", "le"),
    }
    if typ in bounds:
        op, key = bounds[typ]
        unit = _unit(raw_loc)
        return raw_loc, f"must be {op}{ctx[key]:g}{' ' + unit if unit else ''}", "range", value
    if typ in ("too_short", "too_long"):
        lo, hi = ctx.get("min_length"), ctx.get("max_length")
        want = f"{lo} values" if lo == hi or (hi is None and typ == "too_long") else None
        if want is None:
            want = f"at least {lo} values" if typ == "too_short" else f"at most {hi} values"
        return raw_loc, f"must have {want} (got {ctx.get('actual_length')})", "type", value
    if typ == "literal_error":
        choices = ", ".join(_choices(str(ctx.get("expected", ""))))
        return raw_loc, f"must be one of {choices}", "choice", value
    if typ == "missing":
        return raw_loc, "missing (required)", "missing", None
    if typ == "extra_forbidden":
        return raw_loc, "unknown key", "unknown_key", None
    if typ == "invalid_tag":
        field = ctx.get("field", "type")
        tag = value.get(field) if isinstance(value, Mapping) else value
        return (*raw_loc, field), f"must be one of {ctx.get('expected')}", "choice", tag
    if "field" in ctx:  # a rule of one table, reported at the field it names
        msg = err["msg"]
        table_value = value if isinstance(value, Mapping) else {}
        return (*raw_loc, ctx["field"]), msg, "rule", table_value.get(ctx["field"])
    return raw_loc, err["msg"], "rule", value


_UNITS = ("m", "Pa", "N", "N m", "m^2", "m^4", "kg/m^3", "m/s^2", "N/m", "N m/m", "1/m", "deg")


def _descriptions(tp: Any) -> list[str]:
    """Descriptions found in an annotation's metadata, outermost first."""
    out = []
    if typing.get_origin(tp) is Annotated:
        args = typing.get_args(tp)
        out += [m.description for m in args[1:] if getattr(m, "description", None)]
        out += _descriptions(args[0])
    elif typing.get_origin(tp) is Union or type(tp).__name__ == "UnionType":
        for a in typing.get_args(tp):
            out += _descriptions(a)
    return out


def _unit(raw_loc: Sequence[Any]) -> str:
    """The unit in a field's description (``"radius (m)"`` -> ``"m"``), or ``""``."""
    import re

    key = raw_loc[-1] if raw_loc else None
    for model in _models_at(raw_loc[:-1]):
        field = model.model_fields.get(key) if isinstance(key, str) else None
        if field is None:
            continue
        texts = [field.description or "", *_descriptions(field.annotation)]
        texts += [m.description for m in field.metadata if getattr(m, "description", None)]
        for text in texts:
            for inner in re.findall(r"\(([^()]*)\)", text):
                unit = inner.split(",")[0].split(";")[0].strip()
                if unit in _UNITS:
                    return unit
    return ""


def _choices(message: str) -> list[str]:
    return [c.strip(" '\"") for c in message.replace(" or ", ", ").split(",") if c.strip()]


def robot_file_errors(exc: ValidationError) -> list[FieldError]:
    """The errors of a failed :class:`RobotFile` validation, located and with suggestions.

    A misspelt key and the required key it stands for (``youngs_modulu`` for
    ``youngs_modulus``) are reported as one error naming both.
    """
    raw = exc.errors(include_url=False)
    items = []
    for err in raw:
        raw_loc, msg, kind, value = _translate(err)
        items.append((raw_loc, _clean_loc(raw_loc), msg, kind, value))
    missing = {(loc[:-1], loc[-1]) for _, loc, _, kind, _ in items if kind == "missing"}
    absorbed: set[tuple[Any, ...]] = set()
    out: list[FieldError] = []
    for raw_loc, loc, msg, kind, value in items:
        suggestion = None
        if kind == "unknown_key":
            parent, key = loc[:-1], str(loc[-1])
            wanted = [m for p, m in missing if p == parent and isinstance(m, str)]
            suggestion = _suggest(key, wanted)
            if suggestion is not None:
                absorbed.add((*parent, suggestion))
            else:
                known = sorted({f for m in _models_at(raw_loc[:-1]) for f in m.model_fields})
                suggestion = _suggest(key, known)
                if suggestion is None and known:
                    msg += f" (known: {', '.join(known)})"
            if suggestion is not None:
                msg += f"; did you mean `{suggestion}`?"
        elif kind in ("choice", "rule") and isinstance(value, str):
            ctx = raw[len(out)].get("ctx") or {}
            choices = ctx.get("choices") or _choices(msg.removeprefix("must be one of "))
            suggestion = _suggest(value, choices) if kind == "choice" or "choices" in ctx else None
            if suggestion is not None:
                msg += f"; did you mean `{suggestion}`?"
        out.append(FieldError(format_location(loc), msg, value, kind, suggestion))
    return [
        e
        for e, (_, loc, *_rest) in zip(out, items, strict=True)
        if not (e.kind == "missing" and tuple(loc) in absorbed)
    ]


# ----------------------------------------------------------------------------- rules


def _nonzero(v: Sequence[float] | None) -> bool:
    return v is not None and any(x != 0.0 for x in v)


def consistency_errors(spec: RobotFile) -> list[FieldError]:
    """Rules that tie fields of different tables together (the rod's length, density)."""
    length = spec.rod.length
    errs: list[FieldError] = []
    for i, t in enumerate(spec.tendons):
        if t.end is not None and t.end > length:
            errs.append(
                FieldError(
                    f"tendons[{i}].end",
                    f"must be in (0, rod.length] = (0, {length}] m",
                    t.end,
                    "range",
                )
            )
    for i, c in enumerate(spec.chambers):
        if c.start >= length:
            errs.append(
                FieldError(
                    f"chambers[{i}].start",
                    f"must be in [0, rod.length) = [0, {length}) m",
                    c.start,
                    "range",
                )
            )
        if c.end is not None and c.end > length:
            errs.append(
                FieldError(
                    f"chambers[{i}].end",
                    f"must be in (start, rod.length] = ({c.start}, {length}] m",
                    c.end,
                    "range",
                )
            )
    loads = spec.loads
    if loads is not None:
        for i, p in enumerate(loads.point_loads):
            if p.s > length:
                errs.append(
                    FieldError(
                        f"loads.point_loads[{i}].s",
                        f"must be in [0, rod.length] = [0, {length}] m",
                        p.s,
                        "range",
                    )
                )
        if _nonzero(loads.gravity) and spec.rod.density is None:
            errs.append(
                FieldError(
                    "loads.gravity",
                    "needs `rod.density` (kg/m^3), which is not given",
                    loads.gravity,
                    "rule",
                )
            )
    sec = spec.rod.section
    if isinstance(sec, TableSectionSpec) and (sec.s[0] != 0.0 or sec.s[-1] != length):
        errs.append(
            FieldError(
                "rod.section.s",
                f"must run from 0 to rod.length = {length} m",
                sec.s,
                "range",
            )
        )
    return errs
