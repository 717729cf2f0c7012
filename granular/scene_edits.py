"""The structural edits of a :class:`~.scene.Scene`: walls, spheres added, moved, kept and held, their velocities and
their contacts' memory.

:class:`SceneEdits` is mixed into :class:`~.scene.Scene` and works on its host state: every edit first brings the
state back from the device (``_to_host``), changes the host copy (``_spheres``: :class:`.sphere_state.SphereState`;
``_hist``: :class:`.contact_history.ContactHistory`; ``walls``), and leaves the next step to upload it again. The
checks on what an edit is handed live in :mod:`.scene_input`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .contact_history import ContactHistory
from .errors import WheelsoilInputError
from .materials import SOIL_STEEL, STEEL, Material, PairProperties
from .scene_input import as_array, as_vector, checked_mask, checked_plane, checked_spheres, checked_wall_rows
from .walls import MAX_WALLS, Wall


class SceneEdits:
    """Walls, spheres and contact histories of a scene, edited on the host (mixed into :class:`~.scene.Scene`)."""

    def add_wall(
        self,
        point,
        normal,
        *,
        material: Material | None = STEEL,
        pair: PairProperties = SOIL_STEEL,
    ) -> int:
        """Add an infinite plane through ``point`` [m] whose ``normal`` points towards the particles.

        Returns the wall's index. ``material=None`` is a perfectly rigid wall.
        """
        p, nrm = checked_plane(point, normal, material, pair, len(self.walls), MAX_WALLS)
        self._to_host()
        self.walls.append(Wall(p, nrm, material, pair))
        if self._hist is not None:
            self._hist = self._hist.with_wall()
        return len(self.walls) - 1

    def add_box_walls(
        self,
        lo=None,
        hi=None,
        *,
        top: bool = False,
        material: Material | None = STEEL,
        pair: PairProperties = SOIL_STEEL,
    ) -> list[int]:
        """Floor and four side walls of the box ``[lo, hi]`` (default: the domain); ``top`` adds a lid.
        A scene periodic along x gets no walls at the two ends along x."""
        lo = self.domain_min if lo is None else as_vector("lo", lo)
        hi = self.domain_max if hi is None else as_vector("hi", hi)
        planes = [(lo, (0, 0, 1))]
        if not self.periodic_x:
            planes += [(lo, (1, 0, 0)), (hi, (-1, 0, 0))]
        planes += [(lo, (0, 1, 0)), (hi, (0, -1, 0))]
        if top:
            planes.append((hi, (0, 0, -1)))
        return [self.add_wall(p, n, material=material, pair=pair) for p, n in planes]

    def add_spheres(self, positions, radii, velocities=None, angular_velocities=None, *, wall_history=None,
                    wall_roll_history=None) -> slice:
        """Add spheres; arrays are (N, 3) [m], (N,) [m], (N, 3) [m/s], (N, 3) [rad/s].

        Returns the slice of particle indices they received. Every sphere must lie inside the domain.
        ``wall_history``: (N, walls, 3) tangential displacements [m] of their wall contacts (default none);
        ``wall_roll_history``: (N, walls, 3) their rolling spring torques [N m] (EPSD walls; default none);
        pair histories are set with :meth:`set_contact_history`.
        """
        x, r, v, w = checked_spheres(positions, radii, velocities, angular_velocities)
        x, n = self.domain.placed(x), len(x)
        self._require_inside(x, "lies outside the domain")
        given = [checked_wall_rows(name, rows, n, len(self.walls))
                 for name, rows in (("wall_history", wall_history), ("wall_roll_history", wall_roll_history))]
        self._to_host()
        start = self.n_particles
        if self._hist is not None or any(rows is not None for rows in given):
            # new spheres have no pairs yet; existing indices are unchanged
            self._hist = self._history().with_spheres(n, *given)
        self._spheres = self._spheres.appended(x, v, w, r)
        if start:
            self._renumbered(np.concatenate([np.arange(start), np.full(n, -1)]))
        return slice(start, start + n)

    def _require_inside(self, x: np.ndarray, what: str) -> None:
        outside = self.domain.outside(x)
        if outside.size:
            k = int(outside[0])
            raise WheelsoilInputError(
                f"sphere {k} at {x[k].tolist()} m {what} {self.domain.describe()} ({outside.size} spheres outside)")

    def translate(self, offset) -> None:
        """Move every sphere by ``offset`` [m] (a 3-vector); a periodic scene wraps them back into its period.

        Contact histories are kept (a rigid translation changes no contact). Used by a moving soil patch
        that keeps the wheel near the middle of a periodic bin (:mod:`wheelsoil.coupling.patch`).
        """
        off = as_vector("offset", offset)
        self._to_host()
        x = self.domain.placed(self._spheres.x + off)
        self._require_inside(x, f"leaves the domain when translated by {off.tolist()} m:")
        self._spheres = replace(self._spheres, x=x)

    def contact_history(self) -> ContactHistory:
        """The contacts' memory (:class:`.contact_history.ContactHistory`): each pair's and each wall contact's
        tangential displacement [m] and rolling spring torque [N m]."""
        self._to_host()
        return ContactHistory(**self._history().to_arrays())  # a copy: the caller may edit it

    def set_contact_history(self, pair_i, pair_j, pair_xi, pair_roll=None) -> None:
        """Give the sphere pairs (pair_i[k], pair_j[k]) the tangential displacements pair_xi[k] [m] and rolling
        spring torques pair_roll[k] [N m] (default zero) (replacing what they had): a contact of spheres placed at
        rest in a state that had it (a prepared bed's).

        Both are as sphere pair_i[k] sees them (the force pass's owner convention); a pair given with
        pair_i > pair_j is turned around (both negated)."""
        self._to_host()
        self._hist = self._history().with_pairs(pair_i, pair_j, pair_xi, pair_roll)

    def _history(self) -> ContactHistory:
        """The host's contact history (an empty one before any contact)."""
        return self._hist if self._hist is not None else ContactHistory.empty(self.n_particles, len(self.walls))

    def _renumbered(self, old_of_new: np.ndarray) -> None:
        """Tell the interactions that sphere k is now the former sphere old_of_new[k] (-1: a new one)."""
        for body in self.interactions:
            hook = getattr(body, "renumber", None)
            if hook is not None:
                hook(self, old_of_new)

    def keep_spheres(self, mask) -> None:
        """Keep only the spheres where ``mask`` is true (contact history of kept pairs is preserved,
        also that of interactions with a ``renumber(scene, old_of_new)`` method)."""
        mask = checked_mask(mask, self.n_particles)
        self._to_host()
        self._spheres = self._spheres.kept(mask)
        if self._hist is not None:
            self._hist = self._hist.kept(mask)
        self._renumbered(np.flatnonzero(mask))

    def hold(self, mask) -> None:
        """Hold the spheres where ``mask`` is true in place (zero velocity and spin; they still push on the
        others, as a wall of spheres would) and set all others free. A moving soil patch holds the spheres
        at the ends of its bin, so that the soil leans on the packing it continues, not on a flat wall."""
        mask = checked_mask(mask, self.n_particles)
        self._to_host()
        self._spheres = self._spheres.held(mask)

    @property
    def held(self) -> np.ndarray:
        """Which spheres are held in place (:meth:`hold`), (N,) bool."""
        return self._spheres.mobile == 0.0

    def set_velocities(self, velocities=None, angular_velocities=None) -> None:
        """Overwrite translational [m/s] and/or angular [rad/s] velocities, (N, 3) each."""
        self._to_host()
        if velocities is not None:
            self._spheres = replace(self._spheres, v=as_array("velocities", velocities, (3,), self.n_particles))
        if angular_velocities is not None:
            self._spheres = replace(self._spheres, w=as_array("angular_velocities", angular_velocities, (3,),
                                                                self.n_particles))
