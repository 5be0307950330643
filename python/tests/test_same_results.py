"""A scenario run from Python gives the command line's summary bit for bit."""

import hashlib
import json
import subprocess

import pytest

import vibrobed
from conftest import SCENARIOS, without_wall_clock

# Shipped scenes, short: a bed under gravity, rough disks, a gas without gravity, a silo (disks
# leave).
SCENES = [
    ("vibrated_bed", {"run.duration": 20, "run.warmup": 5}),
    ("rough_vibrated_bed", {"run.duration": 10, "run.warmup": 2}),
    ("gas_periodic_phi03", {"run.duration": 5, "run.warmup": 1}),
    ("silo", {"run.duration": 10, "run.warmup": 2}),
]


def digest(summary):
    """A hash of the summary's deterministic part, from its JSON text (floats as written)."""
    text = json.dumps(without_wall_clock(summary), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


@pytest.mark.parametrize("name,sets", SCENES, ids=[s[0] for s in SCENES])
def test_summary_equals_the_command_line(tmp_path, cli, name, sets):
    scenario = SCENARIOS / f"{name}.json"
    args = [f"--set={k}={v}" for k, v in sets.items()]
    out = tmp_path / "summary.json"
    subprocess.run(
        [cli, "run", str(scenario), "--quiet", "--summary", str(out), *args], check=True
    )
    from_cli = json.loads(out.read_text())
    result = vibrobed.run(scenario, set=sets)
    assert result.ending == "completed"
    assert digest(result.summary) == digest(from_cli)
    # And the text itself, but for the wall-clock lines.
    strip = lambda text: [l for l in text.splitlines() if "wall_seconds" not in l
                          and "collisions_per_second" not in l]
    assert strip(result.summary_json) == strip(out.read_text())


def test_summary_file_is_the_command_lines(tmp_path, cli, bed):
    """`summary=` writes the file `--summary` writes; `profiles=` the CSV of `--profiles`."""
    sets = ["run.duration=10", "run.warmup=2"]
    subprocess.run(
        [cli, "run", str(bed), "--quiet", "--summary", str(tmp_path / "cli.json"),
         "--profiles", str(tmp_path / "cli.csv"), *[f"--set={s}" for s in sets]],
        check=True,
    )
    vibrobed.run(bed, set=sets, summary=tmp_path / "py.json", profiles=tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_text() == (tmp_path / "cli.csv").read_text()
    a = json.loads((tmp_path / "py.json").read_text())
    b = json.loads((tmp_path / "cli.json").read_text())
    assert without_wall_clock(a) == without_wall_clock(b)
