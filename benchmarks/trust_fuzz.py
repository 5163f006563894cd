"""Bad-input fuzz of every public callable of softrod and softrod.pcc, in subprocesses.

Issue 10 requires 0 panics, 0 aborts, 0 silent non-finite outputs and >= 95 % of errors naming
the parameter (``tests/harness/fuzz.py``).

    python benchmarks/trust_fuzz.py [--sample N] [--defects] [--unnamed K]
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from harness import fuzz

ORDER = (
    "ok-finite",
    "named-error",
    "unnamed-error",
    "ok-not-converged",
    "ok-nonfinite",
    "ok-swallowed-callback-error",
    "panic",
    "abort",
    "hang",
    "harness-error",
)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sample", type=int, help="a reproducible sample of N calls (default all)")
    ap.add_argument("--defects", action="store_true", help="list every defect")
    ap.add_argument("--unnamed", type=int, default=12, help="show K kinds of unnamed errors")
    args = ap.parse_args()
    calls = fuzz.calls()
    selected = calls if args.sample is None else fuzz.sample(calls, args.sample)
    t0 = time.perf_counter()
    out = fuzz.run(selected)
    s = fuzz.summary(out)
    print(
        f"{s['calls']} fuzzed calls of {s['targets']} targets ({time.perf_counter() - t0:.0f} s, "
        f"{len(selected) - s['calls']} baselines)"
    )
    for k in ORDER:
        print(f"  {k:<28} {s['counts'].get(k, 0):>6}")
    print(f"errors naming the parameter: {100 * s['named_rate']:.1f} %")
    type_errors = [o for o in out if o.call.parameter and o.detail.startswith("TypeError")]
    unnamed_type = sum(o.outcome == "unnamed-error" for o in type_errors)
    print(f"TypeErrors that do not name the parameter: {unnamed_type} of {len(type_errors)}")
    print(f"NaN/inf arguments accepted silently (finite result): {s['accepted_nonfinite']}")
    for o in s["baseline_failures"]:
        print(f"BASELINE FAILED {o.call.target}: {o.detail}")
    by_kind = Counter(o.outcome for o in s["defects"])
    print(f"defects: {dict(by_kind)}")
    shown = (
        s["defects"] if args.defects else [o for o in s["defects"] if o.outcome != "ok-nonfinite"]
    )
    for o in shown:
        print(
            f"  {o.outcome:<28} {o.call.target}({o.call.parameter}={o.call.value}) {o.detail[:90]}"
        )
    if not args.defects:
        nonfinite = sorted({o.call.target for o in s["defects"] if o.outcome == "ok-nonfinite"})
        print(f"  ok-nonfinite in: {', '.join(nonfinite)}")
    kinds = Counter(
        o.detail.split(":")[0] + ": " + o.detail.split(":", 1)[-1][:40] for o in s["unnamed"]
    )
    print("most common unnamed errors:")
    for k, n in kinds.most_common(args.unnamed):
        print(f"  {n:>5}  {k}")


if __name__ == "__main__":
    main()
