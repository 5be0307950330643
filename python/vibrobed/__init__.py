"""vibrobed from Python: run a scenario as the command line runs it, and read its results as
arrays.

The engine, the checks and the messages are the command line's (``vibrobed run``, ``check``,
``resume``, ``sweep run``); the results come back as a dict (the summary, bit for bit the
command line's), pandas DataFrames (profiles, sweep tables; dicts of numpy arrays without
pandas) and numpy arrays (2D fields, velocity distributions, frames).

    import vibrobed
    r = vibrobed.run("scenarios/vibrated_bed.json", set={"floor.gamma": 4})
    r.summary["temperature"]["mean"], r.profiles["packing_fraction"]

A scenario is a file's path or a dict; overrides (``set``) are ``KEY=VALUE`` strings, as
``--set`` takes them, or a dict from dotted path to value. Bad input raises ``ScenarioError`` (a
``ValueError``) with the command line's message; its ``field`` names the culprit. A file that
cannot be read or written raises ``OSError``. Ctrl-C stops a run cleanly at its next event: the
result covers the time simulated so far (``result.ending == "interrupted"``).

In a notebook, ``run(..., view=True)`` shows the run's recording (the command line's, ``--rrd``)
in a Rerun viewer embedded in the cell while it runs, and ``show("bed.rrd")`` a finished one
(``pip install "vibrobed[notebook]"``: rerun-sdk's notebook extra, at the recorder's version).
"""

from __future__ import annotations

import os

from . import _vibrobed as _native
from ._vibrobed import ScenarioError, __version__

# Nothing but the native module is imported with the package: a script that runs a scene and
# writes its summary pays for no more than Python's start. json (and the re it pulls in),
# typing, warnings and numpy are each imported where first needed (a dict scenario, the summary
# read as a dict, a note, an array), the viewer's module with the viewer, the frame's type with
# the first frame.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Union

    import numpy as np

    from ._frame import Frame

    PathLike = Union[str, "os.PathLike[str]"]
    Scenario = Union[PathLike, Mapping[str, Any]]
    Sets = Union[None, str, Sequence[str], Mapping[str, Any]]

__all__ = [
    "ScenarioError",
    "load",
    "check",
    "run",
    "resume",
    "frames",
    "sweep",
    "collect",
    "show",
    "Result",
    "Fields",
    "Frame",
    "Frames",
    "Sweep",
]


def _given(scenario: Scenario) -> Dict[str, Any]:
    """The native functions' ``path`` or ``text`` for a file's path or a dict."""
    if isinstance(scenario, (str, bytes, os.PathLike)):
        return {"path": os.fspath(scenario)}
    import json

    return {"text": json.dumps(dict(scenario))}


def _sets(sets: Sets) -> List[str]:
    """``--set`` overrides: ``KEY=VALUE`` strings as given, or a dict's items with their values
    written as JSON (``{"floor.gamma": 4}`` is ``floor.gamma=4``)."""
    if sets is None:
        return []
    if isinstance(sets, str):
        return [sets]
    if hasattr(sets, "items"):
        import json

        return [f"{key}={json.dumps(value)}" for key, value in sets.items()]
    return [str(s) for s in sets]


def _files(**paths: Optional[PathLike]) -> Dict[str, str]:
    return {name: os.fspath(p) for name, p in paths.items() if p is not None}


def _table(columns: Mapping[str, Sequence[Any]]):
    """A DataFrame of ``columns`` with pandas, else a dict of numpy arrays (of floats: a null,
    a value never measured such as an empty bin's temperature, is NaN)."""
    import numpy as np

    arrays = {name: np.asarray(values, dtype=float) for name, values in columns.items()}
    try:
        import pandas as pd
    except ImportError:
        return arrays
    return pd.DataFrame(arrays)


def _csv_table(text: str):
    """A CSV table (the sweep's ``runs.csv``, ``points.csv``) as :func:`_table` gives it."""
    try:
        import pandas as pd
    except ImportError:
        import csv
        import io

        import numpy as np

        rows = list(csv.reader(io.StringIO(text)))
        header, body = rows[0], rows[1:]
        out = {}
        for k, name in enumerate(header):
            values = [row[k] for row in body]
            try:
                out[name] = np.array([float(v) if v != "" else np.nan for v in values])
            except ValueError:
                out[name] = np.array(values, dtype=object)
        return out
    import io

    return pd.read_csv(io.StringIO(text))


def _arrays(value: Any) -> Any:
    """``value`` with every list of numbers (or of such lists) as a numpy array."""
    if isinstance(value, dict):
        return {k: _arrays(v) for k, v in value.items()}
    if isinstance(value, list):
        import numpy as np

        items = [_arrays(v) for v in value]
        try:
            return np.asarray(items, dtype=float)
        except (TypeError, ValueError):
            return items
    return value


