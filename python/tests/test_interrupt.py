"""Ctrl-C stops a run cleanly within a second and keeps what was computed; a checkpoint
resumes bit for bit."""

import _thread
import json
import threading
import time

import pytest

import vibrobed
from conftest import SCENARIOS, without_wall_clock


def test_ctrl_c_stops_the_run_and_keeps_the_result(bed):
    # A run of minutes, interrupted after half a second as a notebook's interrupt does.
    timer = threading.Timer(0.5, _thread.interrupt_main)
    t0 = time.perf_counter()
    timer.start()
    with pytest.warns(UserWarning, match="interrupted"):
        r = vibrobed.run(bed, set={"run.duration": 100000})
    elapsed = time.perf_counter() - t0
    assert r.ending == "interrupted"
    assert 0 < r.summary["sim_time"] < 100000
    assert r.summary["energy"]["balance_error"] < 1e-10
    assert elapsed < 1.5, f"stopped {elapsed - 0.5:.2f} s after Ctrl-C"


def test_ctrl_c_stops_a_sweep(bed, tmp_path):
    pytest.importorskip("pandas")  # imported before the clock starts: its first import is slow
    sweep = {
        "scenario": str(bed),
        "set": ["run.duration=100000"],
        "axes": [{"key": "floor.gamma", "values": [2, 3]}],
    }
    timer = threading.Timer(0.5, _thread.interrupt_main)
    t0 = time.perf_counter()
    timer.start()
    with pytest.warns(UserWarning, match="interrupted"):
        s = vibrobed.sweep(sweep, tmp_path / "out", jobs=2)
    assert time.perf_counter() - t0 < 1.5
    assert s.interrupted == 2


def test_resume_continues_bit_for_bit(bed, tmp_path):
    whole = vibrobed.run(bed, set={"run.duration": 10, "run.warmup": 2})
    ck = tmp_path / "run.ckpt"
    half = vibrobed.run(bed, set={"run.duration": 5, "run.warmup": 2}, checkpoint=ck)
    assert half.summary["sim_time"] == 5
    rest = vibrobed.resume(ck, set={"run.duration": 10})
    # The memory the engine holds is the process's (as the command line's checkpoint test has it).
    for r in (rest, whole):
        del r.summary["engine"]["bytes_per_disk"]
    assert without_wall_clock(rest.summary) == without_wall_clock(whole.summary)


def test_ctrl_c_while_a_sweep_s_first_run_builds(tmp_path):
    """Ctrl-C while the first run builds its scene (2·10⁵ disks) stops the sweep as SIGINT stops
    ``sweep run``: once that build ends, the run's summary marked interrupted at t = 0, no other
    run started, the sweep file and scenario untouched; the call returns the tables as ever."""
    scene = tmp_path / "gas.json"
    scene.write_bytes((SCENARIOS / "gas_periodic_phi03.json").read_bytes())
    spec = tmp_path / "big.json"
    spec.write_text(json.dumps({
        "scenario": "gas.json",
        "set": ["particles.count=200000", "domain.width=400"],
        "axes": [{"key": "collisions.restitution", "values": [0.9, 0.95]}],
        "seeds": 1,
    }))
    before = (scene.read_bytes(), spec.read_text())
    out = tmp_path / "out"

    def press_when_the_pool_starts():
        # The plan is written as the pool starts, just before run 0 builds its scene.
        deadline = time.monotonic() + 60
        while not (out / "plan.json").exists() and time.monotonic() < deadline:
            time.sleep(0.005)
        _thread.interrupt_main()

    threading.Thread(target=press_when_the_pool_starts, daemon=True).start()
    with pytest.warns(UserWarning, match="interrupted"):
        s = vibrobed.sweep(spec, out, jobs=1)
    assert s.interrupted == 1 and s.ran == 0
    assert (scene.read_bytes(), spec.read_text()) == before
    # Beside the command line's files, the tables the call returns (run 1: not run).
    assert sorted(p.name for p in out.iterdir()) == ["0", "plan.json", "points.csv", "runs.csv"]
    summary = json.loads((out / "0" / "summary.json").read_text())
    assert summary["ending"] == "interrupted" and summary["sim_time"] == 0
