"""A local sweep from Python: its runs, and its tables as DataFrames."""

import json

import pytest

import vibrobed
from conftest import ROOT


def test_a_sweep_and_its_tables(tmp_path, bed):
    pd = pytest.importorskip("pandas")
    spec = {
        "name": "gamma",
        "scenario": str(bed),
        "set": ["run.duration=4", "run.warmup=1"],
        "axes": [{"key": "floor.gamma", "values": [2, 4]}],
        "seeds": 2,
    }
    s = vibrobed.sweep(spec, tmp_path / "out", jobs=2)
    assert (s.ran, s.skipped, s.interrupted) == (4, 0, 0)
    assert isinstance(s.points, pd.DataFrame) and len(s.points) == 2
    assert len(s.runs) == 4 and set(s.runs["ending"]) == {"completed"}
    assert list(s.points["floor.gamma"]) == [2, 4]
    # The tables are the files `sweep collect` writes.
    assert pd.read_csv(tmp_path / "out" / "points.csv").equals(s.points)
    # Run again: every run is done.
    again = vibrobed.sweep(spec, tmp_path / "out")
    assert (again.ran, again.skipped) == (0, 4)
    # A run's summary is the one a run from Python gives.
    summary = json.loads((tmp_path / "out" / "0" / "summary.json").read_text())
    assert summary["ending"] == "completed"


def test_runs_stopped_by_their_limit_are_named(tmp_path, bed):
    """A sweep whose runs stop at their event limit is incomplete (the command line exits 4):
    a warning names them, on the first invocation and on a rerun that skips them."""
    spec = {
        "scenario": str(bed),
        "set": ["run.duration=4", "run.warmup=1"],
        "axes": [{"key": "run.max_events", "values": [100, 100000000]}],
    }
    for _ in range(2):
        with pytest.warns(UserWarning, match=r"the sweep is incomplete: run 0 stopped by the "
                                             r"event limit \(run.max_events\)$"):
            s = vibrobed.sweep(spec, tmp_path / "out", jobs=1)
        assert list(s.runs["ending"]) == ["event-limit", "completed"]


def test_a_wall_clock_limit_per_run(tmp_path, bed):
    """``max_run_seconds`` is ``--max-run-seconds``: each run ends at it (``wall-limit``), named
    in the warning; a limit that is no number of seconds is refused by name."""
    spec = {"scenario": str(bed), "set": ["run.duration=100000"], "seeds": 1}
    with pytest.warns(UserWarning, match="run 0 stopped by the wall-clock limit"):
        s = vibrobed.sweep(spec, tmp_path / "out", max_run_seconds=0.3, progress_every=0.1)
    assert list(s.runs["ending"]) == ["wall-limit"]
    with pytest.raises(vibrobed.ScenarioError, match="--max-run-seconds"):
        vibrobed.sweep(spec, tmp_path / "o2", max_run_seconds=0)


def test_a_shipped_sweep_file_is_checked_first(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({
        "scenario": str(ROOT / "scenarios" / "vibrated_bed.json"),
        "axes": [{"key": "particles.radius", "values": [-1]}],
    }))
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.sweep(bad, tmp_path / "out")
    assert "particles.radius" in str(e.value)
    assert not (tmp_path / "out" / "0").exists()
