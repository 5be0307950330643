#!/usr/bin/env bash
# Side-by-side throughput of vibrobed against harddisks.c (benches/peer/harddisks/: l09rin/EDMD
# Cylinder2D, a 2D port of Smallenburg's EDMD, MIT licence in its LICENSE), the fastest public 2D
# hard-disk EDMD code we know. Elastic equal disks in a square periodic box; rate = pair collisions
# per wall second from two runs of each code (durations T and 2T: set-up cancels). Prints a table
# with the ratio vibrobed/peer; then the shipped vibrated bed's events per second beside the shipped
# gas's (shipped_scenes.py: whole process, T and 2T, one core). Needs gcc, python3, taskset and
# /usr/bin/time.
#
# Run from the project root:  benches/peer/run.sh            (N = 2500 and 1e5, ~6 min)
#                             benches/peer/run.sh --big      (adds N = 1e6, ~25 min)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
work="$(mktemp -d)"
gcc -Ofast -march=native -funroll-loops "$here/harddisks/harddisks.c" -o "$work/mdhdd" -lm 2>/dev/null
cargo build --release --no-default-features -q
bin="${CARGO_TARGET_DIR:-target}/release/vibrobed"
points="2500:0.3:2e6,2500:0.7:4e6,100000:0.3:3e6,100000:0.7:6e6"
[ "${1:-}" = "--big" ] && points="$points,1000000:0.3:6e6,1000000:0.7:1.2e7"
python3 "$here/side_by_side.py" --vb "$bin" --peer "$work/mdhdd" --scenario scenarios/gas_periodic_phi03.json \
  --out "$work" --points "$points" --reps 3 --cores "$(seq -s, 0 $(( $(nproc) - 1 )))" | grep -v '^{'
python3 "$here/shipped_scenes.py" --vb "$bin" --core "$(( $(nproc) - 1 ))"
echo "raw results: $work/raw.json"
