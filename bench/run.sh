#!/usr/bin/env bash
# Every benchmark scene of bench/, beside the reference program where it is
# installed, run back to back on this machine: prints the ratio table of
# BENCHMARKS.md (median user+system CPU seconds of the whole process over
# RUNS runs, one thread each), with the CPU and the SIMD level named.
#
#   bash bench/run.sh                 # all, 3 runs each
#   RUNS=5 bash bench/run.sh lj       # the rows whose name contains "lj"
#   MOTE_SIMD=avx2 bash bench/run.sh  # mote at a forced SIMD level
#
# References: LAMMPS (`lmp`, Debian's lammps, with -sf opt) and LIGGGHTS
# (`liggghts`), decks in ../shared/bench/ (or $REFERENCE_DECKS); a missing
# program leaves its columns empty. Rows without a reference give mote's
# time alone (gravity against REBOUND goes by pair rate: bench/gravity.sh;
# hard spheres against Smallenburg's code, built by hand: BENCHMARKS.md).
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${RUNS:-3}
only=${1:-}
decks=${REFERENCE_DECKS:-../shared/bench}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

cargo build --release -q -p mote
mote=$PWD/target/release/mote

# median of the numbers on stdin
median() { sort -g | awk '{a[NR]=$1} END{if (NR==0) print ""; else if (NR%2) print a[(NR+1)/2]; else print (a[NR/2]+a[NR/2+1])/2}'; }

# CPU seconds (user + system) of one run of "$@".
cpu() {
  /usr/bin/time -o "$out/time" -f "%U %S" "$@" >/dev/null 2>&1 || { echo "failed: $*" >&2; return 1; }
  awk '{print $1 + $2}' "$out/time"
}

declare -A timed

# row NAME SCENE REFERENCE-NAME REFERENCE-COMMAND...
row() {
  local name=$1 scene=$2 ref=$3
  shift 3
  [[ -n "$only" && "$name" != *"$only"* ]] && return
  local m r
  # A scene beside two references is timed once.
  if [[ -z "${timed[$scene]:-}" ]]; then
    timed[$scene]=$(for _ in $(seq "$runs"); do cpu "$mote" -q --threads 1 run "$scene" -o "$out/run"; done | median)
  fi
  m=${timed[$scene]}
  r=""
  if [[ $# -gt 0 ]] && command -v "$1" >/dev/null 2>&1; then
    r=$(for _ in $(seq "$runs"); do (cd "$decks" && cpu "$@"); done | median)
  fi
  local ratio="–"
  [[ -n "$r" ]] && ratio=$(awk -v m="$m" -v r="$r" 'BEGIN{printf "%.2f", m / r}')
  printf '| %s | `%s` | %s | %s | %s | %s |\n' "$name" "$scene" "$m" "${ref:-–}" "${r:-–}" "$ratio"
}

level=$("$mote" --threads 1 run example:sun-earth --steps 1 -o "$out/probe" 2>&1 >/dev/null | grep -o '1 thread, [^)]*)\?' | head -1 | sed 's/^1 thread, //')
cpu_name=$(awk -F': ' '/model name/{print $2; exit}' /proc/cpuinfo)
echo "CPU: ${cpu_name:-unknown}; mote's SIMD level: ${level:-unknown}; $runs runs each, medians of user+system CPU s, one thread"
echo
echo "| benchmark | scene | mote CPU s | reference | reference CPU s | mote / reference |"
echo "|---|---|---|---|---|---|"
row "LJ melt (32000 atoms, 100 steps)" bench/lj-melt.toml "LAMMPS -sf opt" lmp -sf opt -in lammps.lj.in -log none
row "dipolar LJ fluid (32000 atoms, 100 steps)" bench/dipole3d.toml "LAMMPS -sf opt" lmp -sf opt -in lammps.dipole3d.in -log none
row "granular settling (10^4 spheres, 6000 steps)" bench/settle.toml "LIGGGHTS" liggghts -in liggghts.settle_si.in -log none
row "granular settling, LAMMPS" bench/settle.toml "LAMMPS -sf opt" lmp -sf opt -in lammps.settle_si.in -log none
row "trimers (4608 clumps)" bench/clump.toml "LAMMPS rigid/small -sf opt" lmp -sf opt -in lammps.clump.in -log none
row "direct gravity (N = 4096, 50 steps)" bench/gravity-4096.toml ""
row "Barnes–Hut gravity (N = 10^5, theta = 0.5, 10 steps)" bench/gravity-tree-100k.toml ""
row "hard spheres (32000, eta = 0.45, t = 20)" bench/hard-spheres.toml ""
row "all-pairs dipoles (1000, 50 steps)" bench/dipoles-1000.toml ""