def _warn(message: str, stacklevel: int) -> None:
    import warnings

    warnings.warn(message, stacklevel=stacklevel + 1)


def _advise(notes: Sequence[str], stacklevel: int = 3) -> None:
    for note in notes:
        _warn(f"vibrobed: note: {note}", stacklevel)


class Fields:
    """The time-averaged 2D fields (``run(fields=...)``): ``x`` (cell centres across, nx) and
    ``y`` (up, ny), and each quantity as an ``ny × nx`` array, row j at height ``y[j]``, NaN
    where undefined; ``fields["packing_fraction"]``, ``fields.names``."""

    def __init__(self, arrays: Dict[str, np.ndarray]):
        self.x = arrays.pop("x")
        self.y = arrays.pop("y")
        self._arrays = arrays

    @property
    def names(self) -> List[str]:
        return list(self._arrays)

    def __getitem__(self, name: str) -> np.ndarray:
        return self._arrays[name]

    def __contains__(self, name: str) -> bool:
        return name in self._arrays

    def __repr__(self) -> str:
        return f"Fields({len(self.y)} x {len(self.x)} cells: {', '.join(self.names)})"


class Result:
    """What a run made: ``summary`` (the command line's summary as a dict), ``ending``,
    ``profiles`` (height profiles, gravity scenes), ``fields`` (when measured),
    ``velocity_distribution`` and ``phase`` (when the scenario measures them), ``summary_json``
    (the summary's text, byte for byte the command line's)."""

    def __init__(
        self,
        summary_json: str,
        fields: Optional[Dict[str, np.ndarray]],
        ending: str,
        output_failures: Sequence[Any] = (),
    ):
        self.summary_json = summary_json
        self.ending = ending
        """``completed``, ``interrupted``, ``event-limit``, ``wall-limit`` or ``stalled``."""
        # The outputs that could not be written, (output, error): warned of at once.
        self._output_failures = list(output_failures)
        self.fields = Fields(fields) if fields is not None else None
        self._summary: Optional[Dict[str, Any]] = None

    @property
    def summary(self) -> Dict[str, Any]:
        """The summary as a dict (read from ``summary_json`` when first asked for)."""
        if self._summary is None:
            import json

            self._summary = json.loads(self.summary_json)
        return self._summary

    @property
    def profiles(self):
        """The time-averaged profiles against height, one row per bin (None without gravity)."""
        p = self.summary.get("profiles")
        if p is None:
            return None
        return _table({k: v for k, v in p.items() if isinstance(v, list)})

    @property
    def velocity_distribution(self) -> Optional[Dict[str, Any]]:
        """The scaled velocities' distributions (``c``, and per axis ``x``, ``y``) as arrays."""
        v = self.summary.get("velocity_distribution")
        return None if v is None else _arrays(v)

    @property
    def phase(self) -> Optional[Dict[str, Any]]:
        """The motion against the floor's phase, as arrays (a vibrating floor under gravity)."""
        p = self.summary.get("phase")
        return None if p is None else _arrays(p)

    def __repr__(self) -> str:
        s = self.summary
        return (
            f"Result({s['scenario']!r}: {s['ending']} at t = {s['sim_time']}, "
            f"{s['particles']} disks)"
        )


def _result(ran, what: str) -> Result:
    result = Result(*ran)
    if result.ending == "interrupted":
        _warn(
            f"vibrobed: {what} interrupted at t = {result.summary['sim_time']}: the result "
            "covers the time simulated so far",
            3,
        )
    for output, error in result._output_failures:
        _warn(f"vibrobed: the {output} was not written: {error}", 3)
    return result


def load(scenario: Scenario, set: Sets = None) -> Dict[str, Any]:
    """The scenario, overrides applied, checked and typed: a dict with every default filled in.
    Its advisories (likely unintended settings) come as warnings."""
    import json

    text, notes = _native.load(**_given(scenario), sets=_sets(set))
    _advise(notes)
    return json.loads(text)


def check(scenario: Scenario, set: Sets = None) -> int:
    """``vibrobed check``: builds the scene and its engine without running; returns the number
    of disks, or raises ``ScenarioError`` naming the field."""
    given, sets = _given(scenario), _sets(set)
    _advise(_native.load(**given, sets=sets)[1])
    return _native.check(**given, sets=sets)


