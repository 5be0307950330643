#!/usr/bin/env python3
"""The book's numbers from runs, made by this script and checked against today's build.

Every number the book (and the README) quotes from a run of the shipped scenarios sits between
markers in the page's Markdown, `<!-- n:NAME -->…<!-- /n -->` (invisible on the page). This
script runs what makes them and compares:

- the README's fourth step: the shipped bed's temperature and centre of mass at Γ = 3 and 6;
- Getting started, the worked example: the shipped bed's full run (its counts, energies,
  temperatures, centre of mass, floor pressure and profile table); the same run's collisions
  (Python page, Overhead) and first rows of its fields (Fields page, CSV);
- the quick-try settings the README and the book give (`run.duration`, `run.warmup`): they must
  resolve the bed's state (the summary has `state`), and the floor periods they leave are quoted;
- the packing-fraction sentence (summary page, Getting started): a pile at rest
  (`scenarios/hard/pile_equal_periodic_tc.json`) in bins half a diameter high reads above the
  densest packing of the plane (0.907) and never above 1; its largest value is quoted;
- the summary page: the floor's pressure over the weight of the shipped scenes' full runs, the
  velocity distributions' kurtosis, and the shipped bed's
  motion against the floor's phase (lockings, undulation, the gap's widest, the pressure's peak);
- the stability page's table of hard cases, remade from itself: each row's files run as shipped,
  their events per unit time and times to rest;
- the sweeps page's worked example: `scenarios/sweeps/temperature_vs_drive.json` on two workers,
  its points table, fits (plain, over the dense part, the centre of mass's rise above a fitted
  offset) and local slopes, its figure (`figures/sweep-temperature.svg`, byte for byte), and its
  CPU time (checked to a factor of 2: a machine differs from another; everything else is
  deterministic and must match to the digits quoted; its wall time and the machine that took it
  are written, not checked);
- the summary page's bed states of the shipped scenes (the shortened runs of
  `tests/suite/bed_state.rs`: each state with the indicators that decided it) and the pressure
  of `deep_bed.json` (as shipped: about two minutes of CPU, on the second core beside the parts
  before the sweep);
- the phase-diagram page: `scenarios/sweeps/phase_diagram.json` as shipped on two workers (24
  runs, about 13 s of CPU), its table of states and indicators, its figure
  (`figures/phase-diagram.svg`, byte for byte), the ranges its comparison quotes and its CPU
  time (to a factor of 2); and the same sweep without its cure (no `collisions.tc`, 14 s of
  CPU): the runs that change state, and how long the densest ride in contact dynamics;
- the summary page's equation of state (the elastic gas of `tests/suite/equation_of_state.rs`:
  Z against Henderson's); the Physics page's rough bed against the smooth one (temperatures,
  pair collisions) and its discharge against the orifice width
  (`scenarios/sweeps/beverloo.json`, 18 runs: rates, the Beverloo fit and its CPU time);
- the Python page's account of the example notebook's sweep (`examples/gamma_sweep.ipynb`,
  remade as a sweep file: the same runs): its fit T ∝ Γ^δ, states and indicators.

    python3 docs/book/numbers.py [--bin PATH]          # check (exit 1 naming each difference)
    python3 docs/book/numbers.py [--bin PATH] --write  # rewrite the numbers in the pages

`--bin` defaults to `vibrobed` on PATH. A change that moves a run (the engine, a scenario)
moves the book's numbers: run with --write, and read the prose around them again. `.ci/run`
runs the check (about 260 s of CPU, 3 to 4 minutes on the machine's two cores).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BOOK = ROOT / "docs" / "book" / "src"
MARK = re.compile(r"<!-- n:([a-z0-9-]+) -->(.*?)<!-- /n -->", re.S)
# The pages that give the shipped bed's quick try.
QUICK_PAGES = ["getting-started.md", "sweeps.md", "outputs/python.md"]
# A part's result keyed `figure:PATH` is a figure the binary draws, compared with the book's
# `docs/book/src/PATH` byte for byte.
FIGURE = "figure:"
# Timing regions: compared to a factor, not to the digit; None: written, not compared (the wall
# time of two workers on a machine shared with other work).
TIMING = {"tvd-cpu": 2.0, "tvd-wall": None, "tvd-machine": None,
          "pd-cpu": 2.0, "pd-wall": None, "pd-machine": None,
          "pd-exact-cpu": 2.0, "pd-exact-wall": None, "bev-cpu": 2.0}


def run(binary: str, *args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    out = subprocess.run([binary, *args], cwd=cwd, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"numbers.py: `vibrobed {' '.join(args)}` exited {out.returncode}:\n{out.stderr}")
    return out


def summary_of(binary: str, scenario: str, sets: list[str], tmp: Path, name: str) -> dict:
    path = tmp / f"{name}.json"
    args = ["run", scenario, "--quiet", "--summary", str(path)]
    for s in sets:
        args += ["--set", s]
    run(binary, *args)
    return json.loads(path.read_text())


def thousands(n: float) -> str:
    return f"{round(n):,}".replace(",", " ")


def sig(x: float, digits: int = 3) -> str:
    """`x` to `digits` significant digits, as the book's tables write them."""
    if x == 0 or not math.isfinite(x):
        return f"{x:.{digits - 1}f}"
    decimals = max(digits - 1 - math.floor(math.log10(abs(x))), 0)
    return f"{x:.{decimals}f}".replace("-", "−")


def power_of_ten(x: float) -> str:
    """`2.4·10⁻¹⁴`."""
    exponent = math.floor(math.log10(abs(x)))
    mantissa = x / 10**exponent
    sup = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
    return f"{mantissa:.1f}·10{str(exponent).translate(sup)}"


