"""The Python package's overhead over the command line, whole process: the shipped bed run by
`vibrobed run` and by `python -c "import vibrobed; vibrobed.run(...)"`, alternately, each writing
its summary; the medians of their CPU (user + system) and wall times, and their ratio. The
Python process's import and run are timed inside it as well. Both summaries are checked equal
(but for the wall clock) first. Run with the CPU otherwise idle (or under a lock).

    python python/overhead.py --bin target/release/vibrobed [--runs 11] [--scenario FILE]
        [--set KEY=VALUE ...]

The Python is this one (vibrobed installed in it).
"""

import argparse
import json
import os
import pathlib
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]

PY = """
import time
t0 = time.perf_counter()
import vibrobed
t1 = time.perf_counter()
vibrobed.run({scenario!r}, set={sets!r}, summary={summary!r})
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def timed(cmd):
    """Runs `cmd`; its wall seconds, CPU seconds (user + system, children included) and
    stdout."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, out


def without_wall_clock(path):
    s = json.loads(pathlib.Path(path).read_text())
    for key in ("wall_seconds", "collisions_per_second"):
        s.pop(key, None)
    s.get("engine", {}).pop("bytes_per_disk", None)
    return s


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", required=True, help="the command line's binary")
    ap.add_argument("--runs", type=int, default=11, help="runs of each, alternated")
    ap.add_argument("--scenario", default=str(ROOT / "scenarios" / "vibrated_bed.json"))
    ap.add_argument("--set", action="append", default=[], help="an override, as --set takes it")
    args = ap.parse_args()
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="vibrobed-overhead-"))
    cli_summary, py_summary = str(tmp / "cli.json"), str(tmp / "py.json")
    cli = [args.bin, "run", args.scenario, "--quiet", "--summary", cli_summary,
           *[f"--set={s}" for s in args.set]]
    py = [sys.executable, "-c",
          PY.format(scenario=args.scenario, sets=args.set, summary=py_summary)]

    # Once each, unmeasured (caches warm), and the two summaries compared.
    timed(cli)
    timed(py)
    if without_wall_clock(cli_summary) != without_wall_clock(py_summary):
        sys.exit("the summaries differ: the comparison would be of two different runs")

    walls = {"cli": [], "py": []}
    cpus = {"cli": [], "py": []}
    inside = {"import": [], "run": []}
    for _ in range(args.runs):
        for name, cmd in (("cli", cli), ("py", py)):
            wall, cpu, out = timed(cmd)
            walls[name].append(wall)
            cpus[name].append(cpu)
            if name == "py":
                imp, run = map(float, out.split())
                inside["import"].append(imp)
                inside["run"].append(run)
    med = statistics.median
    s = json.loads(pathlib.Path(cli_summary).read_text())
    print(f"{pathlib.Path(args.scenario).name} {' '.join(args.set)}: {s['particles']} disks, "
          f"t = {s['sim_time']}, "
          f"{sum(s['events'].get(k, 0) for k in ('pair', 'wall', 'floor'))} collisions")
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, {_cpu_name()}")
    print(f"medians of {args.runs} alternated runs, whole process:")
    for what, table in (("CPU (user + system)", cpus), ("wall", walls)):
        c, p = med(table["cli"]), med(table["py"])
        print(f"  {what:20s} command line {c:.3f} s, Python {p:.3f} s: "
              f"{p / c:.3f} x ({(p - c) * 1000:+.0f} ms)")
    print(f"  inside Python: import vibrobed {med(inside['import']) * 1000:.0f} ms, "
          f"vibrobed.run {med(inside['run']):.3f} s")
    for path in (cli_summary, py_summary):
        os.remove(path)
    tmp.rmdir()


def _cpu_name():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


if __name__ == "__main__":
    main()