def run(
    scenario: Scenario,
    set: Sets = None,
    *,
    rrd: Optional[PathLike] = None,
    summary: Optional[PathLike] = None,
    profiles: Optional[PathLike] = None,
    fields: Union[None, bool, PathLike] = None,
    trajectory: Optional[PathLike] = None,
    checkpoint: Optional[PathLike] = None,
    checkpoint_every: Optional[float] = None,
    progress: bool = False,
    progress_every: Optional[float] = None,
    view: Any = False,
) -> Result:
    """``vibrobed run``: runs the scenario and returns its :class:`Result`. Each path writes the
    file the command line's option of that name writes (``fields`` a CSV, or VTK for
    ``*.vti``); ``fields=True`` measures the 2D fields without writing them. ``progress`` shows
    the command line's progress on stderr (off a terminal, as in a notebook, a line every
    ``progress_every`` seconds, 60 by default). ``view=True`` shows the run's recording in a Rerun
    viewer embedded in the notebook while it runs (see :func:`show`). The GIL is released while
    the engine runs."""
    given, sets = _given(scenario), _sets(set)
    _advise(_native.load(**given, sets=sets)[1])
    measure = fields is True
    paths = dict(
        summary=summary,
        profiles=profiles,
        fields=None if isinstance(fields, bool) else fields,
        trajectory=trajectory,
        checkpoint=checkpoint,
    )

    def go(rrd: Optional[PathLike]):
        return _native.run(
            **given,
            sets=sets,
            files=_files(rrd=rrd, **paths),
            checkpoint_every=checkpoint_every,
            measure_fields=measure,
            progress=progress,
            progress_every=progress_every,
        )

    return _result(_viewed(go, rrd, view), "run")


def _viewed(go, rrd: Optional[PathLike], view: Any):
    """``go(rrd)``, its recording shown as it is written when ``view`` asks for it: ``True``
    for a new viewer in the notebook's cell, or a viewer to send to (anything with
    ``send_rrd(bytes)``, such as ``rerun_notebook.Viewer``). Without ``rrd`` the recording goes
    to a temporary file, removed afterwards."""
    if view is False or view is None:
        return go(rrd)
    from . import _view

    viewer = _view.notebook_viewer() if view is True else view
    path = os.fspath(rrd) if rrd is not None else _view.temporary_recording()
    follow = _view.Follow(path, viewer.send_rrd).start()
    try:
        return go(path)
    finally:
        follow.finish()
        if rrd is None:
            _view.discard(path)


def show(
    recording: PathLike, *, width: Any = "auto", height: Any = 640, wait: float = 5.0
) -> None:
    """Shows a recording (an ``.rrd`` file, from ``run(rrd=...)`` or ``vibrobed run --rrd``)
    in a Rerun viewer embedded in the notebook's cell, laid out as the recording says (the
    command line's layout). ``width`` and ``height`` are the viewer's, in pixels (``"auto"``:
    the cell's width); it waits up to ``wait`` seconds for the viewer to load. Needs rerun-sdk's
    notebook extra at the version of the recorder (``pip install 'vibrobed[notebook]'``)."""
    from . import _view

    with open(os.fspath(recording), "rb") as f:
        data = f.read()
    piece = _view.Pieces().feed(data)
    viewer = _view.notebook_viewer(width, height, wait)
    if piece is not None:
        viewer.send_rrd(piece)


def resume(
    checkpoint: PathLike,
    set: Sets = None,
    *,
    rrd: Optional[PathLike] = None,
    summary: Optional[PathLike] = None,
    profiles: Optional[PathLike] = None,
    fields: Optional[PathLike] = None,
    trajectory: Optional[PathLike] = None,
    checkpoint_to: Optional[PathLike] = None,
    checkpoint_every: Optional[float] = None,
    progress: bool = False,
    progress_every: Optional[float] = None,
    view: Any = False,
) -> Result:
    """``vibrobed resume``: continues the run the checkpoint holds, bit for bit as if it had not
    stopped; ``set`` may change only ``run.duration`` and ``run.max_events``. Checkpoints go on
    into the same file (or ``checkpoint_to``). Only a checkpoint written by this build resumes.
    ``view`` as for :func:`run`."""
    paths = dict(
        summary=summary,
        profiles=profiles,
        fields=fields,
        trajectory=trajectory,
        checkpoint=checkpoint_to,
    )

    def go(rrd: Optional[PathLike]):
        return _native.resume(
            os.fspath(checkpoint),
            sets=_sets(set),
            files=_files(rrd=rrd, **paths),
            checkpoint_every=checkpoint_every,
            progress=progress,
            progress_every=progress_every,
        )

    return _result(_viewed(go, rrd, view), "resumed run")


