#!/usr/bin/env python3
"""Every user-facing summary by hash, to check that a change alters no result.

Runs, with the binary given, every shipped scenario (`scenarios/*.json`) at its golden file's
overrides (the goldens' short runs), and every hard case (`scenarios/hard/*.json`) as shipped and
again with the local re-mapping (as `tests/suite/hard_cases.rs` runs them), and prints one line
per run: a SHA-256 of its summary, the exit status and the run's name. The summary's
machine-dependent fields (wall time, collisions per second, bytes per disk) are left out of the
hash. Two builds' outputs compared with `diff` show which summaries a change altered; `--show
NAME` prints one run's summary, to see how.

Run from anywhere:

    benches/summary-hashes.py BINARY [--cap T] [--only SUBSTRING] [--show NAME]

`--cap T` shortens every hard case to at most T time units (its warm-up scaled with it), for a
quick look; the full set takes a few minutes of one core.
"""

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# Fields that depend on the machine or its load, not on the results.
MACHINE = [("wall_seconds",), ("collisions_per_second",), ("engine", "bytes_per_disk")]


def runs(cap):
    """(name, scenario file, overrides) of every run."""
    for path in sorted((ROOT / "scenarios").glob("*.json")):
        golden = ROOT / "scenarios/golden" / path.name
        sets = json.loads(golden.read_text())["overrides"] if golden.exists() else []
        yield path.stem, path, sets
    for path in sorted((ROOT / "scenarios/hard").glob("*.json")):
        sets = capped(path, cap) if cap else []
        yield f"hard/{path.stem}", path, sets
        if path.stem != "far_above_bed":  # as the suite: the local re-mapping's event guard
            yield f"hard/{path.stem}+local", path, sets + ["engine.remap=local"]


def capped(path, cap):
    """Overrides that end the run at `cap` if it is longer, its warm-up scaled with it."""
    run = json.loads(path.read_text()).get("run", {})
    duration = run.get("duration")
    if duration is None or duration <= cap:
        return []
    sets = [f"run.duration={cap}"]
    if "warmup" in run:
        sets.append(f"run.warmup={run['warmup'] * cap / duration}")
    return sets


def summary(binary, path, sets, out):
    """Runs one scenario; its exit status and summary (None if none was written)."""
    if out.exists():
        out.unlink()
    args = [binary, "run", str(path), "--quiet", "--summary", str(out)]
    for s in sets:
        args += ["--set", s]
    status = subprocess.run(args, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    if not out.exists():
        return status.returncode, None
    s = json.loads(out.read_text())
    for field in MACHINE:
        node = s
        for key in field[:-1]:
            node = node.get(key, {}) if isinstance(node, dict) else {}
        if isinstance(node, dict):
            node.pop(field[-1], None)
    return status.returncode, s


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("binary", help="the vibrobed binary to run")
    p.add_argument("--cap", type=float, help="end every hard case by this time")
    p.add_argument("--only", default="", help="only the runs whose name contains this")
    p.add_argument("--show", help="print this run's summary (machine fields left out)")
    a = p.parse_args()
    binary = os.path.realpath(a.binary)
    with tempfile.TemporaryDirectory() as work:
        out = Path(work) / "summary.json"
        for name, path, sets in runs(a.cap):
            if a.only not in name or (a.show and name != a.show):
                continue
            status, s = summary(binary, path, sets, out)
            if a.show:
                print(json.dumps(s, indent=1, sort_keys=True))
                return
            text = json.dumps(s, sort_keys=True).encode() if s is not None else b""
            digest = hashlib.sha256(text).hexdigest()[:16] if s is not None else "no-summary"
            print(f"{digest} {status} {name}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
