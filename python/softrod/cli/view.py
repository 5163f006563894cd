"""``softrod view``: the live 3-D view of a robot file in the browser."""

from __future__ import annotations

import sys
import time

from ._common import files


def _cmd_view(args) -> int:
    from ..plot.live import serve
    from ..robot import load_robot

    robot = load_robot(args.robot)
    view = serve(
        robot,
        port=args.port,
        open_browser=not args.no_browser,
        host="127.0.0.1",
        max_tension=args.max_tension,
        max_pressure=None if args.max_pressure is None else args.max_pressure,
        max_force=args.max_force,
    )
    print(f"softrod view: {robot.name} at {view.url} (Ctrl-C stops)", file=sys.stderr)
    try:
        deadline = None if args.seconds is None else time.monotonic() + args.seconds
        while deadline is None or time.monotonic() < deadline:
            time.sleep(0.2)
    except KeyboardInterrupt:
        pass
    finally:
        view.stop()
    return 0


def _port(text: str) -> int:
    import argparse

    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"port must be in [0, 65535], got {port}")
    return port


def _seconds(text: str) -> float:
    import argparse
    import math

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"must be a finite number of seconds >= 0, got {text}")
    return value


def register(sub) -> None:
    """Adds the subcommand of this module to the ``softrod`` parser."""
    v = sub.add_parser(
        "view",
        help="live 3-D view in the browser: sliders for tensions, pressures and tip force",
    )
    v.add_argument(
        "robot",
        metavar="ROBOT",
        help="robot description file (TOML), or the name of a shipped example",
    )
    v.add_argument(
        "--port", type=_port, default=8080, help="port on 127.0.0.1 (default: %(default)s)"
    )
    v.add_argument("--no-browser", action="store_true", help="do not open a browser")
    v.add_argument("--max-tension", type=float, metavar="N", help="top of the tension sliders (N)")
    v.add_argument(
        "--max-pressure", type=float, metavar="PA", help="top of the pressure sliders (Pa)"
    )
    v.add_argument(
        "--max-force", type=float, metavar="N", help="range of the tip-force sliders (N)"
    )
    v.add_argument(
        "--seconds",
        type=_seconds,
        metavar="S",
        help="stop after S seconds (default: until Ctrl-C)",
    )
    v.set_defaults(func=_cmd_view)
    files(v, inputs=("robot",))