def worked_example(binary: str, tmp: Path) -> dict[str, str]:
    """Getting started: the shipped bed's full run; also its collisions (Python page) and the
    first row of its fields (Fields page): measuring the fields changes nothing else."""
    fields = tmp / "fields.csv"
    path = tmp / "bed.json"
    run(binary, "run", "scenarios/vibrated_bed.json", "--quiet", "--summary", str(path),
        "--fields", str(fields))
    s = json.loads(path.read_text())
    with open(fields) as f:
        rows_of = csv.reader(f)
        header, first = next(rows_of), next(rows_of)
    row = ",".join(v if k in ("i", "j") else f"{float(v):.3f}" for k, v in zip(header, first))
    p = s["profiles"]
    rows = ["| height | number density | packing fraction | T_x | T_y | mean v_y |",
            "|---:|---:|---:|---:|---:|---:|"]
    # Every second bin from the third (centre 0.965) to height 11.
    for k in range(2, 24, 2):
        rows.append("| " + " | ".join([
            sig(p["height"][k]), f"{p['density'][k]:.3f}", f"{p['packing_fraction'][k]:.3f}",
            f"{p['temperature_x'][k]:.3f}", f"{p['temperature_y'][k]:.3f}",
            f"{p['velocity_y'][k]:.3f}".replace("-", "−"),
        ]) + " |")
    e = s["energy"]
    pressure = s["floor_pressure"]["measured"] / s["floor_pressure"]["weight"]
    return {
        "gs-pairs": thousands(s["events"]["pair"]),
        "gs-floor": thousands(s["events"]["floor"]),
        "gs-balance": power_of_ten(e["balance_error"]),
        "gs-injected": thousands(e["injected"]),
        "gs-dissipated": thousands(e["dissipated"]),
        "gs-tx": f"{s['temperature']['x']:.3f}",
        "gs-ty": f"{s['temperature']['y']:.3f}",
        "gs-com": f"{s['com_height']:.2f}",
        "gs-impacts": f"{s['impacts_per_unit_time']:.0f}",
        "gs-bin": f"{p['height'][1] - p['height'][0]:.2f}",
        "gs-table": "\n".join(rows),
        "gs-pressure": f"{pressure:.4f}",
        "py-collisions": thousands(sum(s["events"][k] for k in ("pair", "wall", "lid", "floor"))),
        "fields-csv": "\n".join(["```text", ",".join(header), row, "...", "```"]),
    }


def readme_gamma(binary: str, tmp: Path) -> dict[str, str]:
    """The README's fourth step: the shipped bed as shipped and at Γ = 6, their mean granular
    temperatures and centres of mass."""
    made = {}
    for name, sets in (("readme-3", []), ("readme-6", ["floor.gamma=6"])):
        s = summary_of(binary, "scenarios/vibrated_bed.json", sets, tmp, name)
        made[f"{name}-t"] = sig(s["temperature"]["mean"], 2)
        made[f"{name}-com"] = sig(s["com_height"], 2)
    return made


def quick_try(binary: str, tmp: Path) -> dict[str, str]:
    """The quick-try settings wherever the README and the book give them resolve the state."""
    found = set()
    for page in [ROOT / "README.md", *(BOOK / p for p in QUICK_PAGES)]:
        text = page.read_text()
        for d, w in re.findall(r"run\.duration=(\d+)\"?,? (?:--set )?\"?run\.warmup=(\d+)", text):
            found.add((float(d), float(w), page.relative_to(ROOT)))
    if not found:
        sys.exit("numbers.py: no quick-try settings (run.duration=…, run.warmup=…) found")
    periods = set()
    scenario = json.loads((ROOT / "scenarios/vibrated_bed.json").read_text())
    for d, w in sorted({(d, w) for d, w, _ in found}):
        s = summary_of(binary, "scenarios/vibrated_bed.json",
                       [f"run.duration={d:g}", f"run.warmup={w:g}"], tmp, "quick")
        if "state" not in s:
            pages = sorted(str(p) for dd, ww, p in found if (dd, ww) == (d, w))
            sys.exit(f"numbers.py: the quick try run.duration={d:g} run.warmup={w:g} "
                     f"({', '.join(pages)}) resolves no bed state")
        periods.add(f"{(d - w) * scenario['floor']['frequency']:g}")
    if len(periods) != 1:
        sys.exit(f"numbers.py: the quick-try settings differ between pages: {sorted(found)}")
    return {"quick-periods": periods.pop()}


def packing_at_rest(binary: str, tmp: Path) -> dict[str, str]:
    """A pile at rest in bins half a diameter high: above 0.907 somewhere, never above 1."""
    s = summary_of(binary, "scenarios/hard/pile_equal_periodic_tc.json",
                   ["run.duration=40", "run.warmup=30", "output.profile_height=12",
                    "output.profile_bins=24", "output.sample_interval=1"], tmp, "rest")
    phi = s["profiles"]["packing_fraction"]
    top = max(phi)
    if not 0.907 < top <= 1.0:
        sys.exit(f"numbers.py: the pile at rest reads at most {top} in 0.5-diameter bins: the "
                 "packing-fraction sentence (above 0.907, never above 1) is wrong")
    return {"rest-packing": f"{math.floor(top * 100) / 100:.2f}"}


