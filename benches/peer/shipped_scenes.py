#!/usr/bin/env python3
"""The shipped vibrated bed beside the shipped gas: events per whole-process wall second.

The peer benchmark's gas is an elastic gas at four points; users run beds. This measures the
shipped bed (`scenarios/vibrated_bed.json`, 1000 disks, as shipped) and the shipped gas
(`scenarios/gas_periodic_phi03.json`, 2500 disks, without its warm-up) the same way: runs of T
and 2T pinned to one core (set-up and warm-up cancel in the difference), medians of the reps,
one run at a time. Events are every event the engine's loop fired (the summary's `events`: pair
collisions, floor impacts, stale events, shell exits, re-mappings, ...); pair collisions are
quoted beside them.

Usage: shipped_scenes.py --vb BIN [--core K] [--reps R]   (run from the project root)
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time

# (name, scenario, T, overrides): T long enough for about a second of the shorter run.
SCENES = [
    ("vibrated_bed.json (N = 10³)", "scenarios/vibrated_bed.json", 600.0, []),
    ("gas_periodic_phi03.json (N = 2500)", "scenarios/gas_periodic_phi03.json", 333.3,
     ["run.warmup=0"]),
]


def run(vb, core, scenario, duration, sets):
    """Wall seconds, events and pair collisions of one whole-process run."""
    with tempfile.TemporaryDirectory() as d:
        summary = os.path.join(d, "s.json")
        argv = ["taskset", "-c", str(core), vb, "run", scenario, "--quiet", "--summary", summary,
                "--set", f"run.duration={duration}"]
        for s in sets:
            argv += ["--set", s]
        t0 = time.perf_counter()
        subprocess.run(argv, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wall = time.perf_counter() - t0
        events = json.load(open(summary))["events"]
    return wall, sum(events.values()), events["pair"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vb", required=True)
    ap.add_argument("--core", type=int, default=0)
    ap.add_argument("--reps", type=int, default=3)
    a = ap.parse_args()
    print(f"\n{'scene':<38}{'M events/s':>12}{'M pairs/s':>11}  (each rep's events/s)")
    for name, scenario, T, sets in SCENES:
        rates = []
        for _ in range(a.reps):
            w1, e1, p1 = run(a.vb, a.core, scenario, T, sets)
            w2, e2, p2 = run(a.vb, a.core, scenario, 2 * T, sets)
            if w2 > w1:
                rates.append(((e2 - e1) / (w2 - w1), (p2 - p1) / (w2 - w1)))
        if not rates:
            print(f"{name:<38}{'—':>12}")
            continue
        ev = statistics.median(r[0] for r in rates)
        pairs = statistics.median(r[1] for r in rates)
        each = ", ".join(f"{r[0] / 1e6:.3f}" for r in rates)
        print(f"{name:<38}{ev / 1e6:>12.3f}{pairs / 1e6:>11.3f}  ({each})")


if __name__ == "__main__":
    main()
