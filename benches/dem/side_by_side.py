#!/usr/bin/env python3
"""vibrobed beside soft-sphere DEM (LAMMPS) on the same scene: for each seed, vibrobed's own
initial state is given to LAMMPS at each stiffness k_n; both run one after the other, each on
one core, for the scenario's duration; the averages after the warm-up (centre of mass height,
granular temperature, density profile over vibrobed's bins) are compared with the difference
one expects between two seed ensembles (√(2/K)·σ, as `vibrobed accuracy` reports it).

Called by benches/dem.sh, which installs LAMMPS and builds vibrobed; see its usage."""

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from lammps_input import Model, data_file, input_script  # noqa: E402
from observables import Bins, measure, of_vibrobed  # noqa: E402
from scene import Refused, Scene, first_frame, resolved  # noqa: E402


# Temperatures below this are compared in absolute terms only (a bed at rest, a solid).
TEMPERATURE_FLOOR = 1e-3


def refuse(message):
    print(f"benches/dem.sh: {message}", file=sys.stderr)
    sys.exit(2)


def number_list(option, text, kind):
    try:
        values = [kind(float(v)) if kind is float else kind(v) for v in text.split(",")]
    except ValueError:
        refuse(f"{option}: expected a comma-separated list of numbers (got {text!r})")
    if kind is float and not all(math.isfinite(v) and v > 0 for v in values):
        refuse(f"{option}: every stiffness must be a positive number (got {text!r})")
    return values


def arguments():
    p = argparse.ArgumentParser(prog="benches/dem.sh", description=__doc__.split("\n\n")[0])
    p.add_argument("scenario")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--kn", default="1e4,1e5,1e6", help="LAMMPS stiffnesses (default 1e4,1e5,1e6)")
    p.add_argument("--seeds", default=None, help="seeds, e.g. 1,2,3 (default: the scenario's)")
    p.add_argument("--duration", type=float, default=None, help="shorter run.duration")
    p.add_argument("--out", default=None, help="raw results (default: a new temporary directory)")
    p.add_argument("--vb", required=True, help="the vibrobed binary")
    p.add_argument("--lmp", default="lmp", help="the LAMMPS binary")
    a = p.parse_args()
    a.kn = number_list("--kn", a.kn, float)
    if a.seeds is not None:
        a.seeds = number_list("--seeds", a.seeds, int)
    if a.duration is not None:
        if not (math.isfinite(a.duration) and a.duration > 0):
            refuse(f"--duration: must be a positive number (got {a.duration})")
        a.set.append(f"run.duration={a.duration!r}")
    return a


def timed(cmd, **kw):
    """Runs `cmd`; the finished process, its wall seconds and its CPU seconds (user + system:
    on a busy machine the wall time also holds the time spent waiting for a core)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(cmd, **kw)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    return done, wall, cpu


def vibrobed(a, command, sets, *options, timed_run=False):
    """Runs `vibrobed COMMAND SCENARIO OPTIONS --set ...`; bad input ends this script as it
    ended vibrobed (exit 2, its message); returns the wall and CPU seconds of a timed run."""
    cmd = [a.vb, command, a.scenario, *options]
    for s in sets:
        cmd += ["--set", s]
    done, wall, cpu = timed(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode == 2:
        sys.stderr.write(done.stderr)
        sys.exit(2)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({done.returncode}):\n{done.stderr}")
    return (wall, cpu) if timed_run else None


def initial_state(a, sets, scene, work):
    """vibrobed's disks at t = 0: a run of a thousandth of a sample with a trajectory frame."""
    short = scene.sample_interval * 1e-3
    xyz = os.path.join(work, "t0.xyz")
    vibrobed(
        a,
        "run",
        sets
        + [
            f"run.duration={short!r}",
            "run.warmup=0",
            f"output.trajectory_interval={short!r}",
        ],
        "--trajectory",
        xyz,
        "--summary",
        os.path.join(work, "t0.json"),
        "--quiet",
    )
    return first_frame(xyz)


