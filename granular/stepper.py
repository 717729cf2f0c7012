"""The scene's time step, velocity Verlet in two forms, over the typed parts of a scene.

* **separate**: kick-drift (:func:`.integrator.kick_drift`), then the force pass (:func:`.forces.contact_forces`)
  and the closing kick (:func:`.integrator.kick`) -- three launches;
* **fused**: the force pass, the closing half kick, and the next step's opening kick and drift in one launch
  (:func:`.fused_step.contact_step`; the same arithmetic, fewer passes over memory).

A :class:`Stepper` builds each kernel's argument list from the parts once and again only after a neighbour
rebuild has swapped the pair lists; every kernel runs as a compute graph (:mod:`wheelsoil.graph_launch`).
"""

import taichi as ti

from . import forces, fused_step, integrator
from .contact import ContactParameters
from .neighbor_list import NeighborList
from .particles import ParticleArrays
from .walls import WallArrays


class Stepper:
    """Launches the steps of ``particles`` with their ``neighbor_list``, ``walls`` and pair constants ``params``;
    ``external``: whether interactions add forces (``f_ext``, ``t_ext``) that the force pass must take."""

    def __init__(self, particles: ParticleArrays, neighbor_list: NeighborList, walls: WallArrays,
                 params: ContactParameters) -> None:
        self.particles, self.neighbor_list, self.walls, self.params = particles, neighbor_list, walls, params
        #: [0] contacts of the last force pass, [1] the largest squared drift since the last rebuild over the
        #: sphere's squared allowance (a rebuild is due above 1).
        self.result = ti.ndarray(ti.f64, shape=2)
        self._pairs = None
        self._contact_args: tuple = ()

    def _pair_args(self) -> tuple:
        """The force pass's pair, wall and constant arguments (rebuilt when the pair list was swapped)."""
        nl = self.neighbor_list
        if nl.pairs is not self._pairs:
            pairs, w, c = nl.pairs, self.walls, self.params
            self._contact_args = (
                pairs.start, pairs.j, pairs.xi, pairs.roll, pairs.rev, pairs.touching, pairs.partner_slot,
                nl.rev_start, w.point, w.normal, w.props, w.xi, w.roll, w.touching, w.near,
                c.e_eff, c.g_eff, c.beta, c.mu_s, c.mu_r, c.rolling,
            )
            self._pairs = nl.pairs
        return self._contact_args

    def kick_drift(self, gravity, dt: float) -> float:
        """Opening half kick and drift; returns the largest squared displacement since the last rebuild over the
        sphere's squared allowance (a rebuild is due above 1)."""
        p = self.particles
        integrator.kick_drift_graph(p.x, p.v, p.w, p.f, p.t, p.m, p.I, p.mobile, *gravity, dt, p.x_ref,
                                    self.neighbor_list.allowance_inv2, p.r, p.x_r, p.v_m, p.w_i, self.result)
        return float(self.result[0])

    def fused(self, gravity, dt: float, *, external: bool, drift: bool) -> tuple[int, float]:
        """Force pass and closing half kick, then (``drift``) the next step's opening kick and drift, in one launch;
        returns the contacts and the largest squared displacement since the last rebuild over the sphere's squared
        allowance (a rebuild is due above 1)."""
        p, grid = self.particles, self.neighbor_list.grid
        fused_step.contact_step_graph(
            p.x, p.v, p.w, p.r, p.m, p.I, p.mobile, *self._pair_args(), dt,
            grid.period, grid.inv_period, int(external), p.f_ext, p.t_ext, p.f, p.t,
            *gravity, int(drift), p.x_ref, self.neighbor_list.allowance_inv2, p.x_r, p.v_m, p.w_i, self.result,
        )
        return int(self.result[0]), float(self.result[1])

    def forces_and_kick(self, gravity, dt: float, *, external: bool) -> int:
        """Force pass, then the closing half kick (two launches); returns the contacts."""
        p, grid = self.particles, self.neighbor_list.grid
        forces.contact_forces_graph(
            p.x_r, p.v_m, p.w_i, *self._pair_args(), dt, grid.period, grid.inv_period, int(external),
            p.f_ext, p.t_ext, p.f, p.t, self.result,
        )
        integrator.kick_graph(p.v, p.w, p.f, p.t, p.m, p.I, p.mobile, *gravity, dt)
        return int(self.result[0])
