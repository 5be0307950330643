#!/usr/bin/env bash
# The approximate schemes' results by hash: a SHA-256 of each summary (machine-dependent fields
# and engine.threads removed) of the bed (N = 10³, 10⁴), the gas (N = 10⁴) and the rough bed
# (N = 4000), short runs, with both schemes on 1, 2 and 3 threads. The hashes of one build must
# not depend on the threads; diff two builds' outputs to see that a change kept the results.
# Run from the project root:  benches/scheme-hashes.sh BINARY [THREADS]
set -euo pipefail
bin="$(realpath "$1")"; threads="${2:-1 2 3}"; root="$PWD"
work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
strip() { python3 -c '
import json,sys,hashlib
s=json.load(open(sys.argv[1]))
s.pop("wall_seconds",None); s.pop("collisions_per_second",None)
e=s.get("engine")
if isinstance(e,dict):
  e.pop("bytes_per_disk",None); e.pop("threads",None); e.pop("bytes",None)
print(hashlib.sha256(json.dumps(s,sort_keys=True).encode()).hexdigest()[:16])' "$1"; }
declare -A scenes=(
 [bed1e4]="scenarios/vibrated_bed.json --set particles.count=10000 --set domain.width=2000 --set run.duration=6 --set run.warmup=2"
 [bed1e3]="scenarios/vibrated_bed.json --set particles.count=1000 --set domain.width=200 --set run.duration=20 --set run.warmup=5"
 [gas]="scenarios/gas_periodic_phi03.json --set particles.count=10000 --set domain.width=90 --set run.duration=6 --set run.warmup=2"
 [rough]="scenarios/rough_vibrated_bed.json --set particles.count=4000 --set domain.width=800 --set run.duration=6 --set run.warmup=2"
)
for name in bed1e3 bed1e4 gas rough; do
  for scheme in time-step space-time; do
    for t in $threads; do
      (cd $root && "$bin" run ${scenes[$name]} --set engine.scheme=$scheme --set engine.threads=$t --quiet --summary "$work/s.json") || echo "exit $? $name"
      echo "$(strip "$work/s.json") $name $scheme $t"
    done
  done
done
