"""The recording from Python: the command line's file, and the same recording handed to a viewer
(the notebook's) while the run writes it. Read back with the rerun CLI of rerun-sdk, at the
version of the recorder built in."""

import _thread
import os
import re
import shutil
import subprocess
import sys
import threading

import pytest

import vibrobed
import vibrobed._view
from conftest import SCENARIOS

SETS = {"run.duration": 20, "run.warmup": 5}


@pytest.fixture(scope="module")
def rerun_cli():
    """rerun-sdk's command line, beside this Python (the tests' requirements install it)."""
    path = shutil.which("rerun", path=os.path.dirname(sys.executable)) or shutil.which("rerun")
    if path is None:
        pytest.fail("no rerun command: pip install rerun-sdk==" + vibrobed._view.RERUN_VERSION)
    version = subprocess.run([path, "--version"], capture_output=True, text=True).stdout
    assert vibrobed._view.RERUN_VERSION in version, version
    return path


def printed(rerun_cli, path, verbose="-vvv"):
    """`rerun rrd print` of a recording: its messages, with their data at -vvv."""
    out = subprocess.run(
        [rerun_cli, "rrd", "print", verbose, str(path)],
        capture_output=True,
        text=True,
        check=True,
    )
    return out.stdout


# What differs between two recordings of one run: the ids of the recording, of its rows, and of
# the blueprint's containers and views (random, made as they are logged), and the wall-clock
# time the blueprint is logged at (the recording itself has no wall clock).
UUID = re.compile(r"[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}")


def content(path, blueprint=False):
    """Every row of a recording's stores (or of its blueprint: the layout), with its entity, ids
    left out, in order: what the viewer shows, whichever chunks the rows were logged in."""
    import rerun.experimental as rrx

    reader = rrx.RrdReader(str(path))
    stores = reader.blueprints() if blueprint else reader.recordings()
    assert stores, f"{path}: no {'blueprint' if blueprint else 'recording'}"
    rows = []
    for store in stores:
        for chunk in reader.stream(store=store).to_chunks():
            batch = chunk.to_record_batch()
            names = [
                n for n in batch.schema.names if not n.endswith("RowId") and n != "log_time"
            ]
            for row in batch.select(names).to_pylist():
                row.pop("ViewportBlueprint:root_container", None)  # a container's id
                text = repr((chunk.entity_path, chunk.is_static, sorted(row.items())))
                rows.append(UUID.sub("ID", text))
    return sorted(rows)


def test_the_recording_is_the_command_lines(tmp_path, cli, bed):
    """`rrd=` writes the file `--rrd` writes: the same entities and data, the same layout."""
    args = [f"--set={k}={v}" for k, v in SETS.items()]
    subprocess.run(
        [cli, "run", str(bed), "--quiet", "--rrd", str(tmp_path / "cli.rrd"),
         "--summary", str(tmp_path / "cli.json"), *args],
        check=True,
    )
    r = vibrobed.run(bed, set=SETS, rrd=tmp_path / "py.rrd")
    assert r.ending == "completed"
    a, b = content(tmp_path / "cli.rrd"), content(tmp_path / "py.rrd")
    entities = {row.split("'")[1] for row in a}
    for entity in ("/disks", "/scene/floor", "/profiles/packing_fraction", "/series/energy/kinetic"):
        assert entity in entities
    assert len(a) > 500 and a == b
    layout = content(tmp_path / "cli.rrd", blueprint=True)
    assert any("TimeSeries" in row for row in layout)
    assert layout == content(tmp_path / "py.rrd", blueprint=True)


