#!/usr/bin/env python3
"""Do poured piles and jammed beds come to rest, and what do they cost once there?

The two matrices of the book's settling page (docs/book/src/stability/settling.md), run with a
built vibrobed:

- piles: 400 disks poured from a random start onto a static floor (seed 1, width 20.3, floor
  restitution 0.5, 60 time units): equal (radius 0.5) or polydisperse (radii 0.4-0.6) disks,
  side walls or periodic sides, pair restitution e = 0, 0.5, 0.95, with TC (t_c = 1e-3) or the
  speed cutoff (0.01); 24 runs.
- jam: the *exact jam*, 24 equal disks in a width of exactly 3, 4 or 5 diameters
  (scenarios/hard/bed_at_rest_tc.json), seeds 3-6, 60 time units; 12 runs.
- beds: the shipped bed (scenarios/vibrated_bed.json, 1000 disks, five layers) with TC
  (t_c = 1e-3) in a width of 200.3, pair restitution e = 0.5, 0.7, 0.9, side walls or periodic
  sides, on a static floor or a sine floor at Γ = 0.5 and 0.8; 100 time units; 18 runs.

With --friction MU every run has rough disks: Coulomb friction MU on pairs, floor and side walls.
With --scheme NAME every run takes that `engine.scheme` (the beds otherwise run the exact engine
alone, the piles and the jam `auto`, which is the exact engine for them).

The target: every disk at rest (the summary's `at_rest_since`), and at most one event per disk
per unit time after that time. Each run goes to half its duration, writes a checkpoint and is
resumed to the end; it is then run again to its `at_rest_since` (from the checkpoint when that
comes later), so that the events after rest are counted exactly (a resumed or shortened run is
the same run, bit for bit). Where contact dynamics runs the whole time from rest (the hybrid
scheme's dense beds), its events are the contacts that hold the bed each step, not collisions:
there the rebounds (`approximation.rebounds`) are counted after rest instead, marked `*`. The
events per disk per unit time over the last half are printed too.
Runs go two at a time (--jobs). Wall times are whole-process and only indicative.

Usage, from the project root (builds the engine without the recorder first):
    benches/settling.py                 # piles and jam (minutes on 2 cores: each run also reruns to rest)
    benches/settling.py piles           # one of them
    benches/settling.py beds --jobs 1   # the real beds (about 15 minutes on one core)
    benches/settling.py --bin PATH jam  # another build
    benches/settling.py --friction 0.5 piles
    benches/settling.py --scheme auto beds   # the beds as `auto` runs them (hybrid where they shake)
    benches/settling.py --only "cutoff poly" piles   # the runs whose label holds these words
"""
import argparse
import collections
import concurrent.futures as cf
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PILE = os.path.join(ROOT, "scenarios/hard/pile_poly_walls_cutoff.json")
JAM = os.path.join(ROOT, "scenarios/hard/bed_at_rest_tc.json")
BED = os.path.join(ROOT, "scenarios/vibrated_bed.json")

Result = collections.namedtuple("Result", "label ending t rest events last after held ok wall")


def pile_runs():
    for radius in ("equal", "poly"):
        for sides in ("walls", "periodic"):
            for e in (0.0, 0.5, 0.95):
                for cure in ("tc", "cutoff"):
                    s = json.load(open(PILE))
                    s["name"] = f"pile of 400, {radius}, {sides}, e = {e}, {cure}"
                    s["particles"]["count"] = 400
                    s["particles"]["radius"] = 0.5 if radius == "equal" else {"min": 0.4, "max": 0.6}
                    s["domain"]["width"] = 20.3
                    s["domain"]["x_boundary"] = sides
                    s["floor"]["restitution"] = 0.5
                    s["collisions"] = {"restitution": e}
                    s["collisions"]["tc" if cure == "tc" else "speed_cutoff"] = 1e-3 if cure == "tc" else 0.01
                    s["seed"] = 1
                    s["run"] = {"duration": 30.0, "max_events": 50_000_000}
                    s["engine"] = {"check_invariants": False}
                    yield f"{radius:5} {sides:8} e={e:<4} {cure:6}", s