def summary_page(binary: str, tmp: Path) -> dict[str, str]:
    """The summary page: the floor's pressure over the weight of the shipped scenes' full runs
    (`deep_bed.json`, 100 s of runs, is not remade), the velocity distributions' kurtosis, and
    the shipped bed's motion against the floor's phase."""
    made = {}
    pressure_runs = {
        "vibrated-bed": ("scenarios/vibrated_bed.json", []),
        "leidenfrost": ("scenarios/leidenfrost.json", []),
        "dilute": ("scenarios/vibrofluidized_dilute.json", []),
        "ball": ("scenarios/bouncing_ball.json", []),
        "at-rest": ("scenarios/hard/bed_at_rest_tc.json", []),
        "time-step": ("scenarios/vibrated_bed.json",
                      ["engine.scheme=time-step", "run.duration=100"]),
        "space-time": ("scenarios/vibrated_bed.json",
                       ["engine.scheme=space-time", "run.duration=100"]),
    }
    runs = {}
    for name, (scenario, sets) in pressure_runs.items():
        runs[name] = summary_of(binary, scenario, sets, tmp, f"pressure-{name}")
        p = runs[name]["floor_pressure"]
        made[f"p-{name}"] = f"{p['measured'] / p['weight']:.4f}"
    # The gas over 200 units (its scenario's 20 hold too few samples for a fourth moment).
    for name, scenario, sets in (("gas", "gas_periodic_phi03", ["run.duration=200"]),
                                 ("bed", "vibrated_bed", [])):
        s = summary_of(binary, f"scenarios/{scenario}.json",
                       ["output.velocity_distribution=true", *sets], tmp, f"kurtosis-{name}")
        v = s["velocity_distribution"]
        digits = 3 if name == "gas" else 2
        for axis in ("x", "y"):
            made[f"kurtosis-{name}-{axis}"] = f"{v[axis]['kurtosis']:.{digits}f}"
    bed = runs["vibrated-bed"]
    phase = bed["phase"]
    edge = phase["lower_edge"]  # the gap above the floor
    top = max(range(len(edge)), key=edge.__getitem__)
    com = max(range(len(edge)), key=phase["com_height"].__getitem__)
    made.update({
        "phase-locking": f"{phase['com_locking']:.2f}",
        "phase-locking-two": f"{phase['com_locking_two_periods']:.2f}",
        "phase-undulation": f"{phase['undulation']:.2f}",
        "phase-edge-top": f"{edge[top]:.2f}",
        "phase-edge-top-at": f"{round(phase['phase'][top], 2):g}",
        "phase-com-top-at": f"{round(phase['phase'][com], 2):g}",
        "phase-pressure-peak": f"{max(phase['pressure']) / bed['floor_pressure']['weight']:.1f}",
        "phase-samples": f"{sum(phase['samples'])}",
    })
    return made


def two(x: float) -> str:
    """An indicator to two decimals, `0` when it is nothing."""
    return "0" if round(x, 2) == 0 else f"{x:.2f}"


def rough_bed(binary: str, tmp: Path) -> dict[str, str]:
    """The Physics page's rough bed against the smooth one: the shipped bed with μ = 0.5 on pairs
    and floor, and as shipped; their temperatures and pair collisions over the 200 units."""
    made = {}
    for name, sets in (("rough", ["collisions.friction=0.5", "floor.friction=0.5"]),
                       ("smooth", [])):
        s = summary_of(binary, "scenarios/vibrated_bed.json", sets, tmp, f"bed-{name}")
        made[f"{name}-t"] = f"{s['temperature']['mean']:.2f}"
        made[f"{name}-pairs"] = f"{s['events']['pair'] / 1e6:.2f}·10⁶"
    return made


# The equation of state's runs, as `tests/suite/equation_of_state.rs` makes them: (φ, duration).
EOS_RUNS = [(0.1, 320), (0.2, 150), (0.3, 80), (0.4, 50)]


def equation_of_state(binary: str, tmp: Path) -> dict[str, str]:
    """The summary page's equation of state: the elastic gas of the test (2500 disks in a
    periodic box, seed 7), its compressibility factor Z against Henderson's at each φ, and the
    largest difference, rounded up to a tenth of a per cent."""
    measured, henderson, worst = [], [], 0.0
    for phi, duration in EOS_RUNS:
        scene = tmp / f"eos-scene-{phi}.json"
        scene.write_text(json.dumps({
            "name": "eos", "seed": 7,
            "domain": {"width": 50, "x_boundary": "periodic", "y_boundary": "periodic"},
            "particles": {"count": 2500, "radius": 0.5, "packing_fraction": phi},
            "run": {"duration": duration, "warmup": 2}, "output": {"sample_interval": 1}}))
        z = summary_of(binary, str(scene), [], tmp, f"eos-{phi}")["compressibility_factor"]
        h = (1 + phi**2 / 8) / (1 - phi) ** 2
        measured.append(f"{z:.3f}")
        henderson.append(f"{h:.3f}")
        worst = max(worst, abs(z - h) / h)
    rows = ["| φ | " + " | ".join(f"{phi:g}" for phi, _ in EOS_RUNS) + " |",
            "|---|" + "---:|" * len(EOS_RUNS),
            "| Z measured | " + " | ".join(measured) + " |",
            "| Henderson | " + " | ".join(henderson) + " |"]
    return {"eos-table": "\n".join(rows), "eos-within": f"{math.ceil(worst * 1000) / 10:.1f}%"}