def test_view_hands_the_recording_on_while_it_is_written(tmp_path, rerun_cli, bed):
    """A viewer (anything with `send_rrd`) gets the recording in pieces while the run writes
    it: here a run of days, stopped by Ctrl-C once three pieces have come. Together the
    pieces hold every message of the finished file."""
    path = tmp_path / "bed.rrd"

    class Viewer:
        def __init__(self):
            self.pieces = []
            self.while_running = 0

        def send_rrd(self, data):
            assert isinstance(data, bytes) and data[:4] == b"RRF2"
            self.pieces.append(data)
            # The file is complete, under its name, only once the run has ended.
            if not path.exists():
                self.while_running += 1
                if self.while_running == 3:
                    _thread.interrupt_main()

    viewer = Viewer()
    # Should no piece come, the run is stopped anyway, after 60 s.
    timer = threading.Timer(60, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.warns(UserWarning, match="interrupted"):
            r = vibrobed.run(bed, set={"run.duration": 1e6}, rrd=path, view=viewer)
    finally:
        timer.cancel()
    assert r.ending == "interrupted"
    assert viewer.while_running >= 3, f"{len(viewer.pieces)} pieces, {viewer.while_running} " \
        "while the run went on"
    streamed = tmp_path / "streamed.rrd"
    streamed.write_bytes(b"".join(viewer.pieces))
    assert printed(rerun_cli, streamed) == printed(rerun_cli, path)


def test_view_without_a_file_leaves_none(tmp_path, rerun_cli, bed, monkeypatch):
    """Without `rrd` the recording goes through a temporary file, removed at the end."""
    made = []
    original = vibrobed._view.temporary_recording

    def temporary():
        made.append(original())
        return made[-1]

    monkeypatch.setattr(vibrobed._view, "temporary_recording", temporary)

    class Viewer:
        pieces = []

        def send_rrd(self, data):
            self.pieces.append(data)

    viewer = Viewer()
    r = vibrobed.run(bed, set={"run.duration": 5, "run.warmup": 1}, view=viewer)
    assert r.ending == "completed"
    assert viewer.pieces
    assert len(made) == 1 and not os.path.exists(os.path.dirname(made[0]))
    streamed = tmp_path / "streamed.rrd"
    streamed.write_bytes(b"".join(viewer.pieces))
    assert "/disks" in printed(rerun_cli, streamed, "-v")


def test_view_of_a_refused_run_raises_its_error(tmp_path, bed):
    """A run refused once the viewer waits (an output it cannot write) raises as without it."""

    class Viewer:
        def send_rrd(self, data):
            raise AssertionError("nothing to show")

    with pytest.raises(vibrobed.ScenarioError) as e:
        vibrobed.run(bed, set=SETS, summary=tmp_path / "missing" / "s.json", view=Viewer())
    assert e.value.field == "--summary"


def test_rough_disks_record_their_spin(tmp_path, rerun_cli):
    r = vibrobed.run(
        SCENARIOS / "rough_vibrated_bed.json",
        set={"run.duration": 2, "run.warmup": 1},
        rrd=tmp_path / "rough.rrd",
    )
    assert r.ending == "completed"
    assert "/disks/orientation" in printed(rerun_cli, tmp_path / "rough.rrd", "-v")


def test_show_sends_a_finished_recording(tmp_path, cli, rerun_cli, bed, monkeypatch):
    """`show` hands a finished recording (here the command line's) to a new viewer, whole."""
    path = tmp_path / "cli.rrd"
    subprocess.run(
        [cli, "run", str(bed), "--quiet", "--rrd", str(path), "--summary", str(tmp_path / "s.json"),
         "--set=run.duration=5", "--set=run.warmup=1"],
        check=True,
    )

    class Viewer:
        pieces = []

        def send_rrd(self, data):
            self.pieces.append(data)

    made = []

    def viewer(width, height, wait):
        made.append((width, height, wait))
        return Viewer()

    monkeypatch.setattr(vibrobed._view, "notebook_viewer", viewer)
    vibrobed.show(path, height=500)
    assert made == [("auto", 500, 5.0)]
    assert len(Viewer.pieces) == 1
    shown = tmp_path / "shown.rrd"
    shown.write_bytes(Viewer.pieces[0])
    assert printed(rerun_cli, shown) == printed(rerun_cli, path)