def jam_runs():
    for width in (3, 4, 5):
        for seed in (3, 4, 5, 6):
            s = json.load(open(JAM))
            s["name"] = f"exact jam, width {width}, seed {seed}"
            s["domain"]["width"] = float(width)
            s["seed"] = seed
            s["run"]["duration"] = 30.0
            s["engine"] = {"check_invariants": False}
            yield f"width {width} seed {seed}", s


def bed_runs():
    for e in (0.5, 0.7, 0.9):
        for sides in ("walls", "periodic"):
            for gamma in (0.0, 0.5, 0.8):
                s = json.load(open(BED))
                s["name"] = f"shipped bed, e = {e}, {sides}, Γ = {gamma}"
                s["domain"]["width"] = 200.3
                s["domain"]["x_boundary"] = sides
                s["collisions"] = {"restitution": e, "tc": 1e-3}
                s["floor"].pop("gamma")
                if gamma > 0:
                    s["floor"]["gamma"] = gamma
                s["run"] = {"duration": 50.0, "warmup": 0.0, "max_events": 50_000_000}
                # The exact engine's settling (`auto` would run these beds on the hybrid scheme).
                s["engine"] = {"scheme": "event-driven", "check_invariants": False}
                yield f"e={e:<4} {sides:8} gamma={gamma:g}", s


MATRICES = {"piles": (pile_runs, 60.0), "jam": (jam_runs, 60.0), "beds": (bed_runs, 100.0)}


def events(summary):
    return sum(summary["events"].values())


def approximation(summary, key):
    """A field of the summary's `approximation` (present once contact dynamics has run), else 0."""
    return (summary.get("approximation") or {}).get(key, 0)


def roughen(scenario, mu):
    """Coulomb friction `mu` on pairs, floor and side walls (rough disks)."""
    scenario["collisions"]["friction"] = mu
    scenario["floor"]["friction"] = mu
    if scenario["domain"].get("x_boundary") == "walls":
        scenario["domain"]["wall_friction"] = mu
    return scenario


