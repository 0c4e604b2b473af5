#!/usr/bin/env bash
# Builds `import mote` into a virtual environment (target/py-venv) with
# maturin and runs its pytest suite, then the example scripts at small
# sizes. Called by README's test command after `cargo test --workspace`.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$here/../../target/py-venv"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip >/dev/null
"$venv/bin/python" -m pip install --quiet "maturin>=1.5,<2" pytest numpy matplotlib
# ASE for the interop test (skipped with a message where it cannot install).
"$venv/bin/python" -m pip install --quiet ase >/dev/null 2>&1 || echo "note: could not install ase; its Python test will skip"
# Optimised as the Rust tests are (Cargo.toml's `pytest` profile): a debug
# build compiles as long and runs pytest several times slower.
(cd "$here" && VIRTUAL_ENV="$venv" "$venv/bin/maturin" develop --quiet --profile pytest)
cd "$here"
"$venv/bin/python" -m pytest -q tests
# The example scripts at small sizes: each must run and write its plot.
plots="$(mktemp -d)"
for script in "$here"/../../examples/python/*.py; do
  MOTE_EXAMPLE_SMALL=1 MOTE_EXAMPLE_OUT="$plots" "$venv/bin/python" "$script" >/dev/null
  png="$plots/$(basename "${script%.py}").png"
  [ -s "$png" ] || { echo "$script wrote no $png" >&2; exit 1; }
done
echo "examples/python: $(ls "$plots" | wc -l) plots written"
rm -rf "$plots"
