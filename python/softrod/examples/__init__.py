"""Example robots and measured data shipped with softrod, reachable by name.

The robot files live in ``softrod/examples/robots/`` and the tensile curves of the Soft
Robotics Materials Database in ``softrod/examples/data/silicone-tensile/`` (with their
licence); they are installed with the package, so ``softrod solve niti_two_segment`` and
``softrod study`` work from any folder. In a checkout of the repository, ``examples/robots``
and ``data/silicone-tensile`` point here.

Example:
    >>> import softrod
    >>> softrod.examples.names()
    ('niti_two_segment', 'pneumatic_arm', 'tapered_cable_arm')
    >>> robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
"""

from __future__ import annotations

import difflib
from pathlib import Path

from .._core import ParameterError

__all__ = ["data_path", "load", "names", "path", "tensile_curves"]

#: Earlier names of the example robots, still accepted by :func:`path` and :func:`load`.
ALIASES = {"seed000_arm": "tapered_cable_arm", "seed001_pneumatic_arm": "pneumatic_arm"}

_HERE = Path(__file__).resolve().parent
ROBOTS = _HERE / "robots"
DATA = _HERE / "data"


def names() -> tuple[str, ...]:
    """Names of the example robots (file stems), sorted."""
    return tuple(sorted(p.stem for p in ROBOTS.glob("*.toml")))


def path(name: str) -> Path:
    """The file of an example robot.

    Args:
        name: Its name, with or without ``.toml`` (see :func:`names`; the earlier names in
            :data:`ALIASES` work too).

    Raises:
        ParameterError: No example of that name (the message lists the names and the
            closest one).
    """
    stem = str(name).removesuffix(".toml")
    stem = ALIASES.get(stem, stem)
    if stem in names():
        return ROBOTS / f"{stem}.toml"
    close = difflib.get_close_matches(stem, names(), n=1)
    hint = f"; did you mean `{close[0]}`?" if close else ""
    exc = ParameterError(
        f"invalid parameter `name` = {name!r}: no example robot of that name (examples: "
        f"{', '.join(names())}){hint}"
    )
    exc.parameter = "name"
    raise exc


def load(name: str):
    """The example robot ``name``, loaded (:func:`softrod.load_robot`)."""
    from ..robot import load_robot

    return load_robot(path(name))


def data_path(relative: str) -> Path:
    """A shipped data file or folder, e.g. ``"silicone-tensile/Dragon Skin 10 MEDIUM.csv"``.

    Raises:
        ParameterError: No such file or folder.
    """
    p = (DATA / relative).resolve()
    if (DATA.resolve() not in p.parents and p != DATA.resolve()) or not p.exists():
        exc = ParameterError(
            f"invalid parameter `relative` = {relative!r}: no shipped data file of that name"
        )
        exc.parameter = "relative"
        raise exc
    return p


def tensile_curves() -> tuple[Path, ...]:
    """The shipped uniaxial tensile curves (CSV files of the Soft Robotics Materials
    Database), sorted by name."""
    return tuple(sorted((DATA / "silicone-tensile").glob("*.csv")))
