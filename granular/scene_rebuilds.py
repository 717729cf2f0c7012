"""When a :class:`~.scene.Scene` rebuilds its neighbour lists, and how far each sphere may move before the next
rebuild: each sphere's displacement allowance from its clearance (:func:`.neighbors.displacement_allowance`),
widened for a grain in the air (:func:`.neighbors.widen_clearance`), capped or lowered sphere by sphere by the
interactions whose candidate lists rely on it (:class:`.interaction.Interaction`), and a rebuild on request.

:class:`SceneRebuilds` is mixed into :class:`~.scene.Scene` and works on its device parts (``_device``), its time step
(``_dt``) and its interactions.
"""

from __future__ import annotations

import math

from . import neighbors
from .errors import WheelsoilInputError

#: A sphere in the air that would cross its displacement allowance within this many steps at its speed searches
#: further for its clearance at a rebuild (:func:`.neighbors.widen_clearance`).
WIDEN_HORIZON_STEPS = 100


class SceneRebuilds:
    """The neighbour rebuilds of a scene and the spheres' allowances between them (mixed into
    :class:`~.scene.Scene`)."""

    def _rebuild_neighbors(self) -> None:
        device = self._device
        horizon = self.widen_steps * self._dt if self._dt else 0.0
        device.neighbor_list.rebuild(device.particles, device.walls, self.displacement_cap(), horizon)
        self.neighbor_rebuilds += 1
        self._rebuild_requested = False

    def request_neighbor_rebuild(self) -> None:
        """Rebuild the neighbour lists at the start of the next step (after its drift, before the interactions
        evaluate their contacts): an interaction asks this when its own candidate lists need rebuilding, so that
        every candidate build shares the scene's Verlet reference (:meth:`displacement_cap`)."""
        self._rebuild_requested = True

    def limit_allowances(self, gap, less: float) -> None:
        """Keep every sphere i within ``gap[i]`` - ``less`` [m] of where it was at the last neighbour rebuild (its
        allowance lowered where that is less; :func:`.neighbors.limit_allowance`): an interaction that has just
        built its candidate lists in a step in which the scene rebuilt gives each sphere's gap [m] to whatever it
        did not list (a ``ti.ndarray`` of f64, one per sphere), and ``less`` [m] (> 0, below every gap) is how far
        its own body may move before it lists them again."""
        if not (math.isfinite(less) and less > 0):
            raise WheelsoilInputError(f"less = {less!r} m must be a finite number > 0")
        neighbors.limit_allowance(gap, float(less), self._to_device().neighbor_list.allowance_inv2)

    def displacement_cap(self) -> float:
        """The most [m] any sphere may move between two neighbour rebuilds: the least ``displacement_cap(scene)``
        of the interactions that bound it (an interaction whose candidate lists were built with a margin for the
        spheres' motion since the last rebuild), infinite when none does. Each sphere's own allowance is its
        clearance at the rebuild, halved (:func:`.neighbors.displacement_allowance`), within this cap."""
        caps = [float(body.displacement_cap(self)) for body in self.interactions
                if callable(getattr(body, "displacement_cap", None))]
        return min(caps, default=math.inf)