# The summary page's bed states: the shipped scenes in the shortened runs of
# `tests/suite/bed_state.rs` (scene, its overrides, how the page words its state and indicators).
BED_STATES = {
    "leidenfrost": ("leidenfrost", ["run.duration=40", "run.warmup=20"],
                    lambda i: f"dip {two(i['density_dip'])}, max {two(i['max_packing'])} at "
                              f"height {i['max_packing_height']:.1f}, lockings "
                              f"{two(i['com_locking'])} and {two(i['com_locking_two_periods'])}, "
                              f"circulation {two(i['circulation'])}"),
    "dilute": ("vibrofluidized_dilute", ["run.duration=60", "run.warmup=20"],
               lambda i: f"dip {two(i['density_dip'])}, max {two(i['max_packing'])}"),
    "convection": ("convection", ["run.duration=150", "run.warmup=50"],
                   lambda i: f"circulation {two(i['circulation'])}"),
    "convection-smooth": ("convection", ["run.duration=150", "run.warmup=50",
                                         "domain.wall_friction=0"],
                          lambda i: f"circulation {two(i['circulation'])}"),
    "vibrated-bed": ("vibrated_bed", ["run.duration=60", "run.warmup=20"],
                     lambda i: f"locking {two(i['com_locking'])} "
                               f"({two(i['com_locking_two_periods'])} over two periods)"),
    "undulations": ("undulations", [],
                    lambda i: f"{two(i['undulation'])} diameters, locked to two periods "
                              f"({two(i['com_locking_two_periods'])}) and not to one "
                              f"({i['com_locking']:.1g})"),
    "doubled": ("convection", ["engine.scheme=event-driven", "domain.width=50", "particles.count=500", "floor.gamma=4.5",
                               "collisions.restitution=0.7", "collisions.tc=0.001",
                               "run.duration=100", "run.warmup=40"],
                lambda i: f"period-doubled (locking {two(i['com_locking'])}, over two periods "
                          f"{two(i['com_locking_two_periods'])}) and flat "
                          f"({two(i['undulation'])})"),
    "riding": ("hard/bed_riding_gamma_0.5", [], lambda i: ""),
    "rest-1000": ("hard/bed_1000_gamma_0.8_tc", ["run.warmup=45"], lambda i: ""),
}


def bed_states(binary: str, tmp: Path) -> dict[str, str]:
    """The summary page's bed states, each as the page words it: the state's name, then the
    indicators that decided it."""
    made = {}
    for name, (scenario, sets, words) in BED_STATES.items():
        s = summary_of(binary, f"scenarios/{scenario}.json", sets, tmp, f"state-{name}")
        if "state" not in s:
            sys.exit(f"numbers.py: {scenario} ({' '.join(sets)}) has no bed state")
        said = words(s["state"]["indicators"])
        made[f"state-{name}"] = f"`{s['state']['name']}`" + (f", {said}" if said else "")
    return made


class DeepBed:
    """The summary page's pressure of `deep_bed.json` (20 000 disks, 100 units: about two
    minutes of CPU), run as shipped on the second core while the parts before the sweep run
    (the sweep, on both cores, waits for it: its wall time is quoted)."""

    def __init__(self, binary: str, tmp: Path):
        self.path = tmp / "deep.json"
        args = [binary, "run", "scenarios/deep_bed.json", "--quiet", "--summary", str(self.path)]
        self.process = subprocess.Popen(args, cwd=ROOT, stdout=subprocess.PIPE,
                                        stderr=subprocess.PIPE, text=True)

    def deep_bed_pressure(self, binary: str, tmp: Path) -> dict[str, str]:
        _, err = self.process.communicate()
        if self.process.returncode != 0:
            sys.exit(f"numbers.py: `vibrobed run scenarios/deep_bed.json` exited "
                     f"{self.process.returncode}:\n{err}")
        p = json.loads(self.path.read_text())["floor_pressure"]
        return {"p-deep-bed": f"{p['measured'] / p['weight']:.4f}"}


def rate_text(x: float) -> str:
    """Events per unit time as the hard-case table writes them: `0.84`, `8.9`, `60`, `185`,
    `3.2·10³`."""
    if x >= 1000:
        return power_of_ten(x)
    if x >= 100:
        return f"{x:.0f}"
    return f"{x:.{max(1 - math.floor(math.log10(x)), 0)}f}" if x > 0 else "0"


def hard_cases(binary: str, tmp: Path) -> dict[str, str]:
    """The stability page's table of hard cases, remade from itself: each row's files
    (`scenarios/hard/NAME.json`, in backticks) run as shipped; its last column is their events
    per unit time (popped and re-mappings, as `tests/suite/hard_cases.rs` bounds them; a range
    `a – b` where the page gives one), and its "at rest from t = …" their `at_rest_since`, in
    the order of the files that come to rest."""
    page = (BOOK / "stability.md").read_text()
    quoted = re.search(r"<!-- n:hard-cases -->(.*?)<!-- /n -->", page, re.S)
    if quoted is None:
        sys.exit("numbers.py: stability.md has no hard-cases table")
    rows = []
    for line in quoted.group(1).strip().splitlines():
        cells = line.split(" | ")
        files = re.findall(r"`([a-z0-9_.]+)`", cells[1]) if len(cells) == 4 else []
        if not files or line.startswith("| case"):
            rows.append(line)
            continue
        runs = [summary_of(binary, f"scenarios/hard/{f}.json", [], tmp, f) for f in files]
        for f, s in zip(files, runs):
            if s["ending"] != "completed":
                sys.exit(f"numbers.py: hard case {f} ended {s['ending']}")
        rates = [(sum(s["events"].values()) - s["events"].get("rest", 0)) / s["sim_time"]
                 for s in runs]
        last = cells[3].removesuffix(" |")
        if " – " in last:
            cells[3] = f"{rate_text(min(rates))} – {rate_text(max(rates))} |"
        else:
            cells[3] = ", ".join(rate_text(r) for r in rates) + " |"
        rested = [s["at_rest_since"] for s in runs if s.get("at_rest_since") is not None]
        said = re.search(r"at rest from t = ([0-9.]+(?:(?:, | and )[0-9.]+)*)", cells[2])
        if said:
            count = len(re.findall(r"[0-9.]+", said.group(1)))
            if count != len(rested):
                sys.exit(f"numbers.py: hard cases {', '.join(files)}: the page gives {count} "
                         f"times to rest, the runs {len(rested)}")
            times = [f"{t:.1f}" for t in rested]
            words = times[0] if len(times) == 1 else ", ".join(times[:-1]) + " and " + times[-1]
            cells[2] = cells[2].replace(said.group(0), f"at rest from t = {words}")
        rows.append(" | ".join(cells))
    return {"hard-cases": "\n".join(rows)}


# The phase diagram's states as its table words them.
STATE_WORDS = {"bouncing_bed": "bouncing", "leidenfrost": "Leidenfrost"}


