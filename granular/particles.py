"""The spheres' state on the device: one typed set of arrays, one row per sphere.

:class:`ParticleArrays` is what the integrator and the force pass read and write (positions, velocities,
spins, forces, the interactions' external loads, masses, the reference positions of the Verlet skin and the
contact view); :class:`DeviceState` is the part of it an :class:`~.scene.Interaction` may use. The scene keeps
a host mirror (NumPy) that is authoritative while no device state exists, and moves between the two
(:meth:`ParticleArrays.upload`, :meth:`ParticleArrays.download`).
"""

from dataclasses import dataclass

import numpy as np
import taichi as ti

from . import integrator
from .sphere_state import SphereMotion


@dataclass(frozen=True)
class DeviceState:
    """The particle state arrays a scene steps (Taichi ndarrays, one row per sphere).

    For :class:`~.scene.Interaction` objects that add forces from bodies the scene does not own; valid
    until the next structural edit of the scene (adding or removing spheres or walls). An
    interaction reads the state and adds its contact forces and torques to ``external_force`` and
    ``external_torque`` (the step adds them to the contact forces and clears them); it must not write
    ``x``, ``v`` or ``w``: the sphere--sphere force pass reads a copy of them made at each drift (the
    contact view, :func:`wheelsoil.granular.integrator.write_contact_view`).
    """

    x: ti.Ndarray  # positions [m]
    v: ti.Ndarray  # velocities [m/s]
    w: ti.Ndarray  # angular velocities [rad/s]
    radius: ti.Ndarray  # [m]
    mass: ti.Ndarray  # [kg]
    inertia: ti.Ndarray  # moments of inertia [kg m^2]
    force: ti.Ndarray  # contact force of the last step [N]
    torque: ti.Ndarray  # contact torque of the last step [N m]
    external_force: ti.Ndarray  # an interaction adds its contact forces here [N]
    external_torque: ti.Ndarray  # an interaction adds its contact torques here [N m]


def _vec3(a: np.ndarray) -> ti.Ndarray:
    arr = ti.Vector.ndarray(3, ti.f64, shape=max(len(a), 1))
    if len(a):
        arr.from_numpy(np.ascontiguousarray(a, dtype=np.float64))
    return arr


def _scalar(a: np.ndarray, dtype=ti.f64) -> ti.Ndarray:
    arr = ti.ndarray(dtype, shape=a.shape)
    arr.from_numpy(np.ascontiguousarray(a))
    return arr


@dataclass
class ParticleArrays:
    """Device arrays of N spheres (SI units).

    x, v, w: position [m], velocity [m/s], angular velocity [rad/s]; f, t: contact force [N] and torque
    [N m] of the last step; f_ext, t_ext: what interactions add this step; x_ref: positions at the last
    neighbour rebuild (the Verlet skin test); r, m, I: radius [m], mass [kg], moment of inertia [kg m^2];
    mobile: 1 integrated, 0 held in place; x_r, v_m, w_i: the contact view, (x, r), (v, m), (omega, I) side by
    side for the force pass (written at every drift).
    """

    x: ti.Ndarray
    v: ti.Ndarray
    w: ti.Ndarray
    f: ti.Ndarray
    t: ti.Ndarray
    f_ext: ti.Ndarray
    t_ext: ti.Ndarray
    x_ref: ti.Ndarray
    r: ti.Ndarray
    mobile: ti.Ndarray
    m: ti.Ndarray
    I: ti.Ndarray  # noqa: E741 (the moment of inertia's usual name)
    x_r: ti.Ndarray
    v_m: ti.Ndarray
    w_i: ti.Ndarray

    @classmethod
    def upload(cls, x, v, w, f, t, r, mobile, density: float) -> "ParticleArrays":
        """The device arrays of the host state (positions, velocities, spins, last forces and torques, radii,
        mobility) for spheres of ``density`` [kg/m^3]; the contact view is written from them."""
        n = len(r)
        mass = density * 4.0 / 3.0 * np.pi * r**3
        p = cls(
            x=_vec3(x), v=_vec3(v), w=_vec3(w), f=_vec3(f), t=_vec3(t),
            f_ext=_vec3(np.zeros((n, 3))), t_ext=_vec3(np.zeros((n, 3))), x_ref=_vec3(x),
            r=_scalar(r), mobile=_scalar(mobile), m=_scalar(mass), I=_scalar(0.4 * mass * r**2),
            x_r=ti.Vector.ndarray(4, ti.f64, shape=max(n, 1)), v_m=ti.Vector.ndarray(4, ti.f64, shape=max(n, 1)),
            w_i=ti.Vector.ndarray(4, ti.f64, shape=max(n, 1)),
        )
        integrator.contact_view(p.x, p.v, p.w, p.r, p.m, p.I, p.x_r, p.v_m, p.w_i)
        return p

    def download(self) -> SphereMotion:
        """x, v, w, f, t as NumPy arrays (the motion the host state keeps: :class:`~.sphere_state.SphereState`)."""
        return SphereMotion(*(getattr(self, k).to_numpy() for k in ("x", "v", "w", "f", "t")))

    def device_state(self) -> DeviceState:
        return DeviceState(self.x, self.v, self.w, self.r, self.m, self.I, self.f, self.t, self.f_ext, self.t_ext)
