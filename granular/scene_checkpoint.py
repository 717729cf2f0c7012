"""What a scene's checkpoint holds (plain NumPy, no Taichi): its spheres, the contacts' memory and its clock, and
their flat arrays as a checkpoint file stores them (:meth:`SceneCheckpoint.to_arrays`, ``from_arrays``)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .contact_history import ContactHistory
from .sphere_state import SphereState

#: The prefix of the contact history's arrays among a checkpoint's.
HISTORY_PREFIX = "hist_"


@dataclass(frozen=True)
class SceneCheckpoint:
    """A scene's state to continue from: its ``spheres``, the contacts' memory (``history``; None: no contact yet),
    the simulated ``time`` [s], the steps taken, the neighbour-list rebuilds, the contacts after the last step, and
    the most grains seen above the domain's top at one health check."""

    spheres: SphereState
    history: ContactHistory | None
    time: float
    steps_taken: int
    neighbor_rebuilds: int
    n_contacts: int
    most_above_top: int = 0

    def to_arrays(self) -> dict:
        """Flat arrays and scalars (copies): the spheres' arrays, the history's prefixed ``hist_``, the clock."""
        out = self.spheres.to_arrays()
        for key, value in (self.history.to_arrays() if self.history is not None else {}).items():
            out[HISTORY_PREFIX + key] = value
        out.update(time=self.time, steps_taken=self.steps_taken, neighbor_rebuilds=self.neighbor_rebuilds,
                   _n_contacts=self.n_contacts, most_above_top=self.most_above_top)
        return {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in out.items()}

    @classmethod
    def from_arrays(cls, arrays: Mapping) -> "SceneCheckpoint":
        """The checkpoint :meth:`to_arrays` wrote (``most_above_top`` is absent from checkpoints written before it)."""
        history = {k[len(HISTORY_PREFIX):]: v for k, v in arrays.items() if k.startswith(HISTORY_PREFIX)}
        return cls(SphereState.from_arrays(arrays), ContactHistory.from_arrays(history) if history else None,
                   float(arrays["time"]), int(arrays["steps_taken"]), int(arrays["neighbor_rebuilds"]),
                   int(arrays["_n_contacts"]), int(arrays.get("most_above_top", 0)))
