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
facade over its parts on the device (:attr:`Scene.device`): the particle arrays (:mod:`.particles`), the walls
(:mod:`.walls`), the neighbour list with the pairs' contact history on the shared grid (:mod:`.neighbor_list`,
:mod:`.grid`), the pair constants (:class:`.contact.ContactParameters`) and the stepper (:mod:`.stepper`); it keeps
the host mirror, the structural edits (spheres, walls, holds, histories), the clock and the health checks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np
import taichi as ti

from . import integrator, runtime
from .contact import ContactParameters
from .contact_history import ContactHistory
from .errors import SimulationUnstableError, WheelsoilInputError
from .grid import UniformGrid
from .materials import LUNAR_SOIL_SIMULANT, SOIL_SOIL, SOIL_STEEL, STEEL, Material, PairProperties, effective_modulus
from .neighbor_list import NeighborList, PairList, row_width
from .particles import DeviceState, ParticleArrays
from .sphere_state import SphereState
from .stepper import Stepper
from .timestep import TimeStepEstimate, estimate_time_step
from .walls import MAX_WALLS, Wall, WallArrays

__all__ = ["DeviceParts", "DeviceState", "Interaction", "MAX_WALLS", "Scene", "Wall"]


class Interaction:
    """A body outside the scene that exchanges contact forces with the spheres (protocol).

    The scene calls, in every step,

    * ``after_drift(scene, dt)`` once the spheres have drifted to t + dt (a body advances itself
      to t + dt here), then
    * ``add_forces(scene, dt) -> int``: it adds its contact forces and torques at t + dt to
      ``scene.device_state().external_force/external_torque`` and returns its number of contacts.
      The one-launch step that follows adds them to the sphere--sphere and sphere--wall forces
      (:mod:`.fused_step`).

    ``contact_moduli`` lists the effective Young's moduli [Pa] of its contacts with the spheres so
    that the scene's stable time step accounts for them.
    """

    contact_moduli: tuple[float, ...] = ()

    def after_drift(self, scene: "Scene", dt: float) -> None:  # pragma: no cover - protocol
        pass

    def add_forces(self, scene: "Scene", dt: float) -> int:  # pragma: no cover - protocol
        return 0


def _as_array(name: str, value, shape_tail: tuple[int, ...], n: int | None = None) -> np.ndarray:
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == len(shape_tail):  # a single item
        arr = arr[None, ...]
    if arr.shape[1:] != shape_tail or (n is not None and arr.shape[0] != n):
        want = ("N" if n is None else str(n),) + tuple(str(s) for s in shape_tail)
        raise WheelsoilInputError(f"{name} has shape {arr.shape}; expected ({', '.join(want)})")
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = np.argwhere(bad)[0]
        raise WheelsoilInputError(
            f"{name} contains a non-finite value {float(arr[tuple(idx)])!r} at index {tuple(int(i) for i in idx)}"
        )
    return np.ascontiguousarray(arr)


