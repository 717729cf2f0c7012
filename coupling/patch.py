"""A moving soil patch: a bin that keeps fresh soil ahead of the wheel for as long as a run drives.

A rig's bin is as long as it is; a run that needs seconds of driving to reach a steady state would need a
bin that grows with it. The established answer is a *moving patch* (e.g. Chrono's ``GranularTerrain``
moving patch: particles left far behind the vehicle are moved to a region ahead of it, where they are
rained in and settle). Here the soil ahead is not rained in but taken from a **template**: a bed prepared
periodic along x (:class:`~wheelsoil.granular.BedSpec` ``periodic``), so that consecutive slabs of it join
without a seam, for ever, with its contact history (bed format 3). The bin has a floor and side walls; at its
two ends, spheres are *held* in place (:meth:`~wheelsoil.granular.Scene.hold`) instead of walls, so the soil
leans on the packing it continues -- a flat end wall would leave gaps into which the face slumps, a slump
that travels 0.4 m into the smoke bed within 0.1 s:

* the wheel is kept in [x_c, x_c + shift): whenever it has travelled ``shift`` past x_c, the oldest part of
  the rut -- the spheres within ``shift`` of the rear end -- is removed, and every sphere and the wheel are
  translated back by ``shift`` (a rigid translation: no contact changes);
* the zone [L - shift - buffer, L) at the front is then filled with the template's spheres of that zone, in
  the template's own coordinates shifted by everything shifted so far, at rest, with the template's
  tangential contact history: with each other, and with every sphere behind that still sits where the
  template puts it. Without the history, friction-held spheres slip until they re-seat (a tenth of them by
  more than 3 % of a radius within 0.1 s on the smoke bed) and the zones would not join. The ``buffer``
  (three of the largest particle diameters) re-places the spheres held at the front last time, so the zone's
  rear face meets soil that has been free and in the template's equilibrium all along;
* the spheres within ``hold`` (two of the largest diameters) of either end are held; all others are free.

Where soil has crept all the same, a template sphere that would overlap it by more than ``overlap_tolerance``
of a radius is left out. What the wheel meets ahead is thus always the prepared bed, at any travelled
distance, with the particle count nearly constant. The sizes keep the ends and the renewed zone away from the
wheel: the zone ahead lies at least ``ahead`` beyond the wheel's outer radius and the rear end at least
``behind`` behind it (:meth:`MovingPatch.check_start`).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.granular.bed import Bed

from .patch_geometry import PatchGeometry


class MovingPatch:
    """Re-centres the wheel on a periodic bed and renews the soil ahead of it (see the module docstring).

    Parameters
    ----------
    bed: the prepared periodic bed (its spheres are the template).
    wheel_reach: the wheel's outer radius (grousers included) [m].
    shift: distance [m] travelled between two re-centrings (the slab renewed each time).
    ahead, behind: clearance [m] between the wheel's outer radius and the renewed slab ahead and the rut's end
        behind; defaults: 0.4 and 0.25 of ``wheel_reach``.
    buffer: width [m] of the previous zone's front re-placed with each renewal (default three of the largest
        particle diameters; at least the held layer's two).
    overlap_tolerance: a sphere of the rut overlapping a sphere of the new slab by more than this fraction
        of the smaller radius is removed.
    """

    def __init__(self, bed: Bed, *, wheel_reach: float, shift: float, ahead: float | None = None,
                 behind: float | None = None, buffer: float | None = None, overlap_tolerance: float = 0.02) -> None:
        if not bed.spec.periodic:
            raise WheelsoilInputError("a moving soil patch needs a bed prepared periodic along x (soil.periodic = true)")
        g = PatchGeometry.for_wheel(bed.spec.length, wheel_reach, shift, bed.spec.diameter_max)
        g = PatchGeometry(g.length, g.reach, g.shift, g.ahead if ahead is None else float(ahead),
                          g.behind if behind is None else float(behind), g.buffer if buffer is None else float(buffer))
        self.geometry = g
        self.length, self.shift, self.reach = g.length, g.shift, g.reach
        self.ahead, self.behind, self.buffer = g.ahead, g.behind, g.buffer
        self.hold = 2.0 * bed.spec.diameter_max
        self.overlap_tolerance = float(overlap_tolerance)
        x = bed.positions.copy()
        x[:, 0] = np.mod(x[:, 0], self.length)
        self.template_x, self.template_r = x, bed.radii.copy()
        self.template = bed
        self._history = bed.history
        self.creep_tolerance = 0.01  # fraction of a radius a sphere may have crept and still count as unmoved
        self.ids = np.zeros(0, np.int64)  # each sphere's template sphere
        self.expected = np.zeros((0, 3))  # where the template puts it today [m]
        self.shifted = 0.0  # total distance shifted back so far [m]
        self.shifts = 0
        self.removed = 0  # spheres of the rut removed, all shifts
        self.added = 0
        self.left_out = 0  # template spheres not placed because they overlapped crept soil at the rear face
        self.thrown_out = 0  # grains thrown over an open end of the bin, removed (drop_thrown_out)
        self.center = None

    def check_start(self, start_x: float | None) -> float:
        """The wheel's start [m] on this patch (see :meth:`PatchGeometry.check`)."""
        self.center = self.geometry.check(start_x)
        return self.center

    # ------------------------------------------------------------------ the shift
    def update(self, bench) -> float:
        """Shift once the wheel has travelled ``shift`` past its start; returns the distance shifted [m]."""
        hub_x = float(bench.structure.hub_position[0])
        if self.center is None or hub_x - self.center < self.shift:
            return 0.0
        return self.apply(bench)

    def apply(self, bench) -> float:
        """Drop the oldest rut, translate soil and wheel back by ``shift`` and renew the zone ahead."""
        scene, d, L = bench.scene, self.shift, self.length
        x, r = scene.positions, scene.radii
        self._keep(scene, x[:, 0] >= d)  # what would end up behind the rear end
        scene.translate((-d, 0.0, 0.0))
        bench.structure.translate((-d, 0.0, 0.0))
        bench.contact.invalidate()
        self.expected[:, 0] -= d
        self.shifted += d
        self.shifts += 1
        self.removed += int(len(r) - scene.n_particles)
        # the template's spheres of the zone [L - d - buffer, L) in today's coordinates, clear of the front wall
        lo = L - d - self.buffer
        tx = np.mod(self.template_x[:, 0] - self.shifted, L)
        new = np.flatnonzero(tx >= lo)
        new_x = self.template_x[new].copy()
        new_x[:, 0] = tx[new]
        new_r = self.template_r[new]
        x, r = scene.positions, scene.radii
        out = x[:, 0] >= lo
        keep_new = self._clear_of(x[~out], r[~out], new_x, new_r)
        self.left_out += int((~keep_new).sum())
        self.removed += int(out.sum())
        self.added += int(keep_new.sum())
        self._keep(scene, ~out)
        new, new_x = new[keep_new], new_x[keep_new]
        first = scene.n_particles
        scene.add_spheres(new_x, self.template_r[new], **self.template.wall_history_for(scene, new))
        self.ids = np.concatenate([self.ids, new])
        self.expected = np.concatenate([self.expected, new_x])
        self._restore_pairs(scene, np.arange(first, scene.n_particles))
        self._hold_ends(scene)
        return d

    def drop_thrown_out(self, scene) -> int:
        """Remove the grains that have left the bin over one of its open ends (a grain launched from under the
        wheel flies on its arc; behind the rear end it is soil of the old rut, which the next shift would remove
        anyway). Returns how many; the scene's health check does not count x at open ends
        (:attr:`~wheelsoil.granular.Scene.open_ends_x`)."""
        x = scene.positions[:, 0]
        inside = (x >= 0.0) & (x <= self.length)
        if inside.all():
            return 0
        self._keep(scene, inside)
        self.thrown_out += int((~inside).sum())
        return int((~inside).sum())

    def _hold_ends(self, scene) -> None:
        x = scene.positions[:, 0]
        scene.hold((x < self.hold) | (x >= self.length - self.hold))

    def _keep(self, scene, mask: np.ndarray) -> None:
        scene.keep_spheres(mask)
        self.ids, self.expected = self.ids[mask], self.expected[mask]

    def _restore_pairs(self, scene, placed: np.ndarray) -> None:
        """Give the template's contacts of the spheres just ``placed`` their template history: with each
        other, and with spheres already in the bin that sit where the template puts them (within
        ``creep_tolerance`` of a radius), so the new zone joins the soil behind it in the template's
        equilibrium instead of re-seating."""
        h = self._history
        if h is None or not h.n_pairs or not len(placed):
            return
        pi, pj = h.pair_i.astype(np.int64), h.pair_j.astype(np.int64)
        x, r = scene.positions, scene.radii
        unmoved = np.linalg.norm(x - self.expected, axis=1) <= self.creep_tolerance * r
        unmoved[placed] = True
        where = np.full(len(self.template_r), -1, np.int64)  # template sphere -> its unmoved sphere in the bin
        where[self.ids[unmoved]] = np.flatnonzero(unmoved)
        is_new = np.zeros(len(self.template_r), bool)
        is_new[self.ids[placed]] = True
        sel = (is_new[pi] | is_new[pj]) & (where[pi] >= 0) & (where[pj] >= 0)
        if sel.any():
            scene.set_contact_history(where[pi[sel]], where[pj[sel]], h.pair_xi[sel], h.pair_roll[sel])

    def _clear_of(self, x: np.ndarray, r: np.ndarray, new_x: np.ndarray, new_r: np.ndarray) -> np.ndarray:
        """Which new spheres overlap no kept sphere by more than ``overlap_tolerance`` of the smaller radius."""
        ok = np.ones(len(new_r), bool)
        if not len(r) or not len(new_r):
            return ok
        reach = r.max() + new_r.max()
        near = np.flatnonzero(x[:, 0] >= new_x[:, 0].min() - reach)
        if not near.size:
            return ok
        tree = cKDTree(x[near])
        for a, hits in enumerate(tree.query_ball_point(new_x, reach)):
            if hits:
                k = near[np.asarray(hits)]
                gap = np.linalg.norm(x[k] - new_x[a], axis=1) - (r[k] + new_r[a])
                ok[a] = not np.any(gap < -self.overlap_tolerance * np.minimum(r[k], new_r[a]))
        return ok

    def start(self, scene) -> None:
        """Begin on a scene made from the template bed without end walls (sphere k is template sphere k):
        hold the spheres at its ends."""
        self.ids, self.expected = np.arange(scene.n_particles), scene.positions.copy()
        self._hold_ends(scene)

    # ------------------------------------------------------------------ checkpoints
    def state(self) -> dict:
        return {"shifted": self.shifted, "shifts": self.shifts, "removed": self.removed, "added": self.added,
                "left_out": self.left_out, "thrown_out": self.thrown_out, "center": self.center, "ids": self.ids.copy(),
                "expected": self.expected.copy()}

    def restore_state(self, state: dict) -> None:
        self.shifted = float(state["shifted"])
        self.shifts, self.removed, self.added = int(state["shifts"]), int(state["removed"]), int(state["added"])
        self.left_out = int(state["left_out"])
        self.thrown_out = int(state.get("thrown_out", 0))  # absent from checkpoints written before it
        self.ids, self.expected = np.asarray(state["ids"], np.int64), np.asarray(state["expected"], float)
        self.center = float(state["center"])