class Frames:
    """A run under way, iterated frame by frame (at ``output.frame_interval``) without a file.
    The run waits while ``queue`` frames are unread. ``result()`` waits for the end (frames not
    read are dropped) and returns the :class:`Result`; ``stop()`` ends the run early. Ctrl-C
    while waiting for a frame stops the run and raises ``KeyboardInterrupt``; ``result()`` then
    gives what was computed."""

    def __init__(self, scenario: Scenario, set: Sets = None, *, queue: int = 4,
                 _stacklevel: int = 3):
        given, sets = _given(scenario), _sets(set)
        _advise(_native.load(**given, sets=sets)[1], _stacklevel)
        self._native = _native.Frames(**given, sets=sets, queue=queue)
        self._result: Optional[Result] = None

    def __iter__(self) -> Iterator[Frame]:
        return self

    def __next__(self) -> Frame:
        from ._frame import Frame

        return Frame(**next(self._native))

    def stop(self) -> None:
        self._native.stop()

    def result(self) -> Result:
        if self._result is None:
            self._result = _result(self._native.finish(), "run")
        return self._result

    def __enter__(self) -> "Frames":
        return self

    def __exit__(self, *exc) -> None:
        if self._result is None:
            self.stop()
            self.result()


def frames(scenario: Scenario, set: Sets = None, *, queue: int = 4) -> Frames:
    """The frames of a run of ``scenario`` as it goes: see :class:`Frames`."""
    return Frames(scenario, set, queue=queue, _stacklevel=4)


class Sweep:
    """A sweep's results in ``out``: ``runs`` (one row per run) and ``points`` (each point's
    means and standard errors over its seeds), as ``vibrobed sweep collect`` writes them into
    ``runs.csv`` and ``points.csv``; and, after :func:`sweep`, how many runs ran now, were done
    before, or were interrupted."""

    def __init__(self, out: PathLike, ran: int = 0, skipped: int = 0, interrupted: int = 0):
        self.out = os.fspath(out)
        runs_csv, points_csv = _native.sweep_collect(self.out)
        self.runs = _csv_table(runs_csv)
        self.points = _csv_table(points_csv)
        self.ran, self.skipped, self.interrupted = ran, skipped, interrupted

    def __repr__(self) -> str:
        return (
            f"Sweep({self.out!r}: {len(self.runs['index'])} runs, {self.ran} ran now, "
            f"{self.skipped} done before, {self.interrupted} interrupted)"
        )


def sweep(
    sweep: Union[PathLike, Mapping[str, Any]],
    out: PathLike,
    *,
    jobs: Optional[int] = None,
    progress: bool = False,
    progress_every: Optional[float] = None,
    max_run_seconds: Optional[float] = None,
) -> Sweep:
    """``vibrobed sweep run`` on this machine's cores (``jobs`` workers, default all), then its
    tables. ``sweep`` is a sweep file or a dict of one (written to ``out/sweep.json`` once
    it is checked, its scenario path taken from the working directory; a refused sweep writes
    nothing). Runs done before are skipped; a failed run
    raises ``RuntimeError`` once the others are done; runs stopped by their event or wall-clock
    limit (now or before) are named in a warning. ``progress_every`` and ``max_run_seconds``
    are ``sweep run``'s ``--progress-every`` and ``--max-run-seconds``."""
    out = os.fspath(out)
    text = None
    if not isinstance(sweep, (str, bytes, os.PathLike)):
        import json

        spec = dict(sweep)
        if "scenario" in spec:
            spec["scenario"] = os.path.abspath(spec["scenario"])
        # Written by the extension once every check has passed: a refused sweep writes nothing.
        text = json.dumps(spec, indent=2)
        path = os.path.join(out, "sweep.json")
    else:
        path = os.fspath(sweep)
    ran, skipped, interrupted, failed, early = _native.sweep_run(
        path, out, jobs=jobs, progress=progress, progress_every=progress_every,
        max_run_seconds=max_run_seconds, text=text)
    if failed:
        i, first = failed[0]
        total = ran + skipped + interrupted + len(failed)
        raise RuntimeError(
            f"{len(failed)} of {total} runs failed (their folders hold error.txt); run {i}: {first}"
        )
    if interrupted:
        _warn(f"vibrobed: sweep interrupted ({interrupted} runs)", 2)
    if early:
        # The command line exits non-zero for them (4, 5): the sweep's results are incomplete.
        runs = "; ".join(f"run {i} {how}" for i, how in early)
        _warn(f"vibrobed: the sweep is incomplete: {runs}", 2)
    return Sweep(out, ran, skipped, interrupted)


def collect(out: PathLike) -> Sweep:
    """The tables of the sweep in ``out`` (``vibrobed sweep collect``, without the plot)."""
    return Sweep(out)


def __getattr__(name: str) -> Any:
    # The frame's type comes with the first frame (typing's NamedTuple is not imported before).
    if name == "Frame":
        from ._frame import Frame

        return Frame
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
