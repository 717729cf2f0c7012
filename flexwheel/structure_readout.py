"""What a :class:`~.structure.Structure` reports: its node state as NumPy arrays, its elastic forces and energies, and
the account of what changed its momentum (the force balance of issue 35: :class:`MomentumAccount`).

:class:`StructureReadout` is mixed into :class:`~.structure.Structure` and reads its device arrays (``arrays``), its
mesh and the masses its integrator moves (``_node_mass``, ``_free``, ``_hub_mass``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import taichi as ti

from wheelsoil.errors import WheelsoilInputError

from . import integrator as itg
from . import stepper
from .beam import beam_energies, beam_forces
from .shell import shell_energies, shell_forces


@dataclass(frozen=True)
class MomentumAccount:
    """What changed a structure's linear momentum over ``duration`` [s] (:meth:`Structure.take_impulses`), each an
    impulse [N s] (3-vector): ``contact``, the external (contact) forces as the sub-steps applied them; ``damping``,
    the structural damping; ``reaction``, the reactions of the hub's prescribed dofs. The rig's applied force and
    gravity, constant over an interval, are the caller's to add."""

    contact: np.ndarray
    damping: np.ndarray
    reaction: np.ndarray
    duration: float


class StructureReadout:
    """A structure's state, forces, energies and momentum account read back (mixed into
    :class:`~.structure.Structure`)."""

    def linear_momentum(self) -> np.ndarray:
        """The structure's linear momentum [kg m/s] as its integrator carries it: each free node's m v, and the hub's
        whole mass (its own and its nodes') times its velocity."""
        free = self._free
        p = (self._node_mass[free, None] * self.arrays.v.to_numpy()[free]).sum(axis=0)
        if self.hub_nodes.size:
            p = p + self._hub_mass * self._hub_state()[itg.HUB_VELOCITY]
        return p

    def gravity_force(self) -> np.ndarray:
        """The weight of the whole structure [N]: every node's mass and the hub's own, times gravity."""
        total = self._node_mass[self._free].sum() + self._hub_mass
        return total * np.asarray(self.gravity, float)

    def take_impulses(self) -> MomentumAccount:
        """What changed the structure's momentum since the last call (or its construction), and zero the accounts:
        the impulses [N s] of the external (contact) forces as the sub-steps applied them, of the damping, and of the
        hub's held dofs' reactions, with the time they span [s] (:class:`MomentumAccount`). With the rig's applied
        force and gravity, they add up to the change of :meth:`linear_momentum` (the internal forces cancel)."""
        a = self.arrays
        contact = a.j_ext.to_numpy().sum(axis=0)
        damping = a.j_damp.to_numpy().sum(axis=0)
        # the reaction's mean over the steps (of equal length) times the time they span
        reaction = self.hub_reaction(reset=False)[0] * self._account_time if self.hub_nodes.size else np.zeros(3)
        account = MomentumAccount(contact=contact, damping=damping, reaction=reaction, duration=self._account_time)
        self.reset_impulses()
        return account

    def reset_impulses(self) -> None:
        """Zero the impulse accounts (:meth:`take_impulses`) without reading them: an interval's record starts here."""
        self.arrays.j_ext.fill(0.0)
        self.arrays.j_damp.fill(0.0)
        if self.hub_nodes.size:
            self.hub_reaction(reset=True)
        self._account_time = 0.0

    def device_arrays(self) -> stepper.StructureArrays:
        """The Taichi ndarrays (:class:`~.stepper.StructureArrays`, valid for the structure's lifetime). What a
        coupling reads and writes:

        ``x``, ``v``, ``w``: node positions [m], velocities [m/s] and spins [rad/s]; ``f_ext``,
        ``m_ext``: external nodal forces [N] and moments [N m], held over :meth:`advance` (a coupling
        may write them in place instead of passing arrays); ``k_ext`` [N/m], ``x_anchor`` [m]: the
        stiffness of those forces and the node positions they were evaluated at (the node feels
        f_ext - k_ext (x - x_anchor)); ``mass``: lumped node masses [kg]; ``hub``: the hub state rows
        (``flexwheel.integrator.HUB_*``; row 0 is the hub centre).
        """
        return self.arrays

    def positions(self) -> np.ndarray:
        """Node positions (N, 3) [m]."""
        return self.arrays.x.to_numpy()

    def velocities(self) -> np.ndarray:
        """Node velocities (N, 3) [m/s] (at the last half step)."""
        return self.arrays.v.to_numpy()

    def angular_velocities(self) -> np.ndarray:
        return self.arrays.w.to_numpy()

    def rotations(self) -> np.ndarray:
        """Node rotation matrices (N, 3, 3) from the reference configuration."""
        return self.arrays.rot.to_numpy()

    def displacements(self) -> np.ndarray:
        return self.positions() - self.mesh.nodes

    def nodal_forces(self) -> tuple[np.ndarray, np.ndarray]:
        """Total force and moment on every node at the last step (elastic + external + gravity)."""
        return self.arrays.f_tot.to_numpy(), self.arrays.m_tot.to_numpy()

    @property
    def surface_triangles(self) -> np.ndarray:
        """Node indices (S, 3) of the contact-surface facets."""
        return self.mesh.triangles[self.mesh.surface]

    def set_state(self, positions=None, velocities=None, rotations=None, angular_velocities=None) -> None:
        """Overwrite node state arrays (for tests and restarts)."""
        for key, val, shape in (("x", positions, (3,)), ("v", velocities, (3,)), ("rot", rotations, (3, 3)),
                                ("w", angular_velocities, (3,))):
            if val is not None:
                arr = np.asarray(val, float)
                if arr.shape != (self.mesh.n_nodes,) + shape or not np.all(np.isfinite(arr)):
                    raise WheelsoilInputError(f"{key} must be a finite array of shape {(self.mesh.n_nodes,) + shape}")
                getattr(self.arrays, key).from_numpy(arr)

    def _launch_element_forces(self) -> None:
        """Evaluate every element's corner forces and moments into the slot arrays (parallel kernels)."""
        if self.rigid:
            return
        d = self.arrays
        if self.n_facets:
            shell_forces(d.x, d.rot, d.tri, d.frame0, d.local0, d.km, d.kb, d.slot_f, d.slot_m, 0)
        if self.n_beams:
            beam_forces(d.x, d.rot, d.ends, d.bframe0, d.blen0, d.rigidity, d.slot_f,
                        d.slot_m, self._slot_beam_base)

    def element_corner_forces(self) -> tuple[np.ndarray, np.ndarray]:
        """Elastic force and moment on each element corner of the current state (facet corners, then
        beam ends; zero for a rigid structure). No step is taken."""
        self._launch_element_forces()
        return self.arrays.slot_f.to_numpy(), self.arrays.slot_m.to_numpy()

    def internal_forces(self) -> tuple[np.ndarray, np.ndarray]:
        """Elastic nodal forces and moments (N, 3) of the current state (no step is taken)."""
        n = self.mesh.n_nodes
        if self.rigid:
            return np.zeros((n, 3)), np.zeros((n, 3))
        sf, sm = self.element_corner_forces()
        nodes = np.concatenate([self.mesh.triangles.reshape(-1), self.mesh.beams.reshape(-1)])
        f, m = np.zeros((n, 3)), np.zeros((n, 3))
        np.add.at(f, nodes, sf[: len(nodes)])
        np.add.at(m, nodes, sm[: len(nodes)])
        return f, m

    def strain_energy(self) -> float:
        """Elastic energy stored in the elements [J]."""
        if self.rigid:
            return 0.0
        d = self.arrays
        total = 0.0
        if self.n_facets:
            e = ti.ndarray(ti.f64, shape=self.n_facets)
            shell_energies(d.x, d.rot, d.tri, d.frame0, d.local0, d.km, d.kb, d.slot_f, d.slot_m, e)
            total += float(e.to_numpy().sum())
        if self.n_beams:
            e = ti.ndarray(ti.f64, shape=self.n_beams)
            beam_energies(d.x, d.rot, d.ends, d.bframe0, d.blen0, d.rigidity, d.slot_f, d.slot_m, e)
            total += float(e.to_numpy().sum())
        return total

    def kinetic_energy(self) -> float:
        """1/2 sum m v^2 + 1/2 sum I omega^2 over the nodes [J] (half-step velocities)."""
        d = self.arrays
        return float(itg.kinetic_energy(self.mesh.n_nodes, d.v, d.w, d.mass, d.inertia))
