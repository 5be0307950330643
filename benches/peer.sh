#!/usr/bin/env bash
# Side by side with the fastest public 2D event-driven code (harddisks.c, in benches/peer/harddisks/),
# vibrobed's default engine and Isobe's scheme as published (benches/peer/gas_isobe1999.json:
# global DUTC re-mapping, complete binary tree, no renumbering), in one table. Each column is one
# run of the peer benchmark (which re-measures the peer beside it): pair collisions per wall second
# from runs of T and 2T (set-up cancels), medians of 3, one run per core. Needs gcc, python3,
# taskset and /usr/bin/time.
#
# Run from the project root:  benches/peer.sh          (N = 2500 and 1e5, ~10 min)
#                             benches/peer.sh --big    (adds N = 1e6, ~40 min)
set -euo pipefail
peer="$(cd "$(dirname "$0")/peer" && pwd)"
work="$(mktemp -d)"
gcc -Ofast -march=native -funroll-loops "$peer/harddisks/harddisks.c" -o "$work/mdhdd" -lm 2>/dev/null
cargo build --release --no-default-features -q
bin="${CARGO_TARGET_DIR:-target}/release/vibrobed"
points="2500:0.3:2e6,2500:0.7:4e6,100000:0.3:3e6,100000:0.7:6e6"
[ "${1:-}" = "--big" ] && points="$points,1000000:0.3:6e6,1000000:0.7:1.2e7"
cores="$(seq -s, 0 $(( $(nproc) - 1 )))"
for config in default isobe1999; do
  scenario=scenarios/gas_periodic_phi03.json
  [ "$config" = isobe1999 ] && scenario=benches/peer/gas_isobe1999.json
  mkdir -p "$work/$config"
  python3 "$peer/side_by_side.py" --vb "$bin" --peer "$work/mdhdd" --scenario "$scenario" \
    --out "$work/$config" --points "$points" --reps 3 --cores "$cores" > "$work/$config/log.txt"
done
python3 - "$work" <<'PY'
import json, sys
w = sys.argv[1]
d = {c: {(r["N"], r["phi"]): r for r in json.load(open(f"{w}/{c}/table.json"))} for c in ("default", "isobe1999")}
print("collisions per wall second (M); vibrobed / peer of the same run in brackets; peak resident bytes per disk")
print(f"{'point':<18}{'peer':>14}{'Isobe 1999':>18}{'default':>18}{'B/disk peer':>13}{'default':>9}")
for key in sorted(d["default"]):
    a, b = d["isobe1999"][key], d["default"][key]
    peer = f"{min(a['peer'], b['peer'])/1e6:.3f}-{max(a['peer'], b['peer'])/1e6:.3f}"
    print(f"N={key[0]:<8} φ={key[1]:<4}{peer:>14}{a['vb']/1e6:>11.3f} ({a['ratio']:.2f}){b['vb']/1e6:>11.3f} ({b['ratio']:.2f})"
          f"{b['peer_bpd']:>13.0f}{b['vb_bpd']:>9.0f}")
PY
echo "raw results: $work"
