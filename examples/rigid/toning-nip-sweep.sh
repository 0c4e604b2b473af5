#!/usr/bin/env bash
# The developer-loading sweep of the toning nip (issue 20, part 6): runs
# example:toning-nip with N carrier beads (4 N toner particles, the same
# developer) for each N given, and tabulates the developed toner against
# the free volume of the nip, averaged over the last 0.3 ms of each run.
# Loadings above 160 beads cannot be placed at random: the developer is
# first compressed into the gap (example:toning-nip-compress with N beads
# and 4 N toner, a lid travelling down to the shell), and the nip starts
# from its last frame (`[[from_file]]`); COMPRESS_ABOVE=0 prepares every
# loading so (the control of docs/toning-nip.md).
#
#   examples/rigid/toning-nip-sweep.sh [OUT] [N ...]
#   MOTE=target/release/mote SEED=12 examples/rigid/toning-nip-sweep.sh out/sweep 40 80 120 160
#
# SEED (default: the scene's, 11) places the toner and orients the beads.
# Writes OUT/N/ (each run's files), OUT/sweep.csv and OUT/sweep.png
# (mass per area on the image and on the background against free volume).
set -euo pipefail
MOTE=${MOTE:-mote}
SEED=${SEED:-11}
OUT=${1:-out/toning-nip-sweep}
shift || true
LOADS=${*:-40 60 80 100 120 140 160}
mkdir -p "$OUT"
"$MOTE" examples --write "$OUT/scenes" >/dev/null
SCENE="$OUT/scenes/toning-nip.toml"
COMPRESS="$OUT/scenes/toning-nip-compress.toml"
CSV="$OUT/sweep.csv"
echo "seed,carriers,toner,free_volume,mass_per_area_image,mass_per_area_background,neutralised,bridges,brush_height" > "$CSV"
for n in $LOADS; do
  t=$((4 * n))
  # The first `n =` line is the carriers', the second the toner's.
  loaded() {
    awk -v n="$n" -v t="$t" '/^n = / { k++; if (k == 1) $0 = "n = " n; else if (k == 2) $0 = "n = " t } { print }' "$1"
  }
  if [ "$n" -gt "${COMPRESS_ABOVE:-160}" ]; then
    loaded "$COMPRESS" > "$OUT/compress-$n.toml"
    "$MOTE" -q --seed "$SEED" run "$OUT/compress-$n.toml" -o "$OUT/compress-$n"
    # The nip's developer from the compressed frame.
    awk -v f="compress-$n/trajectory.xyz" '
      /^\[\[rigid.lattice\]\]/ { skip = 1; print "[[from_file]]"; print "file = \"" f "\""; print "" }
      /^\[rigid.fields\]/ { skip = 0 }
      !skip { print }' "$SCENE" > "$OUT/toning-nip-$n.toml"
  else
    loaded "$SCENE" > "$OUT/toning-nip-$n.toml"
  fi
  "$MOTE" -q --seed "$SEED" run "$OUT/toning-nip-$n.toml" -o "$OUT/$n"
  # Means over t ≥ 0.7 ms of nip.csv's columns.
  awk -F, -v n="$n" -v t="$t" -v seed="$SEED" '
    /^#/ || /^time/ { next }
    $1 >= 7e-4 { k++; fv += $11; mi += $3; mb += $4; ne += $7; br += $9; bh += $10 }
    END { printf "%d,%d,%d,%.6f,%.6e,%.6e,%.6f,%.3f,%.6e\n", seed, n, t, fv/k, mi/k, mb/k, ne/k, br/k, bh/k }' \
    "$OUT/$n/nip.csv" >> "$CSV"
  tail -n 1 "$CSV"
done
"$MOTE" -q plot "$CSV" --x free_volume --y mass_per_area_image --y mass_per_area_background \
  --title "developed toner (kg/m²) against the nip's free volume" -o "$OUT/sweep.png"
echo "$CSV, $OUT/sweep.png"
