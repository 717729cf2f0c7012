"""The FE structure on the device: state, stable time step, sub-stepping and the rigid hub.

:class:`Structure` is what the coupling talks to. Given nodal forces held over an interval, it advances
the structure over that interval in stable sub-steps (:meth:`Structure.advance`) and reports node
positions, velocities and the surface triangles. A set of nodes can be tied to a rigid *hub* whose
six degrees of freedom are each prescribed (kinematic drive) or free (force drive); a clamped support
is a hub held still. ``rigid=True`` ties every node to the hub: the rigid-wheel variant with the same
surface.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import taichi as ti

from wheelsoil import runtime
from wheelsoil.errors import SimulationUnstableError, WheelsoilInputError

from . import integrator as itg
from . import stepper
from .beam import beam_energies, beam_forces
from .mesh import StructureMesh
from .stability import assembled_critical_frequency
from .structure_arrays import element_arrays, hub_arrays, node_arrays, slot_arrays
from .shell import shell_energies, shell_forces

#: Fraction of the critical central-difference step used by default.
DEFAULT_SAFETY = 0.9


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


class Structure:
    """A shell/beam structure advanced by explicit central differences on Taichi.

    Parameters
    ----------
    mesh: the :class:`StructureMesh`.
    hub_nodes: indices of the nodes rigidly tied to the hub (none: no hub).
    hub_center: reference point of the hub [m] (default: centroid of the hub nodes).
    hub_mass, hub_inertia: the hub's own mass [kg] and principal inertia (Ixx, Iyy, Izz) [kg m^2],
        added to those of its nodes.
    rigid: tie every node to the hub (rigid variant: no element is evaluated).
    damping: mass-proportional damping coefficient a [1/s]: force -a m (v - v_hub) on every free node,
        with v_hub the hub's rigid-body velocity at the node (absolute velocity when there is no hub).
    gravity: acceleration of gravity [m/s^2] (vector).
    safety: fraction of the critical step used by :meth:`advance` (0 < safety <= 1).
    arch: Taichi backend (see :func:`wheelsoil.runtime.init`).
    serial: run whole batches of steps in one serial kernel launch (default: for meshes of at most
        ``SERIAL_ELEMENT_LIMIT`` elements, where parallel-loop dispatch costs more than the work, and for every
        rigid structure, whose step evaluates no element: the CMU wheel's 1,540 nodes step in 0.19 ms serially
        against 0.40 ms in parallel loops, benchmarks/README.md); larger meshes step with parallel loops, several
        steps per launch (:mod:`.stepper`).
    """

    SERIAL_ELEMENT_LIMIT = 1_000
    MAX_STEPS_PER_LAUNCH = 20_000
    #: Largest number of steps unrolled into one parallel launch (one kernel is compiled per count up to it).
    #: Compile time grows faster than the unrolled body: on the 25,920-element lunar-rover mesh one step
    #: compiles in ~5 s, two in ~5 s more, eight in ~20 min, while the step itself costs the same per step
    #: (6.3 ms for one, 14.0 ms for two, 39.9 ms for eight; /tmp/ct.py, 2026-11-23). Two covers the coupled
    #: smoke wheel's two sub-steps per soil step in one launch.
    PARALLEL_STEPS_PER_LAUNCH = 2

    def __init__(
        self,
        mesh: StructureMesh,
        *,
        hub_nodes=None,
        hub_center=None,
        hub_mass: float = 0.0,
        hub_inertia=(0.0, 0.0, 0.0),
        rigid: bool = False,
        damping: float = 0.0,
        gravity=(0.0, 0.0, 0.0),
        safety: float = DEFAULT_SAFETY,
        arch: str | None = None,
        serial: bool | None = None,
    ) -> None:
        self.arch = runtime.init(arch)
        self.mesh = mesh
        n = mesh.n_nodes
        if not (0.0 < safety <= 1.0):
            raise WheelsoilInputError(f"safety={safety!r} must lie in (0, 1]")
        if not (math.isfinite(damping) and damping >= 0.0):
            raise WheelsoilInputError(f"damping={damping!r} 1/s must be finite and >= 0")
        self.safety = float(safety)
        self.damping = float(damping)
        self.gravity = np.asarray(gravity, float).reshape(3)
        self.rigid = bool(rigid)
        hub = np.arange(n) if rigid else np.unique(np.asarray(hub_nodes if hub_nodes is not None else [], np.int64))
        if hub.size and (hub.min() < 0 or hub.max() >= n):
            raise WheelsoilInputError(f"hub_nodes refer to node {hub.max()}, but the mesh has {n} nodes")
        if rigid and hub_nodes is not None and len(hub_nodes) == 0:
            raise WheelsoilInputError("a rigid structure needs its hub")
        self.hub_nodes = hub
        self.mass, self.inertia = mesh.lumped_mass()
        tied = np.zeros(n, bool)
        tied[hub] = True
        loose = np.flatnonzero((self.mass <= 0) & ~tied)
        if loose.size:
            raise WheelsoilInputError(f"node {loose[0]} belongs to no element (and is not tied to the hub)")
        if hub_mass < 0 or any(i < 0 for i in hub_inertia):
            raise WheelsoilInputError(f"hub_mass={hub_mass!r} and hub_inertia={tuple(hub_inertia)!r} must be >= 0")

        self.n_facets, self.n_beams = len(mesh.triangles), len(mesh.beams)
        self._slot_beam_base = 3 * self.n_facets
        n_slots = 3 * self.n_facets + 2 * self.n_beams
        self.hub_center0 = (
            np.asarray(hub_center, float).reshape(3)
            if hub_center is not None
            else (mesh.nodes[hub].mean(axis=0) if hub.size else np.zeros(3))
        )
        self.hub_mass_total = float(hub_mass + self.mass[hub].sum())
        self.arrays = stepper.StructureArrays(**element_arrays(mesh), **slot_arrays(mesh),
                                              **node_arrays(mesh, self.mass, self.inertia, tied),
                                              **hub_arrays(mesh, hub, self.hub_center0, hub_mass, hub_inertia))

        # ---- time step
        if rigid or n_slots == 0:
            self.critical_time_step = math.inf
        else:
            omega = assembled_critical_frequency(mesh)
            zeta = self.damping / (2.0 * omega)
            self.critical_time_step = 2.0 / omega * (math.sqrt(1.0 + zeta**2) - zeta)
        self.time = 0.0
        self.steps_taken = 0
        self._account_time = 0.0  # the time the impulse accounts span (take_impulses)
        # the masses the integrator moves [kg] (set once: the device's node masses, the free nodes, the hub's whole
        # mass), for linear_momentum and gravity_force
        self._node_mass = self.arrays.mass.to_numpy()
        self._free = self.arrays.free.to_numpy().astype(bool)
        self._hub_mass = float(hub_mass + self._node_mass[hub].sum()) if hub.size else 0.0
        self.serial = (self.rigid or mesh.n_elements <= self.SERIAL_ELEMENT_LIMIT) if serial is None else bool(serial)

    # ------------------------------------------------------------------ time stepping
    @property
    def stable_time_step(self) -> float:
        """Largest step :meth:`advance` will use: ``safety`` times the critical step [s]."""
        return self.safety * self.critical_time_step

    def set_external(self, forces=None, moments=None) -> None:
        """Nodal external forces [N] and moments [N m], (N, 3) arrays held until changed (None: zero)."""
        n = self.mesh.n_nodes
        for key, val, name in (("f_ext", forces, "forces"), ("m_ext", moments, "moments")):
            arr = np.zeros((n, 3)) if val is None else np.asarray(val, float)
            if arr.shape != (n, 3):
                raise WheelsoilInputError(f"external {name} must have shape ({n}, 3), got {arr.shape}")
            if not np.all(np.isfinite(arr)):
                raise WheelsoilInputError(f"external {name} contain NaN or inf (first at node {np.argwhere(~np.isfinite(arr))[0][0]})")
            getattr(self.arrays, key).from_numpy(arr)

    def step(self, n_steps: int = 1, dt: float | None = None, *, kinetic_damping: bool = False) -> None:
        """Advance ``n_steps`` central-difference steps of size ``dt`` (default: the stable step).

        ``kinetic_damping`` zeroes the free nodes' velocities whenever the kinetic energy passes a
        maximum (static relaxation, see :mod:`wheelsoil.flexwheel.statics`).
        """
        dt = self.stable_time_step if dt is None else float(dt)
        if not math.isfinite(dt):
            raise WheelsoilInputError("a rigid structure has no stable step of its own: give dt")
        if not (0.0 < dt <= self.critical_time_step * (1.0 + 1e-12)):
            raise WheelsoilInputError(
                f"time step dt={dt:.4g} s exceeds the structure's critical step {self.critical_time_step:.4g} s "
                f"(largest element frequency); use dt <= {self.stable_time_step:.4g} s"
            )
        n_steps = int(n_steps)
        if n_steps <= 0:
            return
        g = self.gravity
        n_facets = 0 if self.rigid else self.n_facets
        n_beams = 0 if self.rigid else self.n_beams
        counts = (self.mesh.n_nodes, n_facets, n_beams, len(self.hub_nodes))
        arrays = self.arrays.kernel_args
        if self.serial:
            for done in range(0, n_steps, self.MAX_STEPS_PER_LAUNCH):
                stepper.steps_serial(min(self.MAX_STEPS_PER_LAUNCH, n_steps - done), dt, self.damping, *g,
                                     int(kinetic_damping), *counts, *arrays)
        else:
            chunk = self.PARALLEL_STEPS_PER_LAUNCH
            for done in range(0, n_steps, chunk):
                stepper.steps_parallel(min(chunk, n_steps - done), beams=n_beams > 0)(
                    dt, self.damping, *g, int(kinetic_damping), *counts, *arrays)
        self.time += dt * n_steps
        self.steps_taken += n_steps
        self._account_time += dt * n_steps

    def advance(self, interval: float, forces=None, moments=None, *, check: bool = True) -> int:
        """Advance by ``interval`` seconds in equal sub-steps no larger than the stable step.

        ``forces``/``moments`` (N, 3), if given, replace the external nodal loads and are held over the
        interval. Returns the number of sub-steps taken. Raises :class:`SimulationUnstableError` if the
        state is no longer finite afterwards.
        """
        if not (math.isfinite(interval) and interval > 0):
            raise WheelsoilInputError(f"interval={interval!r} s must be finite and > 0")
        if forces is not None or moments is not None:
            self.set_external(forces, moments)
        n_sub = 1 if not math.isfinite(self.stable_time_step) else max(1, math.ceil(interval / self.stable_time_step * (1 - 1e-12)))
        dt = interval / n_sub
        self.step(n_sub, dt)
        if check:
            self.check_health()
        return n_sub

    #: Device arrays that change while the structure moves (the rest is set up once from the mesh).
    DYNAMIC_ARRAYS = ("x", "v", "rot", "w", "f_ext", "k_ext", "x_anchor", "m_ext", "f_tot", "m_tot", "slot_f",
                      "slot_m", "peak", "hub", "hub_rot", "hub_scalar")

    def state(self) -> dict:
        """Node and hub state, held loads and the clock as NumPy arrays and scalars (for checkpoints)."""
        out = {k: getattr(self.arrays, k).to_numpy() for k in self.DYNAMIC_ARRAYS}
        out.update(time=self.time, steps_taken=self.steps_taken)
        return out

    def restore_state(self, state: dict) -> None:
        """Continue from a :meth:`state` of a structure built from the same mesh."""
        for k in self.DYNAMIC_ARRAYS:
            value = np.asarray(state[k])
            if value.shape != getattr(self.arrays, k).to_numpy().shape:
                raise WheelsoilInputError(f"the saved wheel state {k!r} has shape {value.shape}; it belongs to another mesh")
            getattr(self.arrays, k).from_numpy(np.ascontiguousarray(value))
        self.time, self.steps_taken = float(state["time"]), int(state["steps_taken"])

    def check_health(self) -> None:
        """Raise :class:`SimulationUnstableError` if any node velocity is NaN/inf or absurdly large."""
        worst = itg.max_speed_squared(self.arrays.v, self.arrays.w)
        limit = 1e3 * self.mesh.material.wave_speed
        if not worst < limit**2:
            raise SimulationUnstableError(
                f"the wheel structure went unstable at t={self.time:.6g} s: node speed "
                f"{math.sqrt(worst) if worst < 1e300 else float('nan'):.3g} m/s (limit {limit:.3g} m/s, NaN means "
                "non-finite state). Reduce the time step (safety) or the loads."
            )

    # ------------------------------------------------------------------ hub
    def _hub_state(self) -> np.ndarray:
        if not self.hub_nodes.size:
            raise WheelsoilInputError("this structure has no hub")
        return self.arrays.hub.to_numpy()

    def drive_hub(self, *, velocity=None, angular_velocity=None, free_translation=None, free_rotation=None,
                  force=None, moment=None) -> None:
        """Set the hub's drive, held until changed.

        velocity, angular_velocity: prescribed velocity [m/s] and spin [rad/s] (global frame) of the
            prescribed degrees of freedom.
        free_translation, free_rotation: three booleans each; True makes that dof force-driven.
        force, moment: load the rig applies to the hub [N, N m] (acts on the free dofs; on prescribed
            ones it only changes the reported reaction).
        """
        s = self._hub_state()
        for row, val in ((itg.HUB_CMD_VELOCITY, velocity), (itg.HUB_CMD_SPIN, angular_velocity),
                         (itg.HUB_APPLIED_FORCE, force), (itg.HUB_APPLIED_MOMENT, moment)):
            if val is not None:
                arr = np.asarray(val, float).reshape(3)
                if not np.all(np.isfinite(arr)):
                    raise WheelsoilInputError(f"hub drive value {arr.tolist()} must be finite")
                s[row] = arr
        for row, val in ((itg.HUB_FREE_TRANSLATION, free_translation), (itg.HUB_FREE_ROTATION, free_rotation)):
            if val is not None:
                s[row] = np.asarray(val, bool).reshape(3).astype(float)
        self.arrays.hub.from_numpy(s)

    def translate(self, offset) -> None:
        """Move the whole structure rigidly by ``offset`` [m] (nodes, the anchors of held contact forces and the
        hub; velocities, rotations and forces unchanged): a moving soil patch re-centring the wheel."""
        off = np.asarray(offset, float).reshape(3)
        if not np.all(np.isfinite(off)):
            raise WheelsoilInputError(f"translation {off.tolist()} must be finite")
        for key in ("x", "x_anchor"):
            getattr(self.arrays, key).from_numpy(getattr(self.arrays, key).to_numpy() + off)
        if self.hub_nodes.size:
            s = self._hub_state()
            s[itg.HUB_POSITION] += off
            self.arrays.hub.from_numpy(s)
        self.hub_center0 = self.hub_center0 + off

    def set_hub_state(self, *, velocity=None, angular_velocity=None) -> None:
        """Set the hub's current velocity and spin (e.g. to start a free dof moving)."""
        s = self._hub_state()
        if velocity is not None:
            s[itg.HUB_VELOCITY] = np.asarray(velocity, float).reshape(3)
        if angular_velocity is not None:
            s[itg.HUB_SPIN] = np.asarray(angular_velocity, float).reshape(3)
        self.arrays.hub.from_numpy(s)

    @property
    def hub_position(self) -> np.ndarray:
        return self._hub_state()[itg.HUB_POSITION].copy()

    @property
    def hub_velocity(self) -> np.ndarray:
        return self._hub_state()[itg.HUB_VELOCITY].copy()

    @property
    def hub_angular_velocity(self) -> np.ndarray:
        return self._hub_state()[itg.HUB_SPIN].copy()

    @property
    def hub_applied_force(self) -> np.ndarray:
        """The force the rig applies to the hub [N] (``drive_hub(force=...)``), held until changed."""
        return self._hub_state()[itg.HUB_APPLIED_FORCE].copy()

    @property
    def hub_rotation(self) -> np.ndarray:
        self._hub_state()
        return self.arrays.hub_rot.to_numpy()[0]

    def hub_reaction(self, reset: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Mean force [N] and moment about the hub centre [N m] the rig applied to the prescribed hub
        dofs since the last reset (zero on free dofs)."""
        s = self._hub_state()
        scal = self.arrays.hub_scalar.to_numpy()
        k = max(scal[itg.HUB_SAMPLES], 1.0)
        f, m = s[itg.HUB_REACTION_FORCE] / k, s[itg.HUB_REACTION_MOMENT] / k
        if reset:
            s[itg.HUB_REACTION_FORCE] = 0.0
            s[itg.HUB_REACTION_MOMENT] = 0.0
            scal[itg.HUB_SAMPLES] = 0.0
            self.arrays.hub.from_numpy(s)
            self.arrays.hub_scalar.from_numpy(scal)
        return f, m

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

    # ------------------------------------------------------------------ state out
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
