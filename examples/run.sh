#!/usr/bin/env bash
# The Python example end to end (with the vibrobed on PATH if there is one, else the
# repository's built by cargo): a virtual environment with examples/requirements.txt (pip's
# cache and the environment live outside the clone, so later runs are fast), a short vibrated-bed
# run writing every output, examples/analyse.py on them, examples/convection.py on a short run of
# the convection scene, and the trajectory test with ASE.
#
#   bash examples/run.sh [OUT_DIR]        (default: a temporary folder, removed afterwards)
#
# Environment: VIBROBED_VENV (default ~/.cache/vibrobed-venv), PIP_CACHE_DIR (default
# ~/.cache/vibrobed-pip), PYTHON (default python3, 3.11 or newer).
set -euo pipefail
cd "$(dirname "$0")/.."

venv="${VIBROBED_VENV:-$HOME/.cache/vibrobed-venv}"
export PIP_CACHE_DIR="${PIP_CACHE_DIR:-$HOME/.cache/vibrobed-pip}"
export PIP_DISABLE_PIP_VERSION_CHECK=1
if [ ! -x "$venv/bin/python" ]; then
  "${PYTHON:-python3}" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet -r examples/requirements.txt

if [ $# -ge 1 ]; then
  out="$1"
  mkdir -p "$out"
else
  out="$(mktemp -d)"
  trap 'rm -rf "$out"' EXIT
fi

# A vibrobed on PATH is used as it is; otherwise the repository's, built with cargo.
if command -v vibrobed > /dev/null; then
  vibrobed() { command vibrobed "$@"; }
else
  vibrobed() { cargo run --release --quiet -- "$@"; }
fi

vibrobed run scenarios/vibrated_bed.json --quiet \
  --set run.duration=50 --set run.warmup=10 \
  --rrd "$out/recording.rrd" --trajectory "$out/trajectory.xyz" \
  --summary "$out/summary.json" --profiles "$out/profiles.csv"
"$venv/bin/python" examples/analyse.py "$out"
test -s "$out/analyse.png"

# The convection rolls' measure (examples/convection.py) on a short run of the convection scene.
vibrobed run scenarios/convection.json --quiet \
  --set run.duration=40 --set run.warmup=10 --set 'output.field_bins=[20,20]' \
  --fields "$out/convection.csv" --summary "$out/convection.json"
"$venv/bin/python" examples/convection.py "$out/convection.csv" \
  --figure "$out/convection.png" > "$out/convection.txt"
grep -q "circulation (centre - walls)" "$out/convection.txt"
test -s "$out/convection.png"

# The trajectory test, ignored by a plain `cargo test`: it needs a Python with ASE.
VIBROBED_PYTHON="$venv/bin/python" cargo test --release --quiet --test suite -- \
  --ignored --exact trajectory::ase_reads_the_trajectory
