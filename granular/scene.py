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
its health verdict (:mod:`.health`) and the bodies it steps with (:mod:`.interaction`). Its structural edits
(spheres, walls, holds, histories: :mod:`.scene_edits`) and what it reports and checkpoints (:mod:`.scene_readout`)
are mixed in; the class itself keeps the clock, the time step and the stepping schedule.
"""

from __future__ import annotations


from typing import Callable

from . import runtime
from .contact_history import ContactHistory
from .device_parts import DeviceParts
from .errors import WheelsoilInputError
from .grid import UniformGrid
from .health import measure_health, require_healthy
from .interaction import Interaction
from .materials import LUNAR_SOIL_SIMULANT, SOIL_SOIL, Material, PairProperties, effective_modulus
from .particles import DeviceState
from .scene_domain import SceneDomain
from .scene_edits import SceneEdits
from .scene_input import as_vector, check_scene_options
from .scene_readout import SceneReadout
from .scene_rebuilds import WIDEN_HORIZON_STEPS, SceneRebuilds
from .sphere_state import SphereState
from .timestep import TimeStepEstimate, estimate_time_step
from .walls import MAX_WALLS, Wall

__all__ = ["DeviceParts", "DeviceState", "Interaction", "MAX_WALLS", "Scene", "Wall"]


class Scene(SceneEdits, SceneReadout, SceneRebuilds):
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
        self._rebuild_requested = False
        #: Run the force pass and the integration as one launch per step when nothing else acts on
        #: the particles (granular.fused_step; the same arithmetic, fewer passes over memory).
        self.fuse_steps = True
        #: steps ahead a sphere in the air looks, at its speed, for a wider search of its clearance at a rebuild
        #: (0: none; :data:`WIDEN_HORIZON_STEPS`)
        self.widen_steps = WIDEN_HORIZON_STEPS
        # host copy of the state (authoritative while self._device is None)
        self._spheres = SphereState.empty()  # the host state (the device's while it steps: _to_host)
        self._hist: ContactHistory | None = None  # the contacts' memory (host copy; None: no contact yet)
        self._device: DeviceParts | None = None

    # ------------------------------------------------------------------ bodies and device parts
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
            if largest > 1.0 or self._rebuild_requested:  # a sphere past its allowance, or an interaction asks
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

    # ------------------------------------------------------------------ health
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

    def _to_host(self) -> None:
        """Copy the device state back to NumPy and drop the device arrays (before structural edits)."""
        device = self._device
        if device is None:
            return
        self._spheres = self._spheres.with_motion(device.particles.download())
        self._hist = device.history()
        self._device = None
