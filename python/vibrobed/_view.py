"""The Rerun viewer embedded in a notebook: a run's recording shown while it is written.

The recording is the command line's (the same recorder, layout and file as ``vibrobed run
--rrd``). While the run writes it, a thread follows the file and hands each batch of complete
messages to the viewer as an RRD stream of its own: the stream header, the messages, and an end
with an empty footer, which is how rerun-sdk's own notebook viewer is fed (its callback sink).
The notebook's viewer comes from rerun-sdk's ``notebook`` extra, at the version of the recorder
built into this package (:data:`RERUN_VERSION`).
"""

from __future__ import annotations

import os
import struct
import tempfile
import threading
import time
from typing import Any, Callable, Optional

#: The version of Rerun whose recorder this package holds; its viewer must be the same version.
RERUN_VERSION = "0.36.3"

# The RRD stream's framing (re_log_encoding 0.36): a 12-byte stream header ("RRF2", the
# version, the encoding options), then messages, each a 16-byte header (kind, length: u64 little
# endian) and its payload; a message of kind 0 ends the stream and carries its footer, followed
# by a 32-byte stream footer.
_STREAM_HEADER = 12
_MESSAGE_HEADER = 16
_END = 0
_FOURCC = b"RRF2"
# xxh32 of an empty footer with Rerun's seed (7850921): the stream footer's checksum of the
# empty footer that ends each piece, as rerun-sdk's callback sink ends its own.
_EMPTY_FOOTER_CRC = 0x2A973671


def _end(length_so_far: int) -> bytes:
    """An end message with an empty footer, and the stream footer pointing at it, for a piece of
    ``length_so_far`` bytes (its stream header included)."""
    end = struct.pack("<QQ", _END, 0)
    footer = struct.pack("<QQI", length_so_far + len(end), 0, _EMPTY_FOOTER_CRC)
    return end + footer + _FOURCC + b"FOOT" + struct.pack("<I", 1)


class Pieces:
    """Cuts a recording's bytes, as they come, into self-contained RRD streams of the complete
    messages received so far: ``feed(data)`` returns one such stream, or ``None`` while no
    message is complete. ``ended`` once the recording's own end has come (its footer, the
    chunks' index, is not passed on: each piece ends with its own)."""

    def __init__(self) -> None:
        self.header: Optional[bytes] = None
        self.buffer = bytearray()
        self.ended = False

    def feed(self, data: bytes) -> Optional[bytes]:
        if self.ended:
            return None
        self.buffer += data
        if self.header is None:
            if len(self.buffer) < _STREAM_HEADER:
                return None
            self.header = bytes(self.buffer[:_STREAM_HEADER])
            del self.buffer[:_STREAM_HEADER]
            if self.header[:4] != _FOURCC:
                raise ValueError(f"not an RRD stream (it starts {self.header[:4]!r})")
        pos = 0
        while len(self.buffer) - pos >= _MESSAGE_HEADER:
            kind, length = struct.unpack_from("<QQ", self.buffer, pos)
            if kind == _END:
                self.ended = True
                break
            if len(self.buffer) - pos - _MESSAGE_HEADER < length:
                break
            pos += _MESSAGE_HEADER + length
        if pos == 0:
            return None
        piece = self.header + bytes(self.buffer[:pos])
        del self.buffer[:pos]
        return piece + _end(len(piece))