def pd_cell(r: dict) -> str:
    """One run of the phase diagram as its table writes it: the state, then the indicators that
    decided it (L₁ and L₂ the lockings to one and two periods)."""
    i = {k.removeprefix("state.indicators."): v for k, v in r.items()
         if k.startswith("state.indicators.")}
    name = r["state.name"]
    words = STATE_WORDS.get(name, name)
    if name == "bouncing_bed":
        lockings = (f"L₁ {two(float(i['com_locking']))}, "
                    f"L₂ {two(float(i['com_locking_two_periods']))}")
        doubled = float(i["com_locking"]) <= 0.5
        return f"{words}, " + ("period-doubled: " if doubled else "") + lockings
    if name == "convection":
        # Tried before the bouncing bed: a lock above its threshold is said too.
        locks = [f"{label} {two(float(i[key]))}" for label, key in
                 (("L₁", "com_locking"), ("L₂", "com_locking_two_periods"))
                 if float(i[key]) > 0.5]
        return f"{words}, circ. {two(float(i['circulation']))}" + (
            f" ({', '.join(locks)})" if locks else "")
    if name == "leidenfrost":
        return f"{words}, dip {two(float(i['density_dip']))}, max φ {two(float(i['max_packing']))}"
    if name == "gas":
        return f"{words}, L₁ {two(float(i['com_locking']))}, max φ {two(float(i['max_packing']))}"
    return words


