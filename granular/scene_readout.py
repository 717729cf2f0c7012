"""What a :class:`~.scene.Scene` reports and keeps: its spheres' state as NumPy copies, its contact count and kinetic
energy, and its checkpoint (the state it continues from bit for bit).

:class:`SceneReadout` is mixed into :class:`~.scene.Scene`: it reads the device arrays while the scene steps and the
host copy otherwise (``_device``, ``_spheres``, ``_hist``).
"""

from __future__ import annotations

import numpy as np

from .errors import WheelsoilInputError
from .scene_checkpoint import SceneCheckpoint


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


class SceneReadout:
    """A scene's state read back and checkpointed (mixed into :class:`~.scene.Scene`)."""

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
