"""Helpers shared by the command modules."""

from __future__ import annotations

import argparse
import sys


def save_figure(fig, path: str, dpi: int = 130) -> None:
    """Writes ``fig`` to ``path`` and says so on stderr."""
    fig.savefig(path, dpi=dpi)
    print(f"wrote {path}", file=sys.stderr)


def use_agg() -> None:
    """Selects matplotlib's non-interactive backend (the CLI only writes files)."""
    import matplotlib

    matplotlib.use("Agg")


def _positive_int(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None


def _fmt6(m) -> str:
    return "\n".join("  [" + ", ".join(f"{v: .4e}" for v in row) + "]" for row in m)
