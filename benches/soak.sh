#!/usr/bin/env bash
# The soak test of checkpoints (not in CI: some 20 minutes at the default size on a free core).
#
# The vibrated bed runs to an event budget twice with the same command line: once without a
# stop, and once killed with SIGKILL at KILLS random moments (some land while a checkpoint is
# being written) and resumed from its checkpoint each time. The two summaries must be equal bit
# for bit, apart from the fields that measure the process (wall_seconds, collisions_per_second,
# engine.bytes_per_disk).
#
#   benches/soak.sh                              # 10^9 events, 5 kills
#   EVENTS=100000000 KILLS=5 benches/soak.sh     # a shorter soak
#
# Environment: EVENTS (event budget, default 1e9), KILLS (default 5), EVERY (simulated time
# between checkpoints, default 1000), SEED (of the kill moments, default: random), VIBROBED (the
# binary, default: the release build), SOAK_DIR (where the files go, default: a new temporary
# directory, kept).
set -euo pipefail
cd "$(dirname "$0")/.."

events="${EVENTS:-1000000000}"
kills="${KILLS:-5}"
every="${EVERY:-1000}"
seed="${SEED:-$RANDOM}"
bin="${VIBROBED:-${CARGO_TARGET_DIR:-target}/release/vibrobed}"
dir="${SOAK_DIR:-$(mktemp -d -t vibrobed-soak.XXXXXX)}"
mkdir -p "$dir"
[[ -x "$bin" ]] || cargo build --release
RANDOM="$seed"

# The run: an event budget well inside the duration, a sample every time unit.
args=(scenarios/vibrated_bed.json --quiet
  --set run.duration=1000000 --set "run.max_events=$events" --set output.sample_interval=1
  --checkpoint-every "$every")

echo "soak: $events events, $kills kills (seed $seed), checkpoint every $every; files in $dir"

start=$(date +%s.%N)
"$bin" run "${args[@]}" --checkpoint "$dir/straight.ckpt" --summary "$dir/straight.json"
wall=$(echo "$(date +%s.%N) - $start" | bc)
echo "uninterrupted: ${wall} s"

# Kill moments: KILLS random fractions of the uninterrupted wall time, spread over the run.
ckpt="$dir/killed.ckpt"
rm -f "$ckpt" "$ckpt.tmp"
part=0
killed=0
while (( killed < kills )); do
  if [[ -f "$ckpt" ]]; then
    cmd=("$bin" resume "$ckpt" --quiet --summary "$dir/killed.json")
  else
    cmd=("$bin" run "${args[@]}" --checkpoint "$ckpt" --summary "$dir/killed.json")
  fi
  # Between 0.2 and 1.0 of a (KILLS+1)-th of the run, in milliseconds.
  slice=$(echo "$wall * 1000 / ($kills + 1)" | bc)
  delay_ms=$(( slice / 5 + RANDOM % (slice * 4 / 5 + 1) ))
  [[ -f "$ckpt" ]] || echo "part $part: no checkpoint yet: from the start"
  "${cmd[@]}" &
  pid=$!
  sleep "$(echo "scale=3; $delay_ms / 1000" | bc)"
  if kill -KILL "$pid" 2>/dev/null; then
    wait "$pid" 2>/dev/null || true
    killed=$((killed + 1))
    at=$(ls -l --time-style=+%s "$ckpt" 2>/dev/null | awk '{print $5 " bytes"}' || echo "none")
    echo "part $part: SIGKILL after ${delay_ms} ms (checkpoint: ${at}; temporary left: $(ls "$ckpt.tmp" 2>/dev/null || echo none))"
  else
    wait "$pid"
    echo "part $part ended before its kill"
    break
  fi
  part=$((part + 1))
done
if [[ ! -f "$dir/killed.json" ]] || (( killed == kills )); then
  if [[ -f "$ckpt" ]]; then
    "$bin" resume "$ckpt" --quiet --summary "$dir/killed.json"
    echo "part $part: resumed to the end"
  else
    "$bin" run "${args[@]}" --checkpoint "$ckpt" --summary "$dir/killed.json"
    echo "part $part: no checkpoint yet, run from the start to the end"
  fi
fi

python3 - "$dir/straight.json" "$dir/killed.json" <<'EOF'
import json, sys
def physics(path):
    s = json.load(open(path))
    for key in ("wall_seconds", "collisions_per_second"):
        s.pop(key)
    s["engine"].pop("bytes_per_disk")
    return s
a, b = (physics(p) for p in sys.argv[1:3])
events = sum(a["events"].values())
print(f"ending {a['ending']}, sim_time {a['sim_time']!r}, {events} events, "
      f"temperature {a['temperature']['mean']!r}, com_height {a['com_height']!r}")
if a != b:
    diff = [k for k in a if a[k] != b.get(k)]
    sys.exit(f"soak: the summaries differ in {diff}")
print("soak: the killed and resumed run equals the uninterrupted run, bit for bit")
EOF
