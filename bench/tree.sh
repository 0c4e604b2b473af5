#!/usr/bin/env bash
# Barnes–Hut gravity, Plummer sphere N = 1e5 (and 1e6), θ = 0.5, ε = 0.01:
# mote's tree (1 and 2 threads) beside REBOUND's tree (single thread), same
# session. Compare CPU time per step. Usage: bench/tree.sh [N] [STEPS]
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-100000}
STEPS=${2:-5}
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$PWD/target}
echo "# $(date -u +%FT%TZ) $(nproc) cores, load: $(cut -d' ' -f1-3 /proc/loadavg)"
lscpu | grep 'Model name' || true
BIN=$(cargo bench -p mote-md --bench tree --no-run --message-format=json 2>/dev/null \
  | python3 -c 'import json,sys
for l in sys.stdin:
    m=json.loads(l)
    if m.get("reason")=="compiler-artifact" and m["target"]["name"]=="tree" and m.get("executable"): print(m["executable"])' | tail -1)
for t in 1 2; do
  /usr/bin/time -f "  process: %U s user, %S s system, %e s wall" "$BIN" --plain "$N" "$STEPS" "$t"
done
VENV=/tmp/rebound-venv
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV"
  "$VENV/bin/pip" install -q rebound numpy
fi
"$VENV/bin/python" -c 'import rebound; print("rebound", rebound.__version__)'
# tree_bench.py runs θ² = 0.25 (θ = 0.5) and θ² = 0.49 (θ = 0.7).
/usr/bin/time -f "  process: %U s user, %S s system, %e s wall" \
  "$VENV/bin/python" ../shared/bench/tree_bench.py "$N" "$STEPS"
