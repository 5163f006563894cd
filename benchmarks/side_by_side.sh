#!/bin/bash
# Criterion benches of two checkouts side by side: the bench binaries of BASE (e.g. a worktree of
# an earlier commit) and of this checkout run alternately, bench by bench, ROUNDS times, so both
# see the same machine load. Prints one line per case: round, old/new, name, median.
#
#   git worktree add ../baseline eff6e87 && (cd ../baseline && cargo bench -p softrod --no-run)
#   cargo bench -p softrod --no-run
#   ROUNDS=2 benchmarks/side_by_side.sh ../baseline statics compliance pcc planar
set -euo pipefail
base=$1
shift
here=$(cd "$(dirname "$0")/.." && pwd)
binary() { ls -t "$1"/target/release/deps/"$2"-* | grep -v '\.d$' | head -1; }
for r in $(seq "${ROUNDS:-2}"); do
  for b in "$@"; do
    for w in old new; do
      dir=$([ "$w" = old ] && echo "$base" || echo "$here")
      "$(binary "$dir" "$b")" --bench --warm-up-time 1 --measurement-time 2 --noplot 2>&1 |
        awk -v w="$w" -v r="$r" '
          /^Benchmarking/ { next }
          /time:/ { n = name; if ($1 != "time:") n = $1
                    for (i = 1; i <= NF; i++) if ($i == "time:") print r, w, n, $(i + 3), $(i + 4)
                    next }
          /^[a-z]/ { name = $1 }'
    done
  done
done
