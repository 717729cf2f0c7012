"""The scriptable DEM scene: spheres, planar walls, materials, stepping, NumPy in and out.

Example
-------
>>> import numpy as np
>>> from wheelsoil.granular import Scene
>>> scene = Scene(domain_min=(0, 0, 0), domain_max=(0.2, 0.2, 0.3))
>>> scene.add_box_walls()                                       # floor and four side walls
>>> scene.add_spheres(positions=np.array([[0.1, 0.1, 0.05]]), radii=np.array([0.01]))
>>> scene.step(100)
>>> scene.positions.shape
(1, 3)

State lives in Taichi arrays while the scene steps; the properties below return NumPy copies. The scene is the
facade over its parts: on the device (:attr:`Scene.device`, :mod:`.device_parts`: particle arrays, walls, neighbour
list with the pairs' contact history, pair constants, stepper), and on the host, plain: its box
(:mod:`.scene_domain`), the checks on what it is handed (:mod:`.scene_input`), its spheres
(:mod:`.sphere_state`) and contacts' memory (:mod:`.contact_history`), its checkpoint (:mod:`.scene_checkpoint`),
its health verdict (:mod:`.health`) and the bodies it steps with (:mod:`.interaction`). The scene keeps the
structural edits (spheres, walls, holds, histories), the clock and the stepping schedule.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np

from . import runtime
from .contact_history import ContactHistory
from .device_parts import DeviceParts
from .errors import WheelsoilInputError
from .grid import UniformGrid
from .health import measure_health, require_healthy
from .interaction import Interaction
from .materials import LUNAR_SOIL_SIMULANT, SOIL_SOIL, SOIL_STEEL, STEEL, Material, PairProperties, effective_modulus
from .particles import DeviceState
from .scene_checkpoint import SceneCheckpoint
from .scene_domain import SceneDomain
from .scene_input import as_array, as_vector, check_scene_options, checked_mask, checked_plane, checked_spheres, \
    checked_wall_rows
from .sphere_state import SphereState
from .timestep import TimeStepEstimate, estimate_time_step
from .walls import MAX_WALLS, Wall

__all__ = ["DeviceParts", "DeviceState", "Interaction", "MAX_WALLS", "Scene", "Wall"]


class _PerSphere:
    """A per-sphere array of a :class:`Scene` as a NumPy copy: from the device while the scene steps, else from its
    host state (``key``: the array's name in both, :class:`.sphere_state.SphereState` and
    :class:`.particles.ParticleArrays`)."""

    def __init__(self, key: str, doc: str) -> None:
        self.key, self.__doc__ = key, doc

    def __get__(self, scene, owner=None):
        if scene is None:
            return self
        if scene._device is None:
            return getattr(scene._spheres, self.key).copy()
        return getattr(scene._device.particles, self.key).to_numpy()


class Scene:
    """A DEM scene of polydisperse spheres of one material and any number of planar walls.

    Parameters
    ----------
    domain_min, domain_max:
        Corners of the box [m] the particles must stay in (it sizes the neighbour grid); a particle
        leaving it stops the run with :class:`SimulationUnstableError`.
    gravity:
        Gravity vector [m/s^2]; e.g. ``(0, 0, -9.81)`` or ``(0, 0, -1.62)`` for the Moon.
    material, pair:
        Particle material and soil--soil pair properties (default: seed 004 Table 1).
    skin:
        Verlet skin [m]; default 15 % of the smallest particle diameter.
    cell_size:
        Neighbour-grid cell edge [m]; default and minimum 2 r_max + skin.
    impact_speed:
        Largest expected relative contact speed [m/s] for the Hertz time-step estimate.
    check_interval:
        Steps between health checks (NaN, escaped particles, energy blow-up).
    arch:
        Taichi backend (``"cpu"`` default, ``"cuda"``...); see :func:`wheelsoil.granular.runtime.init`.
    periodic_x:
        Make the domain periodic along x with period ``domain_max[0] - domain_min[0]``: a sphere leaving
        one end comes back at the other, and spheres near the two ends touch across it (nearest-image
        distances, :func:`.neighbors.nearest_image`). :meth:`add_box_walls` then adds no end walls.
        The period must hold at least three neighbour cells (3 (2 r_max + skin)).
    """

    def __init__(
        self,
        domain_min,
        domain_max,
        *,
        gravity=(0.0, 0.0, -9.81),
        material: Material = LUNAR_SOIL_SIMULANT,
        pair: PairProperties = SOIL_SOIL,
        skin: float | None = None,
        cell_size: float | None = None,
        impact_speed: float = 1.0,
        check_interval: int = 200,
        arch: str | None = None,
        periodic_x: bool = False,
    ) -> None:
        self.domain = SceneDomain.of(domain_min, domain_max, periodic_x)
        self.domain_min, self.domain_max = self.domain.lo, self.domain.hi
        self.gravity = as_vector("gravity", gravity)
        check_scene_options(material, pair, skin, cell_size, impact_speed, check_interval)
        self.material = material
        self.pair = pair
        self._skin_request = skin
        self._cell_request = cell_size
        self.periodic_x, self.period = self.domain.periodic_x, self.domain.period
        self.impact_speed = float(impact_speed)
        self.check_interval = int(check_interval)
        #: the most spheres found above the domain's top at one health check (launched grains; check_health)
        self.most_above_top = 0
        #: the bin has no walls at its x ends (a moving soil patch holds spheres there instead): a sphere beyond
        #: them is the owner's to remove, not an escape (check_health)
        self.open_ends_x = False
        self.arch = runtime.init(arch)

        self.walls: list[Wall] = []
        self.interactions: list[Interaction] = []
        self.time = 0.0
        self.steps_taken = 0
        self._dt: float | None = None
        self._n_contacts = 0
        self.neighbor_rebuilds = 0
        #: Run the force pass and the integration as one launch per step when nothing else acts on
        #: the particles (granular.fused_step; the same arithmetic, fewer passes over memory).
        self.fuse_steps = True
        # host copy of the state (authoritative while self._device is None)
        self._spheres = SphereState.empty()  # the host state (the device's while it steps: _to_host)
        self._hist: ContactHistory | None = None  # the contacts' memory (host copy; None: no contact yet)
        self._device: DeviceParts | None = None

    # ------------------------------------------------------------------ building the scene
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

    def add_interaction(self, interaction: Interaction) -> None:
        """Let ``interaction`` (see :class:`Interaction`) exchange forces with the spheres every step.

        The time step is re-estimated with its contact moduli (a step set earlier stays if it is
        still stable, otherwise it is refused).
        """
        for name in ("after_drift", "add_forces"):
            if not callable(getattr(interaction, name, None)):
                raise WheelsoilInputError(f"an interaction needs an {name}(scene, dt) method; {interaction!r} has none")
        self.interactions.append(interaction)
        if self._dt is not None and self.n_particles:
            self.set_time_step(min(self._dt, self.stable_time_step().stable))

    def device_state(self) -> DeviceState:
        """The device arrays the scene steps (moves the state to the device if needed)."""
        return self._to_device().particles.device_state()

    @property
    def device(self) -> DeviceParts:
        """The scene's parts on the device: particles, neighbour list, walls, pair constants, stepper (moves the
        state to the device if needed; valid until the next structural edit)."""
        return self._to_device()

    @property
    def grid(self) -> UniformGrid:
        """The uniform grid over the domain that the neighbour search bins the spheres in (interactions such as
        the wheel contact bin their own objects in the same cells)."""
        return self._to_device().neighbor_list.grid

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

    # ------------------------------------------------------------------ time step
    @property
    def skin(self) -> float:
        """Verlet skin [m]: the one asked for, or 15 % of the smallest sphere's diameter."""
        if self._skin_request is not None:
            return float(self._skin_request)
        return 0.15 * 2.0 * float(self._spheres.r.min()) if self.n_particles else 0.0

    def stable_time_step(self, impact_speed: float | None = None) -> TimeStepEstimate:
        """Rayleigh and Hertz estimates for the smallest sphere (see :mod:`.timestep`)."""
        if self.n_particles == 0:
            raise WheelsoilInputError("the scene has no spheres; add some before asking for a time step")
        wall_moduli = tuple(effective_modulus(self.material, w.material) for w in self.walls)
        wall_moduli += tuple(float(e) for it in self.interactions for e in getattr(it, "contact_moduli", ()))
        return estimate_time_step(float(self._spheres.r.min()), self.material, wall_moduli=wall_moduli,
                                  impact_speed=impact_speed or self.impact_speed)

    @property
    def time_step(self) -> float:
        """Current time step [s] (the stable estimate unless one was set)."""
        if self._dt is None:
            self._dt = self.stable_time_step().stable
        return self._dt

    @time_step.setter
    def time_step(self, dt: float) -> None:
        self.set_time_step(dt)

    def set_time_step(self, dt: float) -> None:
        """Use ``dt`` [s]; a step above the stable estimate is refused with the numbers."""
        self._dt = self.stable_time_step().checked(dt)

    # ------------------------------------------------------------------ stepping
    def step(self, n: int = 1, *, callback: Callable[[Scene], None] | None = None, callback_every: int = 0) -> None:
        """Advance ``n`` steps of ``time_step``; ``callback(scene)`` runs every ``callback_every`` steps."""
        n = int(n)
        if n < 0:
            raise WheelsoilInputError(f"number of steps {n} must be >= 0")
        if self.n_particles == 0:
            raise WheelsoilInputError("the scene has no spheres to step")
        dt = self.time_step
        device = self._to_device()
        stepper = device.stepper
        gravity = tuple(float(c) for c in self.gravity)
        half_skin2 = (0.5 * device.neighbor_list.skin) ** 2
        external = bool(self.interactions)
        # The force pass, the closing half kick and the next step's opening kick and drift run as one
        # launch (fused_step), except before a step whose state is read; interactions evaluate their
        # contacts between the drift and that launch.
        fused = self.fuse_steps
        drifted = False
        largest = 0.0
        for k in range(n):
            if not drifted:
                largest = stepper.kick_drift(gravity, dt)
            if largest > half_skin2:
                self._rebuild_neighbors()
            n_external = 0
            for body in self.interactions:
                body.after_drift(self, dt)
            for body in self.interactions:
                n_external += int(body.add_forces(self, dt))
            if fused:
                step_number = self.steps_taken + 1
                state_read = (
                    k + 1 == n
                    or step_number % self.check_interval == 0
                    or (callback is not None and callback_every and (k + 1) % callback_every == 0)
                )
                self._n_contacts, largest = stepper.fused(gravity, dt, external=external, drift=not state_read)
                self._n_contacts += n_external
                drifted = not state_read
            else:
                self._n_contacts = stepper.forces_and_kick(gravity, dt, external=external) + n_external
            self.time += dt
            self.steps_taken += 1
            if self.steps_taken % self.check_interval == 0:
                self.check_health()
            if callback is not None and callback_every and (k + 1) % callback_every == 0:
                callback(self)

    # ------------------------------------------------------------------ checkpoints
    def state(self) -> dict:
        """The particle state and contact history as NumPy arrays, plus the clock (for checkpoints;
        :class:`.scene_checkpoint.SceneCheckpoint`).

        The device arrays go back to the host first, so the next step rebuilds the neighbour lists from
        exactly this state: a scene restored from it (:meth:`restore_state`) steps bit for bit like this one.
        """
        self._to_host()
        return SceneCheckpoint(self._spheres, self._hist, self.time, self.steps_taken, self.neighbor_rebuilds,
                               self._n_contacts, self.most_above_top).to_arrays()

    def restore_state(self, state: dict, *, same_spheres: bool = True) -> None:
        """Continue from a :meth:`state` of a scene with the same spheres and walls (``same_spheres=False``:
        the state may hold other spheres, e.g. a moving soil patch's; the walls must be the same)."""
        saved = SceneCheckpoint.from_arrays(state)
        r = saved.spheres.r
        if same_spheres and (r.shape != self._spheres.r.shape or not np.array_equal(r, self._spheres.r)):
            raise WheelsoilInputError(
                f"the saved state has {len(r)} spheres of other radii than this scene's {self.n_particles}; "
                "it belongs to another bed"
            )
        self._device, self._spheres, self._hist = None, saved.spheres, saved.history
        self.time, self.steps_taken, self.neighbor_rebuilds = saved.time, saved.steps_taken, saved.neighbor_rebuilds
        self._n_contacts, self.most_above_top = saved.n_contacts, saved.most_above_top

    def check_health(self) -> dict:
        """Stop with :class:`SimulationUnstableError` on NaN, escaped particles or runaway speeds.

        A sphere above the domain's top is not an escape: a grain launched from under a wheel (elastic energy
        released by soft particles under a force chain: 1.6-2 m/s, 0.2 m up, in the CMU twin) flies and falls
        back under gravity, and the grid clamps it into its top layer meanwhile. A blow-up is caught by the speed
        limit; only the floor and the walls are hard bounds. Such grains are counted (``above_top``; the most
        at any check so far in ``most_above_top``).

        Returns the health figures: ``kinetic_energy`` [J], ``max_speed`` [m/s], ``above_top`` (count).
        """
        device = self._to_device()
        figures = measure_health(device.particles, device.health, self.domain, self.open_ends_x)
        self.most_above_top = max(self.most_above_top, figures.above_top)
        require_healthy(figures, self.domain, where=f"at t = {self.time:.6g} s (step {self.steps_taken})",
                        dt=self.time_step, r_min=float(self._spheres.r.min()),
                        stable_step=lambda: self.stable_time_step().describe())
        return figures.as_dict()

    # ------------------------------------------------------------------ device state
    def _to_device(self) -> DeviceParts:
        if self._device is not None:
            return self._device
        self._device = DeviceParts.upload(self._spheres, self._hist, self.walls, self.material, self.pair, self.domain,
                                          self.skin, self._cell_request)
        self._rebuild_neighbors()
        return self._device

    def _rebuild_neighbors(self) -> None:
        device = self._device
        device.neighbor_list.rebuild(device.particles, device.walls)
        self.neighbor_rebuilds += 1

    def _to_host(self) -> None:
        """Copy the device state back to NumPy and drop the device arrays (before structural edits)."""
        device = self._device
        if device is None:
            return
        self._spheres = self._spheres.with_motion(device.particles.download())
        self._hist = device.history()
        self._device = None

    # ------------------------------------------------------------------ read-back
    @property
    def n_particles(self) -> int:
        return len(self._spheres)

    positions = _PerSphere("x", "Sphere centres, (N, 3) [m].")
    velocities = _PerSphere("v", "Translational velocities, (N, 3) [m/s].")
    angular_velocities = _PerSphere("w", "Angular velocities, (N, 3) [rad/s].")
    contact_forces = _PerSphere("f", "Sum of contact forces (particles and walls, no gravity) on each sphere, "
                                     "(N, 3) [N].")
    contact_torques = _PerSphere("t", "Sum of contact torques about each sphere's centre, (N, 3) [N m].")

    @property
    def radii(self) -> np.ndarray:
        """Radii, (N,) [m]."""
        return self._spheres.r.copy()

    @property
    def masses(self) -> np.ndarray:
        """Masses, (N,) [kg]."""
        return self.material.density * 4.0 / 3.0 * np.pi * self._spheres.r**3

    @property
    def contact_count(self) -> int:
        """Number of touching pairs and particle--wall contacts after the last step."""
        return int(self._n_contacts)

    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy [J]."""
        v, w, m = self.velocities, self.angular_velocities, self.masses
        return float(0.5 * np.sum(m * np.sum(v * v, axis=1))
                     + 0.5 * np.sum(0.4 * m * self._spheres.r**2 * np.sum(w * w, axis=1)))
