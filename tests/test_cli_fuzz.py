"""A fuzz of the command line: generated argument vectors and mutated robot files.

Every invocation must end with exit status 0, 1, 2 or 3; on failure exactly one line
``softrod: error: ...`` and never a traceback or an "internal error"; and no input file may
change. The default run is a bounded profile (``FUZZ_DEFAULT`` invocations); the full one
(``FUZZ_FULL``) runs with ``-m slow``.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import random
from pathlib import Path

import pytest

import softrod
from softrod.cli import main

FUZZ_DEFAULT = 400
FUZZ_FULL = 2500
SEED = 20261201

NITI = softrod.examples.path("niti_two_segment").read_text()
TENSILE = softrod.examples.DATA / "silicone-tensile" / "Ecoflex 00-30.csv"

# Values that stand in for a number in a robot file (TOML text).
TOML_VALUES = [
    "true",
    '"abc"',
    "inf",
    "-inf",
    "nan",
    "-1",
    "0",
    "1e308",
    "-1e308",
    "1e-308",
    "[1, 2]",
    "{ a = 1 }",
    "[]",
    '""',
    "1979-05-27",
    "99999999999999999999",
]
ARG_NUMBERS = ["-1", "0", "1", "2", "0.5", "nan", "inf", "-inf", "1e308", "abc", "", "3:4", "1e3"]


def _mutate_robot(rng: random.Random) -> bytes:
    """A robot file with one to three mutations of the NiTi example."""
    lines = NITI.splitlines()
    for _ in range(rng.randint(1, 3)):
        kind = rng.randrange(11)
        assignments = [i for i, ln in enumerate(lines) if "=" in ln and not ln.startswith("#")]
        if kind <= 2 and assignments:  # a value of the wrong type or out of range
            i = rng.choice(assignments)
            key = lines[i].split("=")[0].strip()
            lines[i] = f"{key} = {rng.choice(TOML_VALUES)}"
        elif kind == 3 and assignments:  # a misspelt key
            i = rng.choice(assignments)
            key, value = lines[i].split("=", 1)
            key = key.strip() or "x"
            cut = rng.randrange(len(key))
            lines[i] = f"{key[:cut] + key[cut + 1 :]} ={value}"
        elif kind == 4:  # a table (or array of tables) given as a string
            table = rng.choice(["rod", "solver", "tendons", "loads", "chambers", "rod.section"])
            lines = [ln for ln in lines if not ln.startswith(("[rod", "[solver", "[[tendons"))]
            lines.insert(0, f'{table.split(".")[0]} = "x"')
        elif kind == 5 and assignments:  # a key removed
            del lines[rng.choice(assignments)]
        elif kind == 6:  # an unknown table
            lines.append(rng.choice(["[extra]", "[[tendons]]", "[loads]\ngravity = [0, 0, -9.81]"]))
        elif kind == 7:  # broken TOML
            lines.insert(rng.randrange(len(lines) + 1), rng.choice(["[rod", "x = ", "= 3", "[[]]"]))
        elif kind in (8, 9) and assignments:  # a number scaled or negated: valid types
            i = rng.choice(assignments)
            key, value = (x.strip() for x in lines[i].split("=", 1))
            try:
                number = float(value.split("#")[0])
            except ValueError:
                continue
            number *= rng.choice([-1.0, 0.0, 1e-6, 1e-3, 10.0, 1e3, 1e6, 1e12])
            lines[i] = f"{key} = {int(number) if key == 'steps' else number!r}"
        else:  # bytes that are not UTF-8
            return "\n".join(lines).encode() + rng.choice([b"\xff\xfe", b"# \xe9\n", b"\x80"])
    return ("\n".join(lines) + "\n").encode()


COMMANDS = [
    "solve",
    "compliance",
    "workspace",
    "compare",
    "planar",
    "fit",
    "study",
    "schema",
    "inverse",
]


def _argv(rng: random.Random, tmp: Path, inputs: list[Path]) -> tuple[list[str], list[Path]]:
    """An argument vector and the input files it names (which must not change)."""
    command = rng.choice([*COMMANDS, *COMMANDS[:4], "demo", "materials", "nope", "--version", ""])
    robot_file = tmp / f"robot{len(inputs)}.toml"
    if rng.random() < 0.6:
        robot_file.write_bytes(_mutate_robot(rng))
        inputs.append(robot_file)
        robot = str(robot_file)
    else:
        robot = rng.choice(
            ["niti_two_segment", "tapered_cable_arm", "pneumatic_arm", "nope", "x/y.toml"]
        )
    argv = [command]
    if command in ("solve", "compliance", "workspace", "compare", "inverse"):
        argv.append(robot)
    elif command == "study" and rng.random() < 0.5:
        argv.append(robot)
    elif command == "fit":
        argv.append(str(rng.choice([TENSILE, robot_file, tmp / "missing.csv"])))

    def out(ext: str) -> str:
        choice = rng.random()
        if choice < 0.15 and inputs:
            return str(rng.choice(inputs))  # an output that is an input
        if choice < 0.25:
            return str(tmp / "same.out")  # possibly the same as another output
        if choice < 0.35:
            return str(tmp / "no" / "such" / f"x.{ext}")
        return str(tmp / f"o{rng.randrange(10**6)}.{ext}")

    options = {
        "--tensions": lambda: rng.choices(ARG_NUMBERS, k=rng.randint(0, 7)),
        "--pressures": lambda: rng.choices(ARG_NUMBERS, k=rng.randint(0, 7)),
        "--csv": lambda: [out("csv")],
        "--json": lambda: [out("json")],
        "--plot": lambda: [
            out(rng.choice(["badext", "txt", "png", ""]))
            if rng.random() < 0.9
            else str(tmp / "p.png")
        ],
        "--sweep": lambda: [
            rng.choice(["0:4", "0:-4", "1:2", "9:1", "a:b", "0", "0:nan", "1:1:1"])
        ],
        "--n": lambda: [rng.choice(["-1", "0", "1", "3", "x", "2.5"])],
        "--tangent": lambda: [rng.choice(["length", "tension", "nope"])],
        "--repeats": lambda: [rng.choice(["0", "1", "-3", "x"])],
        "--levels": lambda: [rng.choice(["0", "1", "2", "x"])],
        "--max-pressure": lambda: [rng.choice(ARG_NUMBERS)],
        "-t": lambda: rng.choices(ARG_NUMBERS, k=rng.randint(0, 3)),
        "-n": lambda: [rng.choice(["1", "2", "11", "0", "-4", "x"])],
        "--length": lambda: [rng.choice(ARG_NUMBERS)],
        "--offset-ratio": lambda: [rng.choice(ARG_NUMBERS)],
        "--anchor": lambda: [rng.choice(ARG_NUMBERS)],
        "--method": lambda: [rng.choice(["ode", "closed-form", "euler"])],
        "-m": lambda: rng.choices(["yeoh", "ogden", "mooney-rivlin", "neo-hookean", "zz"], k=2),
        "--terms": lambda: [rng.choice(["0", "1", "3", "9", "x"])],
        "--stretch-max": lambda: [rng.choice(ARG_NUMBERS)],
        "--target": lambda: rng.choice(
            [["0.13", "0.036", "0.3625"], ["0.3", "0.3", "0"], rng.choices(ARG_NUMBERS, k=3)]
        ),
        "--rotation": lambda: rng.choices(["1", "0", "0", "nan", "2"], k=rng.choice([9, 9, 3])),
        "--tension-bounds": lambda: rng.choices(ARG_NUMBERS, k=rng.choice([2, 2, 1])),
        "--weights": lambda: rng.choices(ARG_NUMBERS, k=rng.randint(0, 7)),
        "--tolerance": lambda: [rng.choice(ARG_NUMBERS)],
        "--bogus": lambda: [],
    }
    names = list(options)
    for _ in range(rng.choice([0, 0, 0, 1, 1, 2, 3, 5])):
        name = rng.choice(names)
        argv += [name, *options[name]()]
    if command == "study" and "--levels" not in argv:
        argv += ["--levels", "2"]  # keep the valid studies short
    if command == "workspace" and "--n" not in argv:
        argv += ["--n", "3"]
    if command == "compare" and "--repeats" not in argv:
        argv += ["--repeats", "1"]
    if command == "inverse" and "--target" not in argv and rng.random() < 0.8:
        argv += ["--target", "0.1305", "0.0366", "0.3625"]
    if command == "demo":
        argv += ["--plot", out("png")]
    if command == "":
        argv = argv[1:]
    named = [p for p in inputs if str(p) in argv[1:2]]
    return argv, named


def _digest(paths: list[Path]) -> dict[Path, str]:
    return {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in paths if p.exists()}


def _fuzz(count: int, tmp: Path, monkeypatch) -> dict[str, int]:
    monkeypatch.chdir(tmp)
    rng = random.Random(SEED)
    inputs: list[Path] = [TENSILE]
    tally = {"runs": 0, "tracebacks": 0, "internal": 0, "overwritten": 0, "multi_line": 0}
    failures: list[str] = []
    for _ in range(count):
        argv, protected = _argv(rng, tmp, inputs)
        before = _digest(protected)
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = main(argv)
            except BaseException as exc:  # an escaped exception is a traceback
                status = f"raised {type(exc).__name__}: {exc}"
        tally["runs"] += 1
        text = err.getvalue()
        lines = [ln for ln in text.splitlines() if ln.startswith("softrod: error:")]
        problem = None
        if not isinstance(status, int) or "Traceback" in text:
            tally["tracebacks"] += 1
            problem = f"traceback: {status}"
        elif "internal error" in text:
            tally["internal"] += 1
            problem = lines[0] if lines else text
        elif status not in (0, 1, 2, 3):
            problem = f"exit {status}"
        elif status != 0 and len(lines) != 1:
            tally["multi_line"] += 1
            problem = f"{len(lines)} error lines"
        if _digest(protected) != before:
            tally["overwritten"] += 1
            problem = "an input changed"
        if problem:
            failures.append(f"{argv}: {problem}")
    assert not failures, "\n".join(failures[:20])
    return tally


def test_cli_fuzz_bounded_profile(tmp_path, monkeypatch):
    tally = _fuzz(FUZZ_DEFAULT, tmp_path, monkeypatch)
    assert tally["runs"] == FUZZ_DEFAULT


@pytest.mark.slow
def test_cli_fuzz_full(tmp_path, monkeypatch):
    tally = _fuzz(FUZZ_FULL, tmp_path, monkeypatch)
    assert tally["runs"] >= 2000
