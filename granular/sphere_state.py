"""The spheres' host state, typed (issue 38 item 5): what a :class:`~.scene.Scene` keeps in NumPy between device
sessions, checkpoints and structural edits (adding, removing, holding or moving spheres). One row per sphere.

The device holds the same state in Taichi arrays while the scene steps (:class:`~.particles.ParticleArrays`); the
scene copies it back (:class:`SphereMotion`) before every structural edit and every checkpoint. Each edit returns a
new :class:`SphereState`, so no edit can leave the seven arrays with different lengths. NumPy only.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .errors import WheelsoilInputError

#: The per-sphere arrays of a checkpoint, in the order :meth:`SphereState.to_arrays` writes them.
STATE_ARRAYS = ("x", "v", "w", "f", "t", "r", "mobile")


@dataclass(frozen=True)
class SphereMotion:
    """What the spheres' stepping changes, (N, 3) each: centres x [m], velocities v [m/s], spins w [rad/s], and
    the last step's contact forces f [N] and torques t [N m]."""

    x: np.ndarray
    v: np.ndarray
    w: np.ndarray
    f: np.ndarray
    t: np.ndarray


@dataclass(frozen=True)
class SphereState:
    """The spheres' host state: :class:`SphereMotion`'s arrays plus radii r (N,) [m] and mobility (N,) (1: integrated;
    0: held in place, :meth:`~.scene.Scene.hold`)."""

    x: np.ndarray
    v: np.ndarray
    w: np.ndarray
    f: np.ndarray
    t: np.ndarray
    r: np.ndarray
    mobile: np.ndarray

    def __post_init__(self) -> None:
        n = self.r.shape[0]
        for name in STATE_ARRAYS:
            a = getattr(self, name)
            expected = (n,) if name in ("r", "mobile") else (n, 3)
            if a.shape != expected:
                raise WheelsoilInputError(f"sphere state {name} has shape {a.shape}; expected {expected}")

    @classmethod
    def empty(cls) -> SphereState:
        vec = np.zeros((0, 3))
        return cls(vec, vec, vec, vec, vec, np.zeros(0), np.zeros(0))

    def __len__(self) -> int:
        return int(self.r.shape[0])

    def appended(self, x: np.ndarray, v: np.ndarray, w: np.ndarray, r: np.ndarray) -> SphereState:
        """These spheres followed by new ones at x, v, w (N, 3) and radii r (N,), free and without forces yet."""
        n = len(r)
        zeros = np.zeros((n, 3))
        return SphereState(*(np.concatenate([a, b]) for a, b in (
            (self.x, x), (self.v, v), (self.w, w), (self.f, zeros), (self.t, zeros), (self.r, r),
            (self.mobile, np.ones(n)))))

    def kept(self, mask: np.ndarray) -> SphereState:
        """Only the spheres where ``mask`` (N,) bool is true, in their order."""
        return SphereState(*(getattr(self, name)[mask] for name in STATE_ARRAYS))

    def with_motion(self, motion: SphereMotion) -> SphereState:
        """The same spheres with the device's motion copied back (its first N rows: a device array holds at least
        one row, even for a scene without spheres)."""
        n = len(self)
        return replace(self, x=motion.x[:n], v=motion.v[:n], w=motion.w[:n], f=motion.f[:n], t=motion.t[:n])

    def held(self, mask: np.ndarray) -> SphereState:
        """Spheres where ``mask`` is true held in place (at rest, not integrated), all others set free."""
        v, w = self.v.copy(), self.w.copy()
        v[mask] = 0.0
        w[mask] = 0.0
        return replace(self, v=v, w=w, mobile=np.where(mask, 0.0, 1.0))

    def to_arrays(self) -> dict[str, np.ndarray]:
        """Copies of the arrays by name (:data:`STATE_ARRAYS`), as a checkpoint stores them."""
        return {name: getattr(self, name).copy() for name in STATE_ARRAYS}

    @classmethod
    def from_arrays(cls, arrays: dict) -> SphereState:
        """The state a checkpoint stored (:meth:`to_arrays`); ``mobile`` may be absent (checkpoints written before
        spheres could be held: every sphere free)."""
        r = np.array(arrays["r"], float)
        mobile = np.array(arrays["mobile"], float) if "mobile" in arrays else np.ones(len(r))
        return cls(*(np.array(arrays[k], float) for k in ("x", "v", "w", "f", "t")), r, mobile)
