#!/usr/bin/env bash
# Direct-summation gravity: mote (whole runs, 1 and 2 threads) beside REBOUND's
# direct gravity (../shared/bench/rebound_bench.py). Needs `pip install rebound numpy`.
# Prints CPU seconds (user+sys) and wall seconds per run; pairs are N(N-1)/2 per force evaluation.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q
mote=target/release/mote
for n in 4096 16384; do
  steps=$([ "$n" = 4096 ] && echo 50 || echo 10)
  for threads in 1 2; do
    for rep in 1 2 3; do
      /usr/bin/time -f "N=$n threads=$threads steps=$steps cpu=%U+%S wall=%e" \
        "$mote" run "bench/gravity-$n.toml" --steps "$steps" --threads "$threads" -q -o /tmp/mote-bench 2>&1
    done
  done
done
if [ "${1:-}" != "--mote-only" ] && python3 -c "import rebound" 2>/dev/null; then
  python3 ../shared/bench/rebound_bench.py
else
  echo "REBOUND not installed: pip install rebound numpy"
fi
