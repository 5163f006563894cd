"""Argument checks of the Python-level API, with the errors of the compiled core.

Every failure names the argument, what was given and what was expected, on one line:
``ParameterTypeError`` (a ``ParameterError`` and a ``TypeError``) for the wrong type or
shape, ``ParameterError`` for a value out of range; both carry ``.parameter``. The limits are
the core's (``softrod._core.MAX_SAMPLES`` ...; see ``docs/conventions.md``).
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from ._core import MAX_ITERATIONS, MAX_SAMPLES, ParameterError, ParameterTypeError

__all__ = [
    "MAX_GRID_VALUES",
    "MAX_ITERATIONS",
    "MAX_SAMPLES",
    "count",
    "describe",
    "finite_array",
    "flag",
    "number",
    "path",
    "type_error",
    "value_error",
]


#: Most values a grid of samples holds: the tensions of a workspace map (rows x tendons) and
#: the points of a sweep (design points x actuation samples); 10,000,000.
MAX_GRID_VALUES = 100 * MAX_SAMPLES


def describe(value: Any) -> str:
    """``repr(value)`` on one line (at most 80 characters) with its type."""
    text = " ".join(repr(value).split())
    if len(text) > 80:
        text = text[:77] + "..."
    return f"{text} ({type(value).__name__})"


def _error(cls, name: str, value: Any, expected: str, described: bool):
    shown = describe(value) if described else value
    err = cls(f"invalid parameter `{name}` = {shown}: must be {expected}")
    err.parameter = name
    return err


def bad(message: str) -> ParameterError:
    """A ``ParameterError`` of a message worded ``invalid parameter `name` ...``, naming
    ``name`` (its ``parameter``) as the errors of :func:`value_error` do."""
    err = ParameterError(message)
    found = re.match(r"invalid parameter `([^`]+)`", message)
    err.parameter = found.group(1) if found else None
    return err


def type_error(name: str, value: Any, expected: str) -> ParameterTypeError:
    """A ``ParameterTypeError`` naming ``name``: ``value`` is not ``expected``."""
    return _error(ParameterTypeError, name, value, expected, True)


def value_error(name: str, value: Any, expected: str) -> ParameterError:
    """A ``ParameterError`` naming ``name``: ``value`` is outside ``expected``."""
    return _error(ParameterError, name, value, expected, False)


def _is_int(value: Any) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def count(value: Any, name: str, low: int = 1, high: int = MAX_SAMPLES) -> int:
    """An integer in ``[low, high]`` (a size, a number of repeats)."""
    if not _is_int(value):
        raise type_error(name, value, "an integer")
    v = int(value)
    if not low <= v <= high:
        raise value_error(name, v, f"in [{low}, {high}]")
    return v


def flag(value: Any, name: str) -> bool:
    """True or False (NumPy booleans included; not numbers or strings)."""
    if not isinstance(value, (bool, np.bool_)):
        raise type_error(name, value, "True or False")
    return bool(value)


def number(
    value: Any,
    name: str,
    *,
    positive: bool = False,
    unit: str = "",
    high: float = math.inf,
) -> float:
    """A finite real number (``> 0`` with ``positive``, ``<= high``)."""
    if isinstance(value, (bool, np.bool_, str, bytes)) or value is None:
        raise type_error(name, value, "a real number")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise type_error(name, value, "a real number") from None
    if not (math.isfinite(v) and (v > 0 or not positive) and v <= high):
        expected = "finite" + (" and > 0" if positive else "")
        if math.isfinite(high):
            expected += f" and <= {high:g}"
        raise value_error(name, v, f"{expected} {unit}".strip())
    return v


def finite_array(value: Any, name: str, *, ndim: int | None = None) -> np.ndarray:
    """A float array (any numeric sequence) with every element finite, of ``ndim`` dims."""
    if value is None or isinstance(value, (str, bytes, dict)):
        raise type_error(name, value, "an array of numbers")
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise type_error(name, value, "an array of numbers") from None
    if ndim is not None and a.ndim != ndim:
        raise type_error(name, value, f"a {ndim}-d array of numbers (got shape {a.shape})")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        index = np.unravel_index(bad[0], a.shape)
        at = ", ".join(str(int(i)) for i in index)
        raise value_error(f"{name}[{at}]" if at else name, a[index], "finite")
    return a


def path(value: Any, name: str = "path") -> Path:
    """A file path: a non-empty ``str`` or ``os.PathLike``."""
    if not isinstance(value, (str, os.PathLike)):
        raise type_error(name, value, "a file path (str or os.PathLike)")
    p = Path(value)
    if str(value) == "":
        raise value_error(name, "''", "a non-empty file path")
    return p
