"""The FE structure on the device: state, stable time step, sub-stepping and the rigid hub.

:class:`Structure` is what the coupling talks to. Given nodal forces held over an interval, it advances
the structure over that interval in stable sub-steps (:meth:`Structure.advance`) and reports node
positions, velocities and the surface triangles. A set of nodes can be tied to a rigid *hub* whose
six degrees of freedom are each prescribed (kinematic drive) or free (force drive); a clamped support
is a hub held still. ``rigid=True`` ties every node to the hub: the rigid-wheel variant with the same
surface. The hub's drive and state (:mod:`.structure_hub`) and what the structure reports (:mod:`.structure_readout`)
are mixed in; the class itself builds the device arrays and keeps the clock and the stepping.
"""

from __future__ import annotations

import math

import numpy as np

from wheelsoil import runtime
from wheelsoil.errors import SimulationUnstableError, WheelsoilInputError

from . import integrator as itg
from . import stepper
from .mesh import StructureMesh
from .stability import assembled_critical_frequency
from .structure_arrays import element_arrays, hub_arrays, node_arrays, slot_arrays
from .structure_hub import HubDrive
from .structure_readout import MomentumAccount, StructureReadout

__all__ = ["DEFAULT_SAFETY", "MomentumAccount", "Structure"]

#: Fraction of the critical central-difference step used by default.
DEFAULT_SAFETY = 0.9


#: Meshes of at most this many elements step serially on a CPU backend (:func:`serial_by_default`).
SERIAL_ELEMENT_LIMIT = 1_000


def serial_by_default(rigid: bool, n_elements: int, arch: str) -> bool:
    """Whether a structure steps in one serial kernel launch unless told otherwise: on a CPU backend, a rigid
    structure (its step evaluates no element: the CMU wheel's 1,540 nodes step in 0.19 ms serially against 0.40 ms
    in parallel loops, ``benchmarks/README.md``) and a mesh of at most :data:`SERIAL_ELEMENT_LIMIT` elements, where
    parallel-loop dispatch costs more than the work. On a device backend never: there a serial loop runs on one of
    its thousands of threads, each far slower than a CPU core."""
    return arch == "cpu" and (bool(rigid) or int(n_elements) <= SERIAL_ELEMENT_LIMIT)


class Structure(HubDrive, StructureReadout):
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
    serial: run whole batches of steps in one serial kernel launch (default: :func:`serial_by_default`);
        otherwise the step runs parallel loops, several steps per launch (:mod:`.stepper`).
    """

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
        self.arrays = stepper.StructureArrays(**element_arrays(mesh), **slot_arrays(mesh, self.rigid),
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
        self.serial = serial_by_default(self.rigid, mesh.n_elements, self.arch) if serial is None else bool(serial)

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

    def max_node_speed(self) -> float:
        """The largest node speed [m/s] (inf where a state is not finite)."""
        worst = itg.max_speed_squared(self.arrays.v, self.arrays.w)
        return math.sqrt(worst) if worst < 1e300 else math.inf

    def check_health(self) -> float:
        """Raise :class:`SimulationUnstableError` if any node velocity is NaN/inf or absurdly large; return the
        largest node speed [m/s] (:meth:`max_node_speed`), for checks of the caller's own."""
        speed = self.max_node_speed()
        limit = 1e3 * self.mesh.material.wave_speed
        if not speed < limit:
            raise SimulationUnstableError(
                f"the wheel structure went unstable at t={self.time:.6g} s: node speed "
                f"{speed if speed < math.inf else float('nan'):.3g} m/s (limit {limit:.3g} m/s, NaN means "
                "non-finite state). Reduce the time step (safety) or the loads."
            )
        return speed

    # ------------------------------------------------------------------ rigid moves
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
