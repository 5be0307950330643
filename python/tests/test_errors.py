"""Bad input raises ScenarioError (a ValueError) with the command line's message."""

import subprocess

import pytest

import vibrobed
from conftest import SCENARIOS


def cli_message(cli, *args):
    """The command line's error message (its stderr without the `vibrobed: ` prefix) and exit
    code."""
    p = subprocess.run([cli, *map(str, args)], capture_output=True, text=True)
    line = p.stderr.strip().splitlines()[-1]
    assert line.startswith("vibrobed: ")
    return line[len("vibrobed: "):], p.returncode


@pytest.mark.parametrize(
    "sets",
    [
        ["particles.radius=-1"],
        ["domain.widht=3"],
        ["floor.gamma=\"high\""],
        ["run.duration"],
    ],
)
def test_bad_field_raises_the_command_lines_message(cli, bed, sets):
    message, code = cli_message(cli, "check", bed, *[f"--set={s}" for s in sets])
    assert code == 2
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.check(bed, set=sets)
    assert str(e.value) == message
    assert isinstance(e.value, ValueError)
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.run(bed, set=sets)
    assert str(e.value) == message


def test_the_error_names_the_field(bed):
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.run(bed, set={"particles.radius": -1})
    assert e.value.field == "particles.radius"
    assert str(e.value).startswith("particles.radius: ")


def test_a_bad_dict_names_the_field(bed):
    import json

    scenario = json.loads(bed.read_text())
    scenario["domain"]["width"] = "wide"
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.load(scenario)
    assert e.value.field == "domain.width"


def test_a_missing_scenario_file(cli, tmp_path):
    message, code = cli_message(cli, "check", tmp_path / "nope.json")
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.check(tmp_path / "nope.json")
    assert str(e.value) == message and code == 2


def test_an_output_nowhere_is_refused_before_the_run(cli, bed, tmp_path):
    missing = tmp_path / "no" / "such" / "dir" / "s.json"
    message, code = cli_message(cli, "run", bed, "--summary", missing)
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.run(bed, summary=missing)
    assert str(e.value) == message and code == 2
    assert e.value.field == "--summary"


def test_a_machine_fault_is_an_oserror_naming_the_file(tmp_path, bed):
    """A summary the system refuses to write (its name is too long for the filesystem): the run
    ends, the others are written, and an OSError names the file with the system's reason."""
    summary = tmp_path / ("s" * 300 + ".json")
    with pytest.raises(OSError) as e:
        vibrobed.run(bed, set={"run.duration": 2, "run.warmup": 1}, summary=summary,
                     profiles=tmp_path / "p.csv")
    assert str(summary) in str(e.value) and "too long" in str(e.value)
    assert (tmp_path / "p.csv").stat().st_size > 0


def test_a_resume_may_change_only_the_run_length(tmp_path):
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.resume(tmp_path / "x.ckpt", set={"floor.gamma": 4})
    assert e.value.field == "--set"
