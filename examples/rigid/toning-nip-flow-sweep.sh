#!/usr/bin/env bash
# The flowing toning nip's loading sweep (issue 41, parts 4 and 5): runs
# example:toning-nip-flow with the inlet kept to each carrier volume
# fraction F given (toner at 0.04 F: four toner per carrier, the same
# developer), and tabulates, over the later half of each run (three passes
# of the image), the developed mass per area on the image and the
# background (what the belt carries out: toning-nip-flow-developed.py),
# the nip's free volume and toner on the belt (nip.csv, the development
# zone), and the mass in and out.
#
#   examples/rigid/toning-nip-flow-sweep.sh [OUT] [F ...]
#   MOTE=target/release/mote SEED=12 examples/rigid/toning-nip-flow-sweep.sh out/flow 0.2 0.3
#
# UNTIL (default 6e-3 s) sets each run's length; its later half is averaged.
set -euo pipefail
MOTE=${MOTE:-mote}
SEED=${SEED:-11}
UNTIL=${UNTIL:-6e-3}
OUT=${1:-out/toning-nip-flow-sweep}
shift || true
FRACTIONS=${*:-0.2 0.25 0.3}
HERE=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$OUT"
"$MOTE" examples --write "$OUT/scenes" >/dev/null
SCENE="$OUT/scenes/toning-nip-flow.toml"
CSV="$OUT/sweep.csv"
[ -f "$CSV" ] || echo "seed,carrier_fraction,free_volume,mass_per_area_image,mass_per_area_background,mass_in_rate,mass_out_rate" > "$CSV"
for f in $FRACTIONS; do
  # The first `volume_fraction =` is the carriers', the second the toner's.
  awk -v f="$f" '/^volume_fraction = / { k++; $0 = "volume_fraction = " (k == 1 ? f : 0.04 * f) } { print }' \
    "$SCENE" > "$OUT/flow-$f.toml"
  run="$OUT/$f-seed$SEED"
  "$MOTE" -q --seed "$SEED" run "$OUT/flow-$f.toml" --until "$UNTIL" -o "$run"
  half=$(awk -v u="$UNTIL" 'BEGIN { print u / 2 }')
  developed=$(python3 "$HERE/toning-nip-flow-developed.py" "$run/outflow.csv" "$half" "$UNTIL" "$OUT/flow-$f.toml")
  image=$(echo "$developed" | sed -E 's/.*image ([0-9.]+) mg.*/\1/')
  background=$(echo "$developed" | sed -E 's/.*background ([0-9.]+) mg.*/\1/')
  free=$(awk -F, -v h="$half" '/^#/ || /^time/ { next } $1 >= h { k++; fv += $11 } END { printf "%.4f", fv / k }' "$run/nip.csv")
  # Mass in and out per second over the later half, from observables.csv.
  rates=$(awk -F, -v h="$half" '
    /^#/ { next }
    /^time/ { for (i = 1; i <= NF; i++) { if ($i ~ /^mass_in_/) mi[i] = 1; if ($i ~ /^mass_out_/) mo[i] = 1 }; next }
    { m_in = 0; m_out = 0; for (i in mi) m_in += $i; for (i in mo) m_out += $i }
    !started && $1 >= h { t0 = $1; in0 = m_in; out0 = m_out; started = 1 }
    { t1 = $1; in1 = m_in; out1 = m_out }
    END { printf "%.6e,%.6e", (in1 - in0) / (t1 - t0), (out1 - out0) / (t1 - t0) }' "$run/observables.csv")
  echo "$SEED,$f,$free,$image,$background,$rates" >> "$CSV"
  tail -n 1 "$CSV"
done
echo "$CSV (mass per area in mg/cm², rates in kg/s)"
