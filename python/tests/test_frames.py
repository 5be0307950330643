"""Frames as numpy arrays while the run goes, without a trajectory file."""

import numpy as np

import vibrobed
from conftest import SCENARIOS, without_wall_clock

SETS = {"run.duration": 5, "run.warmup": 1}


def test_frames_at_the_frame_interval(bed):
    frames = vibrobed.frames(bed, set=SETS)
    times = []
    for f in frames:
        assert f.ids.shape == (1000,) and f.ids.dtype == np.uint32
        assert f.positions.shape == (1000, 2) and f.velocities.shape == (1000, 2)
        assert f.spins is None
        assert np.all(f.positions[:, 1] > f.floor_height)
        times.append(f.time)
    # output.frame_interval is 0.5: frames at 0, 0.5, …, 5.
    assert times == [0.5 * k for k in range(11)]
    assert frames.result().ending == "completed"


def test_frames_do_not_change_the_run(bed):
    frames = vibrobed.frames(bed, set=SETS)
    last = None
    for last in frames:
        pass
    plain = vibrobed.run(bed, set=SETS)
    assert without_wall_clock(frames.result().summary) == without_wall_clock(plain.summary)
    # The last frame is the state at the end: its kinetic energy the summary's.
    assert last.time == 5.0
    assert last.series["energy/kinetic"] == plain.summary["energy"]["final"]["kinetic"]


def test_rough_disks_carry_spins():
    with vibrobed.frames(SCENARIOS / "rough_vibrated_bed.json", set=SETS) as frames:
        f = next(frames)
        assert f.spins.shape == (f.ids.shape[0], 2)
        assert np.all((f.spins[:, 0] >= 0) & (f.spins[:, 0] < 2 * np.pi))


def test_stopping_early_keeps_what_was_computed(bed):
    frames = vibrobed.frames(bed, set={"run.duration": 200})
    next(frames)
    frames.stop()
    r = frames.result()
    assert r.ending == "interrupted" and r.summary["sim_time"] < 200


def test_a_dropped_iterator_stops_its_run(bed):
    import time

    t0 = time.perf_counter()
    frames = vibrobed.frames(bed, set={"run.duration": 10000})
    next(frames)
    del frames
    assert time.perf_counter() - t0 < 10
