"""Shared fixtures: the repository's scenarios and the command line to compare with."""

import os
import pathlib
import shutil

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "scenarios"

# Short runs of the shipped scenes: seconds each.
SHORT = {"run.duration": 20, "run.warmup": 5}


@pytest.fixture
def bed():
    return SCENARIOS / "vibrated_bed.json"


@pytest.fixture(scope="session")
def cli():
    """The command-line binary: $VIBROBED_BIN, else `vibrobed` on the PATH. The comparison
    with it is the point of the package: missing, it fails rather than skips."""
    path = os.environ.get("VIBROBED_BIN") or shutil.which("vibrobed")
    if not path or not os.access(path, os.X_OK):
        pytest.fail("no vibrobed binary: set VIBROBED_BIN (cargo build --release builds it)")
    return path


def without_wall_clock(summary):
    """The summary less what the wall clock decides (the rest is deterministic, bit for bit)."""
    return {k: v for k, v in summary.items() if k not in ("wall_seconds", "collisions_per_second")}


@pytest.fixture(autouse=True, scope="session")
def ctrl_c_raises():
    """Ctrl-C as Python's KeyboardInterrupt, as in a terminal or a notebook, even when the tests
    run in the background of a shell, which starts them with SIGINT ignored (interrupt_main
    then does nothing, and the tests that press Ctrl-C would wait for ever)."""
    import signal

    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
