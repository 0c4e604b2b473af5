#!/usr/bin/env bash
# mote pack beside spheropack (pip install spheropack; never built from source).
#
#   bench/pack.sh [N] [RATE] [SEEDS]      defaults: 10000 0.01 "1 2 3"
#
# Both programs grow N equal spheres in a periodic cube at the same growth rate
# Γ = (1/v_th) d<d>/dt to reduced pressure 1e12 without a quasi-static finish
# (mote: --no-jam; spheropack: stop=[Pressure(1e12)]), and report φ_J and the
# user CPU time (/usr/bin/time -f %U). Compare medians: the machine is shared.
set -euo pipefail
N=${1:-10000}
RATE=${2:-0.01}
SEEDS=${3:-"1 2 3"}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
VENV=${VENV:-/tmp/spheropack-venv}
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV"
  "$VENV/bin/pip" install --quiet spheropack
fi
cargo build --release --manifest-path "$ROOT/Cargo.toml" -p mote >/dev/null
MOTE=${CARGO_TARGET_DIR:-$ROOT/target}/release/mote
cat > /tmp/spheropack_run.py <<'PY'
import sys, spheropack as sp
n, g, seed = int(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
p = sp.pack(n=n, density="max", growth_rate=g, stop=[sp.stop.Pressure(1e12)], seed=seed)
print(f"spheropack N={n} rate={g} seed={seed} phi={p.density:.5f} Z={p.reduced_pressure:.3g} collisions={p.n_collisions}")
PY
for s in $SEEDS; do
  echo "== seed $s"
  /usr/bin/time -f "mote user-s %U" "$MOTE" pack --n "$N" --rate "$RATE" --seed "$s" \
    --max-pressure 1e12 --no-jam --quiet --tol 1e-9 -o /tmp/mote_pack_$s.xyz
  "$MOTE" pack analyse /tmp/mote_pack_$s.xyz | grep "packing fraction"
  /usr/bin/time -f "spheropack user-s %U" "$VENV/bin/python" /tmp/spheropack_run.py "$N" "$RATE" "$s"
done
