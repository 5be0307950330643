"""Running from Python: the result's summary, profiles, fields and distributions."""

import json
import subprocess
import sys

import numpy as np
import pytest

import vibrobed
from conftest import SCENARIOS, SHORT, without_wall_clock


def test_summary_is_a_dict(bed):
    r = vibrobed.run(bed, set=SHORT)
    assert r.summary["particles"] == 1000
    assert r.summary["sim_time"] == 20.0
    assert r.ending == "completed"
    assert r.summary["energy"]["balance_error"] < 1e-10
    assert json.loads(r.summary_json) == r.summary


def test_scenario_from_a_dict_runs_as_the_file(bed):
    from_file = vibrobed.run(bed, set=SHORT)
    from_dict = vibrobed.run(json.loads(bed.read_text()), set=SHORT)
    assert without_wall_clock(from_dict.summary) == without_wall_clock(from_file.summary)


def test_overrides_as_strings_or_a_dict(bed):
    a = vibrobed.run(bed, set=["run.duration=10", "run.warmup=2", "floor.gamma=4"])
    b = vibrobed.run(bed, set={"run.duration": 10, "run.warmup": 2, "floor.gamma": 4})
    assert without_wall_clock(a.summary) == without_wall_clock(b.summary)
    assert vibrobed.load(bed, set={"floor.gamma": 4})["floor"]["gamma"] == 4


def test_profiles_are_a_dataframe(bed):
    pd = pytest.importorskip("pandas")
    r = vibrobed.run(bed, set=SHORT)
    p = r.profiles
    assert isinstance(p, pd.DataFrame)
    assert len(p) == 40
    assert list(p["height"]) == r.summary["profiles"]["height"]
    assert p["packing_fraction"].max() > 0.3


def test_profiles_without_pandas_are_arrays(bed, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas now fails
    p = vibrobed.run(bed, set={"run.duration": 5, "run.warmup": 1}).profiles
    assert isinstance(p, dict)
    assert isinstance(p["density"], np.ndarray) and p["density"].shape == (40,)


def test_fields_in_memory_and_in_the_file(bed, tmp_path):
    pd = pytest.importorskip("pandas")
    sets = {**SHORT, "output.field_bins": [10, 8]}
    mem = vibrobed.run(bed, set=sets, fields=True).fields
    assert mem.x.shape == (10,) and mem.y.shape == (8,)
    assert mem["packing_fraction"].shape == (8, 10)
    on_disk = vibrobed.run(bed, set=sets, fields=tmp_path / "f.csv").fields
    csv = pd.read_csv(tmp_path / "f.csv")
    # Row j, column i of the arrays is the CSV's row with those indices.
    for name in on_disk.names:
        grid = csv.pivot(index="j", columns="i", values=name).to_numpy()
        np.testing.assert_array_equal(on_disk[name], grid)
        np.testing.assert_array_equal(mem[name], grid)
    np.testing.assert_array_equal(np.unique(csv["x"]), mem.x)


def test_no_fields_unless_asked(bed):
    assert vibrobed.run(bed, set={"run.duration": 2, "run.warmup": 1}).fields is None


def test_velocity_distribution_as_arrays(bed):
    r = vibrobed.run(bed, set={**SHORT, "output.velocity_distribution": True})
    v = r.velocity_distribution
    assert isinstance(v["c"], np.ndarray) and v["c"].ndim == 1
    assert v["c"].shape[0] > 10


def test_check_counts_the_disks(bed):
    assert vibrobed.check(bed) == 1000
    assert vibrobed.check(SCENARIOS / "gas_periodic_phi03.json") == 2500


def test_outputs_written_as_the_options_name_them(bed, tmp_path):
    sets = {"run.duration": 5, "run.warmup": 1}
    vibrobed.run(bed, set=sets, summary=tmp_path / "s.json", profiles=tmp_path / "p.csv",
                 trajectory=tmp_path / "t.xyz", fields=tmp_path / "f.vti")
    for name in ("s.json", "p.csv", "t.xyz", "f.vti"):
        assert (tmp_path / name).stat().st_size > 0, name
    assert json.loads((tmp_path / "s.json").read_text())["ending"] == "completed"


def test_a_recording_where_none_can_be_written_is_refused(bed, tmp_path):
    """The wheel records (Rerun built in); a recording into a missing directory is refused
    before the run, naming the option, as the command line refuses it."""
    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.run(bed, rrd=tmp_path / "missing" / "r.rrd", summary=tmp_path / "s.json")
    assert e.value.field == "--rrd" and "does not exist" in str(e.value)
    assert not (tmp_path / "s.json").exists()


def test_the_gil_is_released(bed):
    """Two runs on two Python threads overlap in time (the engine holds no GIL)."""
    import threading
    import time

    spans = []

    def one():
        t0 = time.perf_counter()
        vibrobed.run(bed, set={"run.duration": 20, "run.warmup": 5})
        spans.append((t0, time.perf_counter()))

    threads = [threading.Thread(target=one) for _ in range(2)]
    for t in threads:
        t.start()
    # Meanwhile this thread runs Python.
    ticks = 0
    while any(t.is_alive() for t in threads):
        ticks += 1
        time.sleep(0.001)
    for t in threads:
        t.join()
    (a0, a1), (b0, b1) = spans
    assert min(a1, b1) > max(a0, b0), "the runs did not overlap"
    assert ticks > 10


def test_numpy_is_imported_with_the_first_array(bed):
    """`import vibrobed` and a run read by its summary do not import numpy (a tenth of a second,
    a fifth of the shipped bed's run: python/overhead.py); the first array does."""
    code = (
        "import sys, vibrobed\n"
        f"r = vibrobed.run({str(bed)!r}, set={{'run.duration': 5, 'run.warmup': 1}})\n"
        "assert r.summary['ending'] == 'completed'\n"
        "print('numpy' in sys.modules)\n"
        f"r = vibrobed.run({str(bed)!r}, set={{'run.duration': 5, 'run.warmup': 1}}, fields=True)\n"
        "assert type(r.fields['packing_fraction']).__name__ == 'ndarray'\n"
        "print('numpy' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-W", "ignore", "-c", code], capture_output=True,
                         text=True, check=True).stdout.split()
    assert out == ["False", "True"]


def test_import_loads_nothing_a_run_does_not_need(bed, tmp_path):
    """`import vibrobed` and a run of the shipped bed (no notes) that writes its summary import
    no json, re, typing, warnings or numpy (the Python start is then the whole overhead over the
    command line); reading the summary as a dict brings json."""
    script = (
        "import sys, vibrobed\n"
        "heavy = ('json', 're', 'typing', 'warnings', 'numpy')\n"
        "print(*sorted(m for m in heavy if m in sys.modules), sep=',')\n"
        f"r = vibrobed.run({str(bed)!r}, summary={str(tmp_path / 's.json')!r})\n"
        "print(r.ending, *sorted(m for m in heavy if m in sys.modules), sep=',')\n"
        "r.summary\n"
        "print('json' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         check=True).stdout.splitlines()
    assert out == ["", "completed", "True"], out