@dataclass
class DeviceParts:
    """A scene on the device, part by part (made from the host state, dropped before a structural edit)."""

    particles: ParticleArrays
    neighbor_list: NeighborList
    walls: WallArrays
    params: ContactParameters
    stepper: Stepper
    health: ti.Ndarray  # state_health's five figures


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
        self.domain_min = _as_array("domain_min", domain_min, (3,), 1)[0]
        self.domain_max = _as_array("domain_max", domain_max, (3,), 1)[0]
        if np.any(self.domain_max <= self.domain_min):
            raise WheelsoilInputError(
                f"domain_max {self.domain_max.tolist()} must exceed domain_min {self.domain_min.tolist()} on every axis"
            )
        self.gravity = _as_array("gravity", gravity, (3,), 1)[0]
        if not isinstance(material, Material):
            raise WheelsoilInputError(f"material must be a wheelsoil.granular.Material, got {type(material).__name__}")
        if not isinstance(pair, PairProperties):
            raise WheelsoilInputError(f"pair must be a PairProperties, got {type(pair).__name__}")
        self.material = material
        self.pair = pair
        for name, value in (("skin", skin), ("cell_size", cell_size)):
            if value is not None and not (math.isfinite(value) and value > 0):
                raise WheelsoilInputError(f"{name} = {value!r} m must be a finite number > 0")
        if not (math.isfinite(impact_speed) and impact_speed > 0):
            raise WheelsoilInputError(f"impact_speed = {impact_speed!r} m/s must be > 0")
        if int(check_interval) < 1:
            raise WheelsoilInputError(f"check_interval = {check_interval!r} must be >= 1")
        self._skin_request = skin
        self._cell_request = cell_size
        self.periodic_x = bool(periodic_x)
        self.period = float(self.domain_max[0] - self.domain_min[0]) if self.periodic_x else 0.0
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
        p = _as_array("wall point", point, (3,), 1)[0]
        nrm = _as_array("wall normal", normal, (3,), 1)[0]
        length = float(np.linalg.norm(nrm))
        if length == 0.0:
            raise WheelsoilInputError("wall normal (0, 0, 0) has no direction")
        if len(self.walls) >= MAX_WALLS:
            raise WheelsoilInputError(
                f"a scene holds at most {MAX_WALLS} planar walls (each particle tracks its wall contacts in a bit mask)"
            )
        if material is not None and not isinstance(material, Material):
            raise WheelsoilInputError(f"wall material must be a Material or None, got {type(material).__name__}")
        if not isinstance(pair, PairProperties):
            raise WheelsoilInputError(f"wall pair must be a PairProperties, got {type(pair).__name__}")
        self._to_host()
        self.walls.append(Wall(tuple(p), tuple(nrm / length), material, pair))
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
        lo = self.domain_min if lo is None else _as_array("lo", lo, (3,), 1)[0]
        hi = self.domain_max if hi is None else _as_array("hi", hi, (3,), 1)[0]
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
        x = _as_array("positions", positions, (3,))
        n = x.shape[0]
        r = _as_array("radii", radii, (), n) if np.ndim(radii) else np.full(n, float(radii))
        if np.ndim(radii) == 0 and not (math.isfinite(float(radii))):
            raise WheelsoilInputError(f"radii = {radii!r} must be finite")
        bad = np.flatnonzero(r <= 0.0)
        if bad.size:
            raise WheelsoilInputError(f"radius {float(r[bad[0]])!r} m of sphere {int(bad[0])} is invalid: radii must be > 0")
        v = np.zeros((n, 3)) if velocities is None else _as_array("velocities", velocities, (3,), n)
        w = np.zeros((n, 3)) if angular_velocities is None else _as_array("angular_velocities", angular_velocities, (3,), n)
        if self.periodic_x:
            x = x.copy()
            x[:, 0] = self._wrapped(x[:, 0])
        outside = np.flatnonzero(np.any((x < self.domain_min) | (x > self.domain_max), axis=1))
        if outside.size:
            k = int(outside[0])
            raise WheelsoilInputError(
                f"sphere {k} at {x[k].tolist()} m lies outside the domain "
                f"[{self.domain_min.tolist()}, {self.domain_max.tolist()}] ({outside.size} spheres outside)"
            )
        self._to_host()
        start = self.n_particles
        self._spheres = self._spheres.appended(x, v, w, r)
        given = [None if rows is None else np.asarray(rows, float) for rows in (wall_history, wall_roll_history)]
        for name, rows in zip(("wall_history", "wall_roll_history"), given):
            if rows is not None and rows.shape != (n, len(self.walls), 3):
                raise WheelsoilInputError(f"{name} has shape {rows.shape}; expected ({n}, {len(self.walls)}, 3)")
        if self._hist is None and any(rows is not None for rows in given):
            self._hist = ContactHistory.empty(start, len(self.walls))
        if self._hist is not None:  # new spheres have no pairs yet; existing indices are unchanged
            self._hist = self._hist.with_spheres(n, *given)
        if start:
            self._renumbered(np.concatenate([np.arange(start), np.full(n, -1)]))
        return slice(start, start + n)

    def _wrapped(self, xs: np.ndarray) -> np.ndarray:
        """x coordinates brought into [domain_min x, domain_min x + period) (periodic scenes)."""
        u = np.mod(np.asarray(xs, float) - self.domain_min[0], self.period)
        u[u >= self.period] -= self.period
        return self.domain_min[0] + u

    def translate(self, offset) -> None:
        """Move every sphere by ``offset`` [m] (a 3-vector); a periodic scene wraps them back into its period.

        Contact histories are kept (a rigid translation changes no contact). Used by a moving soil patch
        that keeps the wheel near the middle of a periodic bin (:mod:`wheelsoil.coupling.patch`).
        """
        off = _as_array("offset", offset, (3,), 1)[0]
        self._to_host()
        x = self._spheres.x + off
        if self.periodic_x:
            x[:, 0] = self._wrapped(x[:, 0])
        outside = np.flatnonzero(np.any((x < self.domain_min) | (x > self.domain_max), axis=1))
        if outside.size:
            raise WheelsoilInputError(f"translating by {off.tolist()} m moves {outside.size} spheres out of the domain")
        self._spheres = replace(self._spheres, x=x)

    def contact_history(self) -> ContactHistory:
        """The contacts' memory (:class:`.contact_history.ContactHistory`): each pair's and each wall contact's
        tangential displacement [m] and rolling spring torque [N m]."""
        self._to_host()
        if self._hist is None:
            return ContactHistory.empty(self.n_particles, len(self.walls))
        return ContactHistory(**self._hist.to_arrays())  # a copy: the caller may edit it

    def set_contact_history(self, pair_i, pair_j, pair_xi, pair_roll=None) -> None:
        """Give the sphere pairs (pair_i[k], pair_j[k]) the tangential displacements pair_xi[k] [m] and rolling
        spring torques pair_roll[k] [N m] (default zero) (replacing what they had): a contact of spheres placed at
        rest in a state that had it (a prepared bed's).

        Both are as sphere pair_i[k] sees them (the force pass's owner convention); a pair given with
        pair_i > pair_j is turned around (both negated)."""
        self._to_host()
        base = self._hist if self._hist is not None else ContactHistory.empty(self.n_particles, len(self.walls))
        self._hist = base.with_pairs(pair_i, pair_j, pair_xi, pair_roll)

    def _renumbered(self, old_of_new: np.ndarray) -> None:
        """Tell the interactions that sphere k is now the former sphere old_of_new[k] (-1: a new one)."""
        for body in self.interactions:
            hook = getattr(body, "renumber", None)
            if hook is not None:
                hook(self, old_of_new)

    def keep_spheres(self, mask) -> None:
        """Keep only the spheres where ``mask`` is true (contact history of kept pairs is preserved,
        also that of interactions with a ``renumber(scene, old_of_new)`` method)."""
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != (self.n_particles,):
            raise WheelsoilInputError(f"mask has shape {mask.shape}; expected ({self.n_particles},)")
        self._to_host()
        self._spheres = self._spheres.kept(mask)
        if self._hist is not None:
            self._hist = self._hist.kept(mask)
        self._renumbered(np.flatnonzero(mask))

    def hold(self, mask) -> None:
        """Hold the spheres where ``mask`` is true in place (zero velocity and spin; they still push on the
        others, as a wall of spheres would) and set all others free. A moving soil patch holds the spheres
        at the ends of its bin, so that the soil leans on the packing it continues, not on a flat wall."""
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != (self.n_particles,):
            raise WheelsoilInputError(f"mask has shape {mask.shape}; expected ({self.n_particles},)")
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
            self._spheres = replace(self._spheres, v=_as_array("velocities", velocities, (3,), self.n_particles))
        if angular_velocities is not None:
            self._spheres = replace(self._spheres, w=_as_array("angular_velocities", angular_velocities, (3,),
                                                                 self.n_particles))

    # ------------------------------------------------------------------ time step
    @property
    def skin(self) -> float:
        if self._skin_request is not None:
            return float(self._skin_request)
        return 0.15 * 2.0 * float(self._spheres.r.min()) if self.n_particles else 0.0

    def stable_time_step(self, impact_speed: float | None = None) -> TimeStepEstimate:
        """Rayleigh and Hertz estimates for the smallest sphere (see :mod:`.timestep`)."""
        if self.n_particles == 0:
            raise WheelsoilInputError("the scene has no spheres; add some before asking for a time step")
        r_min = float(self._spheres.r.min())
        wall_moduli = tuple(effective_modulus(self.material, w.material) for w in self.walls)
        wall_moduli += tuple(float(e) for it in self.interactions for e in getattr(it, "contact_moduli", ()))
        return estimate_time_step(
            r_min,
            self.material,
            wall_moduli=wall_moduli,
            impact_speed=impact_speed or self.impact_speed,
        )

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
        dt = float(dt)
        if not (math.isfinite(dt) and dt > 0):
            raise WheelsoilInputError(f"time step {dt!r} s must be a finite number > 0")
        est = self.stable_time_step()
        if dt > est.stable * (1.0 + 1e-12):
            raise WheelsoilInputError(
                f"time step {dt:.3e} s exceeds the stable time step: {est.describe()}"
            )
        self._dt = dt

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
    _STATE_SCALARS = ("time", "steps_taken", "neighbor_rebuilds", "_n_contacts")

    def state(self) -> dict:
        """The particle state and contact history as NumPy arrays, plus the clock (for checkpoints).

        The device arrays go back to the host first, so the next step rebuilds the neighbour lists from
        exactly this state: a scene restored from it (:meth:`restore_state`) steps bit for bit like this one.
        """
        self._to_host()
        out = self._spheres.to_arrays()
        for key, value in (self._hist.to_arrays() if self._hist is not None else {}).items():
            out[f"hist_{key}"] = value
        out.update({k: getattr(self, k) for k in self._STATE_SCALARS})
        out["most_above_top"] = self.most_above_top
        return {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in out.items()}

    def restore_state(self, state: dict, *, same_spheres: bool = True) -> None:
        """Continue from a :meth:`state` of a scene with the same spheres and walls (``same_spheres=False``:
        the state may hold other spheres, e.g. a moving soil patch's; the walls must be the same)."""
        r = np.asarray(state["r"], float)
        if same_spheres and (r.shape != self._spheres.r.shape or not np.array_equal(r, self._spheres.r)):
            raise WheelsoilInputError(
                f"the saved state has {len(r)} spheres of other radii than this scene's {self.n_particles}; "
                "it belongs to another bed"
            )
        self._device = None
        self._spheres = SphereState.from_arrays(state)
        hist = {k[5:]: v for k, v in state.items() if k.startswith("hist_")}
        self._hist = ContactHistory.from_arrays(hist) if hist else None
        for k in self._STATE_SCALARS:
            setattr(self, k, type(getattr(self, k))(state[k]))
        self.most_above_top = int(state.get("most_above_top", 0))  # absent from checkpoints written before it

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
        p, out = device.particles, device.health
        lo, hi = self.domain_min.tolist(), self.domain_max.tolist()
        if self.periodic_x or self.open_ends_x:  # centres wrap at each rebuild; in between they may cross the ends
            lo[0], hi[0] = -math.inf, math.inf
        top, hi[2] = hi[2], math.inf
        integrator.state_health(p.x, p.v, p.w, p.m, p.I, lo, hi, top, out)
        bad, outside, vmax2, energy, above = out.to_numpy()
        self.most_above_top = max(self.most_above_top, int(above))
        where = f"at t = {self.time:.6g} s (step {self.steps_taken})"
        if bad:
            raise SimulationUnstableError(
                f"{int(bad)} particles have non-finite position or velocity {where}; "
                f"the time step {self.time_step:.3e} s may be too large ({self.stable_time_step().describe()})"
            )
        if outside:
            raise SimulationUnstableError(
                f"{int(outside)} particles left the domain [{self.domain_min.tolist()}, "
                f"{self.domain_max.tolist()}] m {where}; the bin may be missing a wall or the run blew up"
            )
        vmax = math.sqrt(vmax2)
        limit = 0.2 * float(self._spheres.r.min()) / self.time_step
        if vmax > limit:
            raise SimulationUnstableError(
                f"energy blow-up {where}: a particle moves at {vmax:.3g} m/s, more than 0.2 r_min per step "
                f"({limit:.3g} m/s); kinetic energy {energy:.3g} J. Reduce the time step "
                f"({self.stable_time_step().describe()})"
            )
        return {"kinetic_energy": float(energy), "max_speed": vmax, "above_top": int(above)}

    # ------------------------------------------------------------------ device state
    def _to_device(self) -> DeviceParts:
        if self._device is not None:
            return self._device
        n = self.n_particles
        s = self._spheres
        r_min, r_max = float(s.r.min()), float(s.r.max())
        skin = self.skin
        reach = 2.0 * r_max + skin
        cell = reach if self._cell_request is None else float(self._cell_request)
        if cell < reach * (1 - 1e-12):
            raise WheelsoilInputError(
                f"cell_size = {cell!r} m is smaller than the interaction reach 2 r_max + skin = {reach:.4g} m"
            )
        grid = UniformGrid.covering(self.domain_min, self.domain_max, cell, period=self.period)
        h = self._hist
        particles = ParticleArrays.upload(s.x, s.v, s.w, s.f, s.t, s.r, s.mobile, self.material.density)
        # the pair list the first build carries the history from (the host copy, if any)
        pairs = (PairList.from_history(n, h.pair_i, h.pair_j, h.pair_xi, h.pair_roll) if h is not None
                 else PairList.allocate(n, 1))
        neighbor_list = NeighborList(n, grid, skin, row_width(r_min, r_max, skin), pairs)
        walls = WallArrays.upload(self.walls, self.material, n, *((h.xi_wall, h.roll_wall) if h is not None
                                                                 else (None, None)))
        params = ContactParameters.of(self.material, self.pair)
        self._device = DeviceParts(particles, neighbor_list, walls, params,
                                   Stepper(particles, neighbor_list, walls, params), ti.ndarray(ti.f64, shape=5))
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
        self._hist = ContactHistory(**device.neighbor_list.history(), **device.walls.history())
        self._device = None

    # ------------------------------------------------------------------ read-back
    @property
    def n_particles(self) -> int:
        return len(self._spheres)

    def _read(self, key: str, host: np.ndarray) -> np.ndarray:
        if self._device is None:
            return host.copy()
        return getattr(self._device.particles, key).to_numpy()

    @property
    def positions(self) -> np.ndarray:
        """Sphere centres, (N, 3) [m]."""
        return self._read("x", self._spheres.x)

    @property
    def velocities(self) -> np.ndarray:
        """Translational velocities, (N, 3) [m/s]."""
        return self._read("v", self._spheres.v)

    @property
    def angular_velocities(self) -> np.ndarray:
        """Angular velocities, (N, 3) [rad/s]."""
        return self._read("w", self._spheres.w)

    @property
    def radii(self) -> np.ndarray:
        """Radii, (N,) [m]."""
        return self._spheres.r.copy()

    @property
    def masses(self) -> np.ndarray:
        """Masses, (N,) [kg]."""
        return self.material.density * 4.0 / 3.0 * np.pi * self._spheres.r**3

    @property
    def contact_forces(self) -> np.ndarray:
        """Sum of contact forces (particles and walls, no gravity) on each sphere, (N, 3) [N]."""
        return self._read("f", self._spheres.f)

    @property
    def contact_torques(self) -> np.ndarray:
        """Sum of contact torques about each sphere's centre, (N, 3) [N m]."""
        return self._read("t", self._spheres.t)

    @property
    def contact_count(self) -> int:
        """Number of touching pairs and particle--wall contacts after the last step."""
        return int(self._n_contacts)

    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy [J]."""
        v, w, m = self.velocities, self.angular_velocities, self.masses
        return float(0.5 * np.sum(m * np.sum(v * v, axis=1)) + 0.5 * np.sum(0.4 * m * self._spheres.r**2 * np.sum(w * w, axis=1)))
