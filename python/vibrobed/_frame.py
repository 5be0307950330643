"""The type of one frame of :func:`vibrobed.frames`, imported with the first frame."""

from __future__ import annotations

from typing import TYPE_CHECKING, Dict, NamedTuple, Optional

if TYPE_CHECKING:
    import numpy as np


class Frame(NamedTuple):
    """One frame: the disks in the scene at ``time``, one row each."""

    index: int
    time: float
    ids: np.ndarray
    """Each row's disk id (uint32)."""
    positions: np.ndarray
    """``x, y`` (n × 2)."""
    velocities: np.ndarray
    """``vx, vy`` (n × 2)."""
    spins: Optional[np.ndarray]
    """``angle, ω`` (n × 2), rough disks only."""
    floor_height: Optional[float]
    series: Dict[str, float]
    """The recording's time series at this frame (energies, temperature, centre of mass)."""
