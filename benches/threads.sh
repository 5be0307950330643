#!/usr/bin/env bash
# The approximate schemes on several cores: wall time of the event loop (the summary's
# `wall_seconds`, set-up excluded) against `engine.threads`, for the vibrated bed at N = 10³, 10⁴
# and 10⁵ (about five layers: width N/5) and the elastic gas at φ = 0.3 and N = 10⁴, with the
# time-step and space-time schemes, and the exact engine (one core) beside them. The thread counts
# are run in turn, REPEATS times each (alternated, so that a slow spell of the machine touches
# them all); the table gives medians, and the speed-up against one thread. A run during which
# other processes used more than a tenth of a core (from /proc/stat, less the run's own CPU time)
# is run again, up to TRIES (40) times; the table says how many of the runs it kept were undisturbed.
#
# Run from the project root:  benches/threads.sh                 (1 and 2 threads, ~3 min on 2 cores)
#                             THREADS="1 2 4 8" benches/threads.sh
#                             REPEATS=5 SCENES="bed1e4 gas" SCHEMES=time-step benches/threads.sh
#                             STRIPS="bed1e4:25 gas:4" SCHEMES=space-time benches/threads.sh
# STRIPS gives the space-time scheme's engine.strips per scene (absent: the scenario's, 1).
# On a shared machine, run it alone: it measures wall time.
set -euo pipefail
threads="${THREADS:-1 2}"
repeats="${REPEATS:-3}"
scenes="${SCENES:-bed1e3 bed1e4 bed1e5 gas}"
schemes="${SCHEMES:-time-step space-time}"
cargo build --release -q
bin="${CARGO_TARGET_DIR:-target}/release/vibrobed"
work="$(mktemp -d)"

# The overrides of a scene: scenario, then --set arguments (durations keep a run to seconds).
scene() {
  case "$1" in
    bed1e3) echo "scenarios/vibrated_bed.json particles.count=1000 domain.width=200 run.duration=200 run.warmup=50" ;;
    bed1e4) echo "scenarios/vibrated_bed.json particles.count=10000 domain.width=2000 run.duration=40 run.warmup=10" ;;
    bed1e5) echo "scenarios/vibrated_bed.json particles.count=100000 domain.width=20000 run.duration=4 run.warmup=1" ;;
    gas) echo "scenarios/gas_periodic_phi03.json particles.count=10000 domain.width=90 run.duration=40 run.warmup=10" ;;
    *) echo "benches/threads.sh: unknown scene $1" >&2; exit 2 ;;
  esac
}

# Runs `vibrobed run ARGS --summary FILE` until no other process disturbed it.
busy() { awk '/^cpu /{print $2+$3+$4+$7+$8+$9}' /proc/stat; }
hz="$(getconf CLK_TCK)"
undisturbed() {
  local out="$1"; shift
  for try in $(seq "${TRIES:-40}"); do
    local b0 t0 b1 t1 u s
    b0="$(busy)"; t0="$(date +%s.%N)"
    /usr/bin/time -f "%U %S" -o "$work/time" "$bin" run "$@" --quiet --summary "$out"
    b1="$(busy)"; t1="$(date +%s.%N)"
    read -r u s < "$work/time"
    if python3 -c "import sys; sys.exit(0 if ($b1-$b0)/$hz-($u+$s) < 0.1*($t1-$t0) else 1)"; then
      return 0
    fi
    sleep 2
  done
  echo "benches/threads.sh: $out: disturbed ${TRIES:-40} times; kept the last" >&2
  touch "$out.disturbed"
}

for name in $scenes; do
  read -r -a spec <<< "$(scene "$name")"
  sets=()
  for s in "${spec[@]:1}"; do sets+=(--set "$s"); done
  strips=()
  for entry in ${STRIPS:-}; do
    if [[ "${entry%%:*}" == "$name" ]]; then strips=(--set "engine.strips=${entry#*:}"); fi
  done
  for rep in $(seq "$repeats"); do
    undisturbed "$work/$name.exact.$rep.json" "${spec[0]}" "${sets[@]}"
    for scheme in $schemes; do
      for t in $threads; do
        extra=()
        if [[ "$scheme" == space-time ]]; then extra=("${strips[@]}"); fi
        undisturbed "$work/$name.$scheme.$t.$rep.json" "${spec[0]}" "${sets[@]}" "${extra[@]}" \
          --set engine.scheme=$scheme --set engine.threads="$t"
      done
    done
  done
done

python3 - "$work" "$threads" "$scenes" "$schemes" <<'PY'
import glob, json, statistics, sys
work, threads, scenes, schemes = sys.argv[1], sys.argv[2].split(), sys.argv[3].split(), sys.argv[4].split()
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
import os
print(f"machine: {cpu}, {os.cpu_count()} cores; medians of the runs of each cell")
def med(pattern):
    runs = [json.load(open(f)) for f in sorted(glob.glob(f"{work}/{pattern}")) if f.endswith(".json")]
    return statistics.median(r["wall_seconds"] for r in runs), runs[0]
import os.path
def quiet(pattern):
    runs = sorted(glob.glob(f"{work}/{pattern}"))
    return f"{sum(not os.path.exists(f + '.disturbed') for f in runs)}/{len(runs)}"
head = f"{'scene':<8}{'N':>8} {'scheme':<13}{'sim time':>9}" + "".join(f"{f'{t} thr (s)':>12}" for t in threads) + "".join(f"{f'×{t}':>7}" for t in threads[1:]) + "   undisturbed runs"
print(head)
for name in scenes:
    wall, s = med(f"{name}.exact.*.json")
    print(f"{name:<8}{s['particles']:>8} {'event-driven':<13}{s['sim_time']:>9g}{wall:>12.3f}" + " " * (7 * (len(threads) - 1) + 12 * (len(threads) - 1) + 3) + quiet(f"{name}.exact.*.json"))
    for scheme in schemes:
        walls = [med(f"{name}.{scheme}.{t}.*.json")[0] for t in threads]
        row = f"{name:<8}{s['particles']:>8} {scheme:<13}{s['sim_time']:>9g}" + "".join(f"{w:>12.3f}" for w in walls)
        row += "".join(f"{walls[0] / w:>7.2f}" for w in walls[1:])
        row += "   " + " ".join(quiet(f"{name}.{scheme}.{t}.*.json") for t in threads)
        print(row)
PY
echo "summaries: $work"