def phase_diagram_runs(binary: str, sweep_file: Path, out: Path) -> tuple[dict, float, float]:
    """A phase-diagram sweep on two workers: its runs keyed (Γ, N), its CPU and wall seconds."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    run(binary, "sweep", "run", str(sweep_file), "--out", str(out), "--jobs", "2", "--quiet")
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    run(binary, "sweep", "collect", str(out), "--states", "floor.gamma", "particles.count",
        "--log")
    with open(out / "runs.csv") as f:
        runs = {(float(r["floor.gamma"]), int(r["particles.count"])): r for r in csv.DictReader(f)}
    for key, r in runs.items():
        if r["ending"] != "completed" or not r["state.name"]:
            sys.exit(f"numbers.py: the phase diagram's run at Γ, N = {key} ended {r['ending']} "
                     f"with state {r['state.name'] or 'none'}")
    return runs, cpu, wall


def phase_diagram(binary: str, tmp: Path) -> dict[str, str]:
    """The phase-diagram page: `scenarios/sweeps/phase_diagram.json` as shipped (24 runs, about
    13 s of CPU) — its table of states and indicators, its figure byte for byte, the numbers its
    comparison quotes — and the same sweep without its cure (no `collisions.tc`): the runs that
    change state and how long the densest ride in contact dynamics."""
    shipped = ROOT / "scenarios/sweeps/phase_diagram.json"
    runs, cpu, wall = phase_diagram_runs(binary, shipped, tmp / "pd")
    plan = json.loads(shipped.read_text())
    width = json.loads((shipped.parent / plan["scenario"]).read_text())["domain"]["width"]
    gammas = sorted({g for g, _ in runs})
    counts = sorted({n for _, n in runs})
    layers = {n: f"{n / width:g}" for n in counts}
    rows = ["| Γ (S) | " + " | ".join(f"F = {layers[n]}" for n in counts) + " |",
            "|---|" + "---|" * len(counts)]
    for g in gammas:
        s = g**2 / math.pi**2
        rows.append(f"| {g:g} ({s:.1f}) | " if s >= 1 else f"| {g:g} ({s:.2f}) | ")
        rows[-1] += " | ".join(pd_cell(runs[g, n]) for n in counts) + " |"

    def ind(r: dict, name: str) -> float:
        return float(r[f"state.indicators.{name}"])

    def span(values: list[float]) -> str:
        return f"{two(min(values))}–{two(max(values))}"

    state = {k: r["state.name"] for k, r in runs.items()}
    gas = [k for k in runs if state[k] == "gas"]
    beds = [k for k in runs if state[k] != "gas"]
    wavy_gas = max(gas, key=lambda k: ind(runs[k], "undulation"))
    doubled = [r for k, r in runs.items() if state[k] == "bouncing_bed"
               and ind(r, "com_locking") <= 0.5]
    thin, deep = counts[0], counts[-1]
    made = {
        "pd-table": "\n".join(rows),
        f"{FIGURE}figures/phase-diagram.svg": (tmp / "pd" / "states.svg").read_text(),
        "pd-cpu": f"{cpu:.0f} s",
        "pd-wall": f"{wall:.0f} s",
        "pd-machine": machine(),
        "pd-undulation-bed": two(max(ind(runs[k], "undulation") for k in beds)),
        "pd-undulation-gas": f"{two(ind(runs[wavy_gas], 'undulation'))} in the dilute gas of "
                             f"F = {layers[wavy_gas[1]]} at Γ = {wavy_gas[0]:g}",
        "pd-thin-locking": two(ind(runs[gammas[1], thin], "com_locking")),
        "pd-thin-packing": two(max(ind(runs[k], "max_packing") for k in gas if k[1] == thin)),
        "pd-doubled-dips": span([ind(r, "density_dip") for r in doubled]),
        "pd-f6-packing": span([ind(runs[k], "max_packing") for k in runs
                               if k[1] == counts[1] and state[k] == "convection"]),
        "pd-deep-top-circulation": two(ind(runs[gammas[-1], deep], "circulation")),
        "pd-convection-dips": span([ind(runs[k], "density_dip") for k in runs
                                    if state[k] == "convection"]),
    }
    # Without the cure: the shipped file less its `collisions.tc`, the scene found from here.
    plan["scenario"] = str((shipped.parent / plan["scenario"]).resolve())
    plan["set"] = [s for s in plan["set"] if not s.startswith("collisions.tc=")]
    exact_file = tmp / "phase_diagram_exact.json"
    exact_file.write_text(json.dumps(plan))
    exact, cpu, wall = phase_diagram_runs(binary, exact_file, tmp / "pd-exact")
    changed = ["| Γ | F | as shipped | without the cure |", "|---:|---:|---|---|"]
    for g, n in sorted(k for k in runs if exact[k]["state.name"] != state[k]):
        changed.append(f"| {g:g} | {layers[n]} | {pd_cell(runs[g, n])} | "
                       f"{pd_cell(exact[g, n])} |")
    dense = [float(exact[gammas[0], n]["approximation.dense_time"] or 0) for n in counts[2:]]
    made.update({
        "pd-exact-cpu": f"{cpu:.0f} s",
        "pd-exact-wall": f"{wall:.0f} s",
        "pd-exact-changed": "\n".join(changed),
        "pd-exact-count": f"{len(changed) - 2}",
        "pd-exact-dense": " and ".join(f"{d:.0f}" for d in dense),
    })
    return made


def sweep(binary: str, tmp: Path) -> dict[str, str]:
    """The sweeps page: the 21 runs on two workers, their points, fits and CPU time."""
    out = tmp / "tvd"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    run(binary, "sweep", "run", "scenarios/sweeps/temperature_vs_drive.json", "--out", str(out),
        "--jobs", "2", "--quiet")
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    run(binary, "sweep", "collect", str(out), "--x", "drive.peak_velocity", "--y",
        "temperature.mean", "--y", "com_height", "--fit", "power", "--log")
    figure = (out / "plot.svg").read_text()
    with open(out / "points.csv") as f:
        points = list(csv.DictReader(f))
    rows = ["| A | Γ | Aω | T | T_x | T_y | centre of mass | pair collisions per run |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for p in points:
        t, t_se = float(p["temperature.mean:mean"]), float(p["temperature.mean:se"])
        decimals = 4 if t < 10 else 3
        rows.append("| " + " | ".join([
            f"{float(p['floor.amplitude']):.3f}", f"{float(p['drive.gamma']):.2f}",
            f"{float(p['drive.peak_velocity']):.3f}", f"{t:.{decimals}f} ± {t_se:.{decimals}f}",
            f"{float(p['temperature.x:mean']):.3f}", f"{float(p['temperature.y:mean']):.3f}",
            f"{float(p['com_height:mean']):.3f} ± {float(p['com_height:se']):.3f}",
            f"{float(p['events.pair:mean']) / 1000:.0f} k",
        ]) + " |")
    fits = {f["field"]: f["fit"] for f in json.loads((out / "fit.json").read_text())["power_law"]}
    t_fit, com_fit = fits["temperature.mean"], fits["com_height"]
    # The centre of mass's rise above a fitted height at rest, and T over the dense part only.
    run(binary, "sweep", "collect", str(out), "--x", "drive.peak_velocity", "--y", "com_height",
        "--fit", "power", "--offset", "fit", "--plot", str(tmp / "rise.svg"))
    rise = json.loads((out / "fit.json").read_text())["power_law"][0]["fit"]
    run(binary, "sweep", "collect", str(out), "--x", "drive.peak_velocity", "--y",
        "temperature.mean", "--fit", "power", "--fit-range", "0.6", "2", "--plot",
        str(tmp / "dense.svg"))
    dense = json.loads((out / "fit.json").read_text())["power_law"][0]["fit"]
    x = [float(p["drive.peak_velocity"]) for p in points]
    y = [float(p["temperature.mean:mean"]) for p in points]
    slopes = [math.log(y[i + 1] / y[i]) / math.log(x[i + 1] / x[i]) for i in range(len(x) - 1)]
    return {
        "tvd-table": "\n".join(rows),
        "tvd-delta": f"{t_fit['exponent']:.2f} ± {t_fit['exponent_se']:.2f}",
        "tvd-delta-value": f"{t_fit['exponent']:.2f}",
        "tvd-delta-seeds": f"{t_fit['exponent_seed_se']:.3f}",
        "tvd-slopes": ", ".join(f"{s:.2f}" for s in slopes),
        "tvd-com": f"{com_fit['exponent']:.2f} ± {com_fit['exponent_se']:.2f}",
        "tvd-rise": f"{rise['exponent']:.2f} ± {rise['exponent_se']:.2f}",
        "tvd-rise-seeds": f"{rise['exponent_seed_se']:.3f}",
        "tvd-rise-y0": f"{rise['offset']:.2f}",
        "tvd-dense": f"{dense['exponent']:.2f} ± {dense['exponent_se']:.2f}",
        "tvd-dense-points": f"{dense['points']}",
        "tvd-cpu": f"{cpu:.0f} s",
        "tvd-wall": f"{wall:.0f} s",
        "tvd-machine": machine(),
        f"{FIGURE}figures/sweep-temperature.svg": figure,
    }


def notebook_sweep(binary: str, tmp: Path) -> dict[str, str]:
    """The Python page's account of the example notebook's sweep (`examples/gamma_sweep.ipynb`:
    the shipped bed over eleven Γ, three seeds, an event cap), remade as a sweep file on two
    workers: the same runs, bit for bit. Its fit T ∝ Γ^δ (least squares of log T on log Γ, as the
    notebook's `np.polyfit`), the state of each Γ, and the indicators its prose quotes."""
    notebook = json.loads((ROOT / "examples/gamma_sweep.ipynb").read_text())
    setup = "".join(next(c["source"] for c in notebook["cells"] if c["cell_type"] == "code"))
    gammas = json.loads(re.search(r"GAMMAS = (\[[^\]]*\])", setup).group(1))
    seeds = int(re.search(r"SEEDS = (\d+)", setup).group(1))
    sets = json.loads(re.search(r"SETS = (\[[^\]]*\])", setup).group(1))
    plan = tmp / "gamma_sweep.json"
    plan.write_text(json.dumps({
        "name": "gamma_sweep", "scenario": str(ROOT / "scenarios/vibrated_bed.json"), "set": sets,
        "axes": [{"key": "floor.gamma", "values": gammas}], "seeds": seeds}))
    out = tmp / "gamma_sweep"
    run(binary, "sweep", "run", str(plan), "--out", str(out), "--jobs", "2", "--quiet")
    run(binary, "sweep", "collect", str(out))
    with open(out / "points.csv") as f:
        points = {float(p["floor.gamma"]): p for p in csv.DictReader(f)}
    with open(out / "runs.csv") as f:
        runs = list(csv.DictReader(f))
    if any(float(p["temperature.y:mean"]) <= float(p["temperature.x:mean"])
           for p in points.values()):
        sys.exit("numbers.py: the notebook's sweep has T_y ≤ T_x at some Γ: the Python page says "
                 "T_y is above T_x throughout")
    lx = [math.log(g) for g in points]
    ly = [math.log(float(p["temperature.mean:mean"])) for p in points.values()]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    slope = (sum((x - mx) * (y - my) for x, y in zip(lx, ly))
             / sum((x - mx) ** 2 for x in lx))

    def mean(g: float, name: str) -> float:
        return float(points[g][f"state.indicators.{name}:mean"])

    def states(name: str) -> str:
        return ", ".join(f"{g:g}" for g, p in points.items() if p["state"] == name)

    words = {0: "none", 1: "one", 2: "two", 3: "three"}
    disagree = []
    for g in (g for g, p in points.items() if int(p["state:n"]) < seeds):
        bouncing = sum(1 for r in runs if float(r["floor.gamma"]) == g
                       and r["state.name"] == "bouncing_bed")
        disagree.append(f"at Γ = {g:g} the locking averages {mean(g, 'com_locking'):.2f} over "
                        f"the seeds and {words.get(bouncing, bouncing)} of {words[seeds]} read "
                        "bouncing")
    made = {
        "nb-slope": f"{slope:.2f}",
        "nb-bouncing": states("bouncing_bed"),
        "nb-gas": states("gas"),
        "nb-boundary": "; ".join(disagree) or "none: every seed reads the same state at every Γ",
    }
    dipped = [g for g in points if mean(g, "density_dip") <= 0.8]
    made["nb-dip-from"] = f"{min(dipped):g}"
    made["nb-dip-packing"] = f"{max(mean(g, 'max_packing') for g in dipped):.2f}"
    circulating = [g for g, p in points.items() if p.get("state.indicators.circulation:mean")]
    made["nb-circulation-at"] = " and ".join(f"{g:g}" for g in circulating)
    return made


def beverloo(binary: str, tmp: Path) -> dict[str, str]:
    """The Physics page's discharge against the orifice width: `scenarios/sweeps/beverloo.json`
    on two workers (18 runs), its rates, and the fit of `examples/beverloo.py` (a weighted
    straight line Q^(2/3) = a + b D over D ≥ 3, errors scaled by √(χ²/dof) when above 1; C =
    b^(3/2), k = −a/b, their errors by the delta method), made here without numpy."""
    out = tmp / "bev"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    run(binary, "sweep", "run", "scenarios/sweeps/beverloo.json", "--out", str(out), "--jobs",
        "2", "--quiet")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    run(binary, "sweep", "collect", str(out))
    with open(out / "points.csv") as f:
        points = sorted(csv.DictReader(f), key=lambda p: int(p["point"]))
    with open(out / "runs.csv") as f:
        runs = list(csv.DictReader(f))
    rows = ["| D / d | rate | ± | the three seeds |", "|---|---|---|---|"]
    used = []
    for p in sorted(points, key=lambda p: float(p["floor.orifice.to"]) -
                    float(p["floor.orifice.from"])):
        width = float(p["floor.orifice.to"]) - float(p["floor.orifice.from"])
        rate, se = float(p["flow.rate:mean"]), float(p["flow.rate:se"])
        seeds = sorted((r for r in runs if r["point"] == p["point"]), key=lambda r: int(r["seed"]))
        said = ", ".join(f"{float(r['flow.rate']):.2f}" for r in seeds)
        if width < 3 - 1e-9:
            said += " (arches clog the orifice for long spells)"
        else:
            used.append((width, rate, se))
        rows.append(f"| {width:g} | {rate:.2f} | {se:.2f} | {said} |")
    # The weighted straight line through y = Q^(2/3).
    ws, xs, ys = [], [], []
    for width, rate, se in used:
        ws.append(1 / ((2 / 3) * rate ** (-1 / 3) * se) ** 2)
        xs.append(width)
        ys.append(rate ** (2 / 3))
    s, sx, sy = sum(ws), sum(w * x for w, x in zip(ws, xs)), sum(w * y for w, y in zip(ws, ys))
    sxx = sum(w * x * x for w, x in zip(ws, xs))
    sxy = sum(w * x * y for w, x, y in zip(ws, xs, ys))
    det = s * sxx - sx * sx
    a, b = (sxx * sy - sx * sxy) / det, (s * sxy - sx * sy) / det
    chi2 = sum(w * (y - a - b * x) ** 2 for w, x, y in zip(ws, xs, ys))
    dof = len(used) - 2
    scale = max(1.0, math.sqrt(chi2 / dof))
    var_a, var_b, cov_ab = (sxx / det * scale**2, s / det * scale**2, -sx / det * scale**2)
    c, k = b**1.5, -a / b
    c_se = 1.5 * b**0.5 * math.sqrt(var_b)
    gk = (-1 / b, a / b**2)
    k_se = math.sqrt(gk[0] ** 2 * var_a + 2 * gk[0] * gk[1] * cov_ab + gk[1] ** 2 * var_b)
    off = {width: c * (width - k) ** 1.5 / rate - 1 for width, rate, _ in used}
    close = [w for w, d in off.items() if abs(d) < 0.03]
    far = [w for w, d in off.items() if abs(d) >= 0.03]

    def widths(ws: list[float]) -> str:
        return ", ".join(f"{w:g}" for w in ws[:-1]) + (" and " if len(ws) > 1 else "") + \
            f"{ws[-1]:g}"

    made = {
        "bev-table": "\n".join(rows),
        "bev-cpu": f"{cpu:.0f} s",
        "bev-chi2": f"χ² = {chi2:.0f} for {dof} degrees of freedom",
        "bev-scale": f"{scale:.1f}",
        "bev-fit": f"C = {c:.3f} ± {c_se:.3f} and k = {k:.2f} ± {k_se:.2f}",
        "bev-close": f"within {math.ceil(max(abs(off[w]) for w in close) * 100):.0f} % of the "
                     f"rates at D = {widths(close)}" if close else "within 3 % of no rate",
    }
    if far:
        lo, hi = (100 * min(off[w] for w in far), 100 * max(off[w] for w in far))
        side = "above" if lo > 0 else "below" if hi < 0 else "off"
        lo, hi = sorted((abs(lo), abs(hi))) if side != "off" else (lo, hi)
        made["bev-far"] = f"{lo:.0f}–{hi:.0f} % {side} them at D = {widths(far)}"
    else:
        made["bev-far"] = "within 3 % of them at every other D"
    return made


def machine() -> str:
    """The machine and the day a timing was taken on: `AMD EPYC (family 25, model 17), 2 cores,
    2026-11-29`."""
    info = {}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            info.setdefault(key.strip(), value.strip())
    except OSError:
        pass
    name = info.get("model name", "a machine")
    if "cpu family" in info and "model" in info:
        name += f" (family {info['cpu family']}, model {info['model']})"
    return f"{name}, {os.cpu_count()} cores, {time.strftime('%Y-%m-%d')}"


def seconds(text: str) -> float:
    return float(text.split()[0])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bin", default=shutil.which("vibrobed") or "vibrobed")
    parser.add_argument("--write", action="store_true", help="rewrite the numbers in the pages")
    args = parser.parse_args()
    binary = str(Path(args.bin).resolve()) if Path(args.bin).exists() else args.bin
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        deep = DeepBed(binary, tmp)
        made: dict[str, str] = {}
        try:
            for part in (worked_example, readme_gamma, quick_try, packing_at_rest, summary_page,
                         rough_bed, equation_of_state, bed_states, hard_cases,
                         deep.deep_bed_pressure, sweep, notebook_sweep, phase_diagram, beverloo):
                before = resource.getrusage(resource.RUSAGE_CHILDREN)
                made.update(part(binary, tmp))
                after = resource.getrusage(resource.RUSAGE_CHILDREN)
                cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
                print(f"numbers.py: {part.__name__}: {cpu:.0f} s of CPU", flush=True)
        finally:
            if deep.process.poll() is None:
                deep.process.kill()
                deep.process.wait()
    wrong, used = [], set()
    for key in [k for k in made if k.startswith(FIGURE)]:
        figure, fresh = BOOK / key.removeprefix(FIGURE), made.pop(key)
        if not figure.exists() or figure.read_text() != fresh:
            wrong.append(f"{figure.relative_to(ROOT)}: not the figure today's build draws")
            if args.write:
                figure.write_text(fresh)
    for page in [ROOT / "README.md", *sorted(BOOK.rglob("*.md"))]:
        text = page.read_text()
        # A line that opens with a marker is an HTML block in Markdown: the rest of it would
        # not render (code spans, links); only a marker alone on its line (around a block) may.
        for k, line in enumerate(text.splitlines(), 1):
            if line.startswith(("<!-- n:", "<!-- /n")) and not re.fullmatch(
                    r"<!-- (n:[a-z0-9-]+|/n) -->", line):
                wrong.append(f"{page.relative_to(ROOT)}:{k}: a number opens the line (Markdown "
                             "then reads the line as HTML): move it into the line")

        def replace(m: re.Match) -> str:
            name, quoted = m.group(1), m.group(2)
            used.add(name)
            if name not in made:
                wrong.append(f"{page.relative_to(ROOT)}: no number named {name}")
                return m.group(0)
            fresh = made[name]
            if name in TIMING:
                factor = TIMING[name]
                same = factor is None or 1 / factor <= seconds(fresh) / max(
                    seconds(quoted), 1e-9) <= factor
            else:
                # A quotation may be wrapped over lines like the prose around it.
                same = quoted.split() == fresh.split()
                if same:
                    return m.group(0)
            if not same:
                wrong.append(f"{page.relative_to(ROOT)}: {name}: the page says\n{quoted.strip()}\n"
                             f"today's build gives\n{fresh}")
            # The blank lines around a table stay (Markdown needs them).
            lead = quoted[: len(quoted) - len(quoted.lstrip())]
            trail = quoted[len(quoted.rstrip()):]
            return f"<!-- n:{name} -->{lead}{fresh}{trail}<!-- /n -->"

        new = MARK.sub(replace, text)
        if args.write and new != text:
            page.write_text(new)
    unused = sorted(set(made) - used)
    if unused:
        wrong.append(f"numbers made but quoted nowhere: {', '.join(unused)}")
    print(f"numbers.py: {len(made)} numbers made (the sweep: {made['tvd-cpu']} of CPU, "
          f"{made['tvd-wall']} on two workers)", flush=True)
    if wrong and not args.write:
        print("the book differs from today's build (rerun with --write, then reread the prose):",
              file=sys.stderr)
        for w in wrong:
            print(f"- {w}", file=sys.stderr)
        return 1
    if args.write:
        print(f"pages rewritten: {len(wrong)} quotations changed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