def run_lammps(a, scene, disks, masses, kn, bins, work):
    """One LAMMPS run at stiffness kn from `disks`; its wall seconds and observables."""
    os.makedirs(work, exist_ok=True)
    model = Model(scene, kn, min(masses))
    first_sample = math.ceil(scene.warmup / scene.sample_interval - 1e-9)
    steps = round(scene.duration / model.dt)
    with open(os.path.join(work, "data.lmp"), "w") as f:
        f.write(data_file(scene, disks, masses))
    a_max = max(d[3] for d in disks)
    script = input_script(
        scene, model, a_max, "samples.dump", first_sample * model.steps_per_sample, steps
    )
    with open(os.path.join(work, "in.lmp"), "w") as f:
        f.write(script)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    done, wall, cpu = timed(
        [a.lmp, "-in", "in.lmp", "-log", "log.lammps", "-screen", "none", "-nocite"],
        cwd=work,
        env=env,
    )
    if done.returncode != 0:
        raise RuntimeError(f"LAMMPS failed in {work} ({done.returncode}): see its log.lammps")
    dump = os.path.join(work, "samples.dump")
    radii = [d[3] for d in disks]
    result = measure(dump, bins, masses, radii, scene.rough)
    os.remove(dump)
    result.update(wall=wall, cpu=cpu, dt=model.dt, steps=steps, gamma_pair=model.gamma_pair,
                  gamma_floor=model.gamma_floor)
    return result


def mean(v):
    return sum(v) / len(v)


def spread(values):
    """√(2/K)·σ/|mean| of K per-seed values (None for one seed)."""
    k = len(values)
    if k < 2:
        return None
    m = mean(values)
    var = sum((x - m) ** 2 for x in values) / (k - 1)
    return math.sqrt(2.0 / k) * math.sqrt(var) / abs(m) if m else None


def profile_spread(profiles):
    """The same for profiles: √(2/K)·√(Σ_bins var / Σ_bins mean²)."""
    k = len(profiles)
    if k < 2:
        return None
    num = den = 0.0
    for col in zip(*profiles):
        m = mean(col)
        num += sum((x - m) ** 2 for x in col) / (k - 1)
        den += m * m
    return math.sqrt(2.0 / k) * math.sqrt(num / den) if den else None


def l2_rel(a, b):
    """‖a − b‖ / ‖b‖."""
    den = sum(x * x for x in b)
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)) / den) if den else None


def ensemble(runs):
    """Seed means and spreads of one code's runs."""
    out = {"wall": mean([r["wall"] for r in runs]), "cpu": mean([r["cpu"] for r in runs])}
    for key in ("com_height", "temperature", "temperature_rotational"):
        if key in runs[0]:
            values = [r[key] for r in runs]
            out[key], out[key + "_spread"] = mean(values), spread(values)
    profiles = [r["density"] for r in runs]
    out["density"] = [mean(col) for col in zip(*profiles)]
    out["density_spread"] = profile_spread(profiles)
    return out


def machine():
    """The processor as lscpu names it: model name, family, model."""
    info = {}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if ":" in line:
                    k, v = (s.strip() for s in line.split(":", 1))
                    info.setdefault(k, v)
    except OSError:
        return "unknown processor"
    return (
        f"{info.get('model name', '?')} (family {info.get('cpu family', '?')}, "
        f"model {info.get('model', '?')}), {os.cpu_count()} cores"
    )


def percent(x):
    return "—" if x is None else f"{100 * x:+.1f}%"


def plain(x):
    return "—" if x is None else f"{100 * x:.1f}%"