class Follow:
    """Follows the recording a run writes to ``path`` (as ``FILE.partial`` until it is complete,
    then ``FILE``), handing each piece of complete messages to ``send`` as soon as it is written,
    every ``poll`` seconds. ``start()`` before the run, ``finish()`` after it: the rest is sent,
    and ``finish`` returns how many bytes of messages went to ``send``."""

    def __init__(self, path: str, send: Callable[[bytes], Any], poll: float = 0.2):
        self.path = os.fspath(path)
        self.partial = self.path + ".partial"
        self.send = send
        self.poll = poll
        self.pieces = Pieces()
        self.sent = 0
        self.error: Optional[BaseException] = None
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._follow, name="vibrobed-view", daemon=True)
        # The file a finished run leaves is told from one there before by its inode.
        self._before = _inode(self.path)

    def start(self) -> "Follow":
        # A partial file left by an earlier run of this path would be read as this run's.
        try:
            os.remove(self.partial)
        except FileNotFoundError:
            pass
        self._thread.start()
        return self

    def _open(self):
        for name in (self.partial, self.path):
            if name == self.path and _inode(name) in (None, self._before):
                continue
            try:
                return open(name, "rb")
            except FileNotFoundError:
                continue
        return None

    def _follow(self) -> None:
        try:
            f = None
            while f is None:
                f = self._open()
                if f is None:
                    if self._done.is_set():
                        return  # the run wrote no recording (refused, or stopped before it)
                    time.sleep(self.poll / 4)
            with f:
                while True:
                    # Read what is there; once the run has ended, what is there is all there is.
                    done = self._done.is_set()
                    data = f.read()
                    piece = self.pieces.feed(data) if data else None
                    if piece is not None:
                        self.sent += len(piece)
                        self.send(piece)
                    if self.pieces.ended or (done and not data):
                        return
                    if not data:
                        time.sleep(self.poll)
        except BaseException as e:  # noqa: BLE001 (raised again by finish)
            self.error = e

    def finish(self) -> int:
        self._done.set()
        self._thread.join()
        if self.error is not None:
            raise self.error
        return self.sent


def _inode(path: str) -> Optional[int]:
    try:
        return os.stat(path).st_ino
    except FileNotFoundError:
        return None


def notebook_viewer(width: Any = "auto", height: Any = 640, wait: float = 5.0):
    """A Rerun viewer widget for a notebook (rerun-sdk's ``notebook`` extra), displayed in the
    cell, waiting up to ``wait`` seconds for it to load, so that what is sent to it shows at once
    (without a browser, as when a notebook is executed headless, it waits that long and goes
    on: what is sent is kept for the page that opens it)."""
    try:
        import rerun_notebook
    except ImportError as e:
        raise ImportError(
            "the notebook viewer needs rerun-sdk's notebook extra, at the version of the "
            f"recorder built into vibrobed: pip install 'rerun-sdk[notebook]=={RERUN_VERSION}'"
        ) from e
    version = getattr(rerun_notebook, "__version__", None)
    if version is not None and version != RERUN_VERSION:
        import warnings

        warnings.warn(
            f"vibrobed: rerun-notebook {version} may not read recordings of Rerun "
            f"{RERUN_VERSION}: pip install 'rerun-sdk[notebook]=={RERUN_VERSION}'",
            stacklevel=3,
        )
    from IPython.display import display

    viewer = rerun_notebook.Viewer(width=width, height=height)
    display(viewer)
    if wait > 0:
        _wait_until_ready(viewer, wait)
    return viewer


def _wait_until_ready(viewer, wait: float) -> None:
    """The viewer's own ``block_until_ready``, quietly: it logs a warning on timeout, which a
    notebook executed without a browser always reaches."""
    import logging

    logger = logging.getLogger()
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        viewer.block_until_ready(timeout=wait)
    except Exception:  # noqa: BLE001 (no kernel to poll: the data waits for the page)
        pass
    finally:
        logger.setLevel(level)


def temporary_recording() -> str:
    """A path for a recording nobody asked to keep (removed by :func:`discard`)."""
    return os.path.join(tempfile.mkdtemp(prefix="vibrobed-view-"), "recording.rrd")


def discard(path: str) -> None:
    for name in (path, path + ".partial"):
        try:
            os.remove(name)
        except FileNotFoundError:
            pass
    try:
        os.rmdir(os.path.dirname(path))
    except OSError:
        pass