def run_one(binary, label, scenario, work, duration):
    key = "".join(c if c.isalnum() else "_" for c in label)
    path = os.path.join(work, key + ".json")
    ckpt = os.path.join(work, key + ".ckpt")
    first, second = (os.path.join(work, key + s) for s in (".a.json", ".b.json"))
    json.dump(scenario, open(path, "w"))
    t0 = time.perf_counter()
    run = subprocess.run([binary, "run", path, "--quiet", "--checkpoint", ckpt, "--summary", first],
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if not os.path.exists(first):
        return failed(label, run, 0.0, 0, t0)
    a = json.load(open(first))
    half = a["sim_time"]
    b = a
    if a["ending"] == "completed":
        # The resumed run checkpoints elsewhere: the half-time checkpoint is needed again when
        # rest comes after it (`summary_until`).
        end_ckpt = os.path.join(work, key + ".end.ckpt")
        run = subprocess.run([binary, "resume", ckpt, "--quiet", "--set", f"run.duration={duration}",
                              "--checkpoint", end_ckpt, "--summary", second],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if not os.path.exists(second):
            return failed(label, run, half, events(a), t0)
        b = json.load(open(second))
    n = a["particles"]
    last = (events(b) - events(a)) / n / (duration - half) if b["ending"] == "completed" else None
    rest = b.get("at_rest_since")
    after, held = None, False
    if last is not None and rest is not None and rest < duration:
        r = summary_until(binary, path, ckpt, half, rest, os.path.join(work, key + ".r.json"))
        if r is not None:
            after, held = after_rest(b, r, n, duration - rest)
    wall = time.perf_counter() - t0
    ok = after is not None and after <= 1.0
    return Result(label, b["ending"], b["sim_time"], rest, events(b), last, after, held, ok, wall)


def after_rest(end, rest, n, span):
    """Events per disk per unit time between the summaries at rest and at the end (`span`
    apart), and whether they are contact dynamics' rebounds: where contact dynamics ran the
    whole span (to a step), its event counts are the contacts that held the bed each step, not
    collisions, and what would be a collision there is a contact that rebounded."""
    dense = approximation(end, "dense_time") - approximation(rest, "dense_time")
    if abs(dense - span) <= 1e-3 * span:
        return (approximation(end, "rebounds") - approximation(rest, "rebounds")) / n / span, True
    return (events(end) - events(rest)) / n / span, False


def summary_until(binary, path, ckpt, half, rest, summary):
    """The run's summary at its `at_rest_since`: run again to that time (from the checkpoint at
    half time when rest comes later), bit for bit the same run."""
    if rest >= half:
        command = [binary, "resume", ckpt]
    else:
        command = [binary, "run", path]
    subprocess.run(command + ["--quiet", "--set", f"run.duration={rest}", "--summary", summary],
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return json.load(open(summary)) if os.path.exists(summary) else None


def failed(label, run, t, ev, t0):
    """A run that wrote no summary: its exit code, and the last line it printed."""
    said = run.stderr.strip().splitlines()[-1:] or [""]
    print(f"{label}: exit {run.returncode}: {said[0]}", file=sys.stderr)
    return Result(label, f"failed ({run.returncode})", t, None, ev, None, None, False, False,
                  time.perf_counter() - t0)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("matrix", nargs="*", help="piles, jam, beds (default: piles and jam)")
    p.add_argument("--bin", help="vibrobed binary (default: build and use target/release/vibrobed)")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--friction", type=float, help="Coulomb friction on pairs, floor and walls")
    p.add_argument("--scheme", help="engine.scheme for every run (e.g. auto)")
    p.add_argument("--only", metavar="WORDS",
                   help="only the runs whose label holds every word (e.g. 'cutoff poly')")
    args = p.parse_args()
    matrices = args.matrix or ["piles", "jam"]
    unknown = [m for m in matrices if m not in MATRICES]
    if unknown:
        p.error(f"unknown matrix {unknown[0]!r} (piles, jam or beds)")
    binary = args.bin
    if binary is None:
        subprocess.run(["cargo", "build", "--release", "--no-default-features", "-q"], cwd=ROOT, check=True)
        target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
        binary = os.path.join(target, "release", "vibrobed")
    work = tempfile.mkdtemp(prefix="vibrobed-settling-")
    for name in matrices:
        make, duration = MATRICES[name]
        runs = list(make())
        if args.only:
            runs = [(label, s) for label, s in runs if all(w in label for w in args.only.split())]
        if args.friction is not None:
            runs = [(label, roughen(s, args.friction)) for label, s in runs]
        for _, s in runs:
            if args.scheme:
                s.setdefault("engine", {})["scheme"] = args.scheme
        rough = "" if args.friction is None else f" (mu = {args.friction:g} on pairs, floor, walls)"
        rough += "" if args.scheme is None else f" (engine.scheme = {args.scheme})"
        print(f"\n{name}{rough}: at rest from (first sample time after which every disk stays at rest), "
              f"events per disk per unit time over t = {duration / 2:g}-{duration:g}")
        print(f"{'run':34}{'ending':>13}{'t':>7}{'at rest':>9}{'events':>12}{'last half':>11}"
              f"{'after rest':>11}  target")
        with cf.ThreadPoolExecutor(args.jobs) as pool:
            futures = [pool.submit(run_one, binary, label, s, work, duration) for label, s in runs]
            results = [f.result() for f in futures]
        for r in results:
            rest_s = "-" if r.rest is None else f"{r.rest:g}"
            last_s = "-" if r.last is None else f"{r.last:.3g}"
            after_s = "-" if r.after is None else f"{r.after:.3g}" + ("*" if r.held else "")
            print(f"{r.label:34}{r.ending:>13}{r.t:>7.2f}{rest_s:>9}{r.events:>12}{last_s:>11}{after_s:>11}  "
                  f"{'met' if r.ok else 'not met'}")
        if any(r.held for r in results):
            print("* contact dynamics all the way from rest: the contacts that rebounded, not the "
                  "contacts holding the bed")
        print(f"{sum(r.ok for r in results)} of {len(results)} meet the target "
              f"({sum(r.wall for r in results):.0f} s of runs)")
    print(f"\nsummaries and checkpoints: {work}")


if __name__ == "__main__":
    sys.exit(main())