def table(a, scene, vb, lmp, seeds, samples):
    """The side-by-side: seed means, LAMMPS's differences from vibrobed, then the spreads."""
    rough = scene.rough
    print(f"scene: {a.scenario} {' '.join('--set ' + s for s in a.set)}".rstrip())
    print(
        f"       {scene.duration:g} time units, averages after {scene.warmup:g} "
        f"({samples} samples), seeds {','.join(map(str, seeds))}"
    )
    print(f"machine: {machine()}; one run at a time, one core each; whole-process seconds")
    head = f"{'code':<16}{'wall s':>9}{'/ vb':>7}{'CPU s':>9}{'/ vb':>7}"
    head += f"{'COM':>10}{'Δ':>8}{'T':>10}{'Δ':>8}{'ρ(z) L2':>9}"
    if rough:
        head += f"{'T_rot':>10}{'Δ':>8}"
    print(head)
    rows = [("vibrobed", vb)] + [(f"LAMMPS k_n={kn:.0e}", e) for kn, e in lmp]
    for name, e in rows:
        ref = e is vb

        def diff(key):
            # A bed at rest has a temperature of round-off in vibrobed: no relative difference.
            small = key.startswith("temperature") and vb[key] < TEMPERATURE_FLOOR
            return "" if ref else "—" if small else percent(e[key] / vb[key] - 1)

        line = (
            f"{name:<16}{e['wall']:>9.2f}{e['wall'] / vb['wall']:>7.1f}"
            f"{e['cpu']:>9.2f}{e['cpu'] / vb['cpu']:>7.1f}"
            f"{e['com_height']:>10.4f}{diff('com_height'):>8}"
            f"{e['temperature']:>10.4g}{diff('temperature'):>8}"
            f"{'' if ref else plain(l2_rel(e['density'], vb['density'])):>9}"
        )
        if rough:
            line += f"{e['temperature_rotational']:>10.4g}{diff('temperature_rotational'):>8}"
        print(line)
    print("seed spread √(2/K)·σ (the difference expected between two ensembles of these seeds):")
    for name, e in rows:
        line = (
            f"  {name:<16} COM {plain(e['com_height_spread'])}, "
            f"T {plain(e['temperature_spread'])}, ρ(z) {plain(e['density_spread'])}"
        )
        if rough:
            line += f", T_rot {plain(e['temperature_rotational_spread'])}"
        print(line)


def main():
    a = arguments()
    # vibrobed checks the scene first: bad input is refused by it, naming the field.
    vibrobed(a, "check", a.set)
    try:
        tree = resolved(a.scenario, a.set)
        scene = Scene(tree)
    except Refused as r:
        refuse(str(r))
    seeds = a.seeds if a.seeds is not None else [tree.get("seed", 0)]
    out = a.out or tempfile.mkdtemp(prefix="vibrobed-dem-")
    os.makedirs(out, exist_ok=True)
    quiet = ["output.rrd=null", "output.trajectory=null"]
    runs_vb, runs_lmp, samples = [], {kn: [] for kn in a.kn}, None
    for seed in seeds:
        sets = a.set + quiet + [f"seed={seed}"]
        work = os.path.join(out, f"seed-{seed}")
        os.makedirs(work, exist_ok=True)
        disks = initial_state(a, sets, scene, work)
        masses = scene.masses([d[3] for d in disks], [d[0] for d in disks])
        summary_path = os.path.join(work, "vibrobed.json")
        wall, cpu = vibrobed(
            a, "run", sets, "--summary", summary_path, "--quiet", timed_run=True
        )
        with open(summary_path) as f:
            summary = json.load(f)
        if summary.get("ending") != "completed":
            raise RuntimeError(f"vibrobed's run ended {summary.get('ending')}: see {summary_path}")
        vb = of_vibrobed(summary)
        vb["wall"], vb["cpu"] = wall, cpu
        runs_vb.append(vb)
        samples = vb["samples"]
        bins = Bins.of_summary(summary, scene.width)
        print(f"seed {seed}: vibrobed {wall:.2f} s ({cpu:.2f} s CPU)", file=sys.stderr)
        for kn in a.kn:
            r = run_lammps(a, scene, disks, masses, kn, bins, os.path.join(work, f"kn-{kn:g}"))
            if r["samples"] != vb["samples"]:
                raise RuntimeError(f"LAMMPS took {r['samples']} samples, vibrobed {vb['samples']}")
            runs_lmp[kn].append(r)
            print(
                f"seed {seed}: LAMMPS k_n={kn:g} {r['wall']:.2f} s ({r['cpu']:.2f} s CPU, "
                f"dt {r['dt']:.4g})",
                file=sys.stderr,
            )
    vb = ensemble(runs_vb)
    lmp = [(kn, ensemble(runs_lmp[kn])) for kn in a.kn]
    with open(os.path.join(out, "table.json"), "w") as f:
        json.dump({"seeds": seeds, "vibrobed": runs_vb,
                   "lammps": {f"{kn:g}": runs_lmp[kn] for kn in a.kn}}, f, indent=1)
    table(a, scene, vb, lmp, seeds, samples)
    print(f"raw results: {out}")


if __name__ == "__main__":
    main()
