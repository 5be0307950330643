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


def test_an_output_over_the_scenario_is_refused_and_the_scenario_kept(cli, bed, tmp_path):
    """As on the command line (issue 62): a summary written over the scenario it runs would
    destroy it."""
    scenario = tmp_path / "bed.json"
    text = bed.read_text()
    scenario.write_text(text)
    message, code = cli_message(cli, "run", scenario, "--summary", scenario)
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.run(scenario, summary=scenario)
    assert str(e.value) == message and code == 2
    assert e.value.field == "--summary"
    assert scenario.read_text() == text


def test_an_output_over_the_resumed_checkpoint_is_refused_and_it_kept(cli, bed, tmp_path):
    """A summary over the checkpoint resumed is refused as on the command line (the checkpoint
    itself may go on into the same file); two outputs on one path too. (The wheel and the
    binary are different builds: each resumes its own checkpoint.)"""
    short = {"run.duration": 2, "run.warmup": 1}
    cli_ck = tmp_path / "cli.ckpt"
    subprocess.run([cli, "run", bed, "--quiet", "--checkpoint", cli_ck,
                    *[f"--set={k}={v}" for k, v in short.items()]], check=True)
    message, code = cli_message(cli, "resume", cli_ck, "--summary", cli_ck)
    ck = tmp_path / "c.ckpt"
    vibrobed.run(bed, set=short, checkpoint=ck)
    saved = ck.read_bytes()
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.resume(ck, summary=ck)
    assert str(e.value) == message.replace(str(cli_ck), str(ck)) and code == 2
    assert e.value.field == "--summary"
    both = tmp_path / "x.csv"
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.resume(ck, profiles=both, fields=both)
    assert e.value.field in ("--profiles", "--fields")
    assert ck.read_bytes() == saved and not both.exists()


def test_an_output_named_dash_is_refused_by_name(bed, tmp_path, monkeypatch):
    """`-` is the command line's stdout for --summary only; from Python (which returns the
    summary) no output may be named `-`: refused by name, no file `-` written (issue 62)."""
    monkeypatch.chdir(tmp_path)
    for output in ("summary", "profiles", "trajectory"):
        with pytest.raises(vibrobed.ScenarioError) as e:
            vibrobed.run(bed, **{output: "-"})
        assert e.value.field == f"--{output}" and "`-`" in str(e.value)
    assert list(tmp_path.iterdir()) == []


def test_a_wall_clock_limit_past_32_years_is_refused_by_name(bed, tmp_path):
    """A limit past what the clock holds aborted the process (issue 62)."""
    spec = {"scenario": str(bed), "seeds": 1}
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.sweep(spec, tmp_path / "out", max_run_seconds=1e101)
    assert e.value.field == "--max-run-seconds"
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.run(bed, set={"run.max_wall_seconds": 1e19})
    assert e.value.field == "run.max_wall_seconds"


@pytest.mark.parametrize("bad, field", [
    ({"axes": [{"key": "particles.radius", "values": [-1]}]}, "particles.radius"),
    ({"seeds": -1}, "seeds"),
    ({"set": ["run.duration=1e308"]}, "run.duration"),
])
def test_a_refused_sweep_dict_writes_nothing(bed, tmp_path, bad, field):
    """A sweep given as a dict is written to ``out/sweep.json`` only once it is checked: a
    refused one leaves no folder and no file (issue 62)."""
    spec = {"scenario": str(bed), **bad}
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.sweep(spec, tmp_path / "out")
    assert field in str(e.value)
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(vibrobed.ScenarioError, match="--progress-every"):
        vibrobed.sweep({"scenario": str(bed)}, tmp_path / "out", progress_every=5e-324)
    assert list(tmp_path.iterdir()) == []


def test_a_sweep_dict_into_another_sweep_s_folder_is_refused_and_its_file_kept(bed, tmp_path):
    """A dict run into the folder of a different sweep is refused before its ``sweep.json`` is
    written over the one there."""
    first = {"scenario": str(bed), "set": ["run.duration=4", "run.warmup=1"], "seeds": 1}
    vibrobed.sweep(first, tmp_path / "out", jobs=1)
    kept = (tmp_path / "out" / "sweep.json").read_text()
    other = {**first, "seeds": 2}
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.sweep(other, tmp_path / "out", jobs=1)
    assert e.value.field == "--out"
    assert (tmp_path / "out" / "sweep.json").read_text() == kept
