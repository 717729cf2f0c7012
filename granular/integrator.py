"""Velocity-Verlet (kick--drift--kick) integration of sphere translation and rotation.

The scheme is symplectic and second-order for conservative forces (Hairer, Lubich & Wanner,
*Geometric Numerical Integration*, sec. I.1.4); it is the ``nve/sphere`` integrator of LAMMPS and
LIGGGHTS. Spheres need no orientation for their contact mechanics, so only the angular velocity
omega is integrated: I domega/dt = T (seed 004 eq. 2 for a sphere, I = 2/5 m r^2).
"""


import taichi as ti

from .neighbors import nd_f64, nd_vec3, vec3


@ti.func
def half_kick(
    i,
    v: ti.template(),
    omega: ti.template(),
    force: ti.template(),
    torque: ti.template(),
    mass: ti.template(),
    inertia: ti.template(),
    gravity,
    half,
):
    """v += dt/2 (F/m + g), omega += dt/2 T/I for particle i."""
    v[i] += half * (force[i] / mass[i] + gravity)
    omega[i] += half * (torque[i] / inertia[i])


@ti.kernel
def kick_drift(
    x: nd_vec3,
    v: nd_vec3,
    omega: nd_vec3,
    force: nd_vec3,
    torque: nd_vec3,
    mass: nd_f64,
    inertia: nd_f64,
    gx: ti.f64,
    gy: ti.f64,
    gz: ti.f64,
    dt: ti.f64,
    x_ref: nd_vec3,
) -> ti.f64:
    """Half kick of v and omega, full drift of x; returns the largest squared displacement since the
    last neighbour-list build [m^2]. Gravity (gx, gy, gz) [m/s^2] comes as three scalars: a vector
    argument costs Taichi ~40 us per launch on the Python side."""
    half = 0.5 * dt
    gravity = vec3(gx, gy, gz)
    largest = 0.0
    for i in x:
        half_kick(i, v, omega, force, torque, mass, inertia, gravity, half)
        x[i] += dt * v[i]
        ti.atomic_max(largest, (x[i] - x_ref[i]).norm_sqr())
    return largest


@ti.kernel
def kick(
    v: nd_vec3,
    omega: nd_vec3,
    force: nd_vec3,
    torque: nd_vec3,
    mass: nd_f64,
    inertia: nd_f64,
    gx: ti.f64,
    gy: ti.f64,
    gz: ti.f64,
    dt: ti.f64,
):
    """Second half kick of v and omega with the forces at the new positions."""
    half = 0.5 * dt
    gravity = vec3(gx, gy, gz)
    for i in v:
        half_kick(i, v, omega, force, torque, mass, inertia, gravity, half)


@ti.kernel
def copy_vec3(src: nd_vec3, dst: nd_vec3):
    for i in src:
        dst[i] = src[i]


@ti.kernel
def state_health(
    x: nd_vec3, v: nd_vec3, omega: nd_vec3, mass: nd_f64, inertia: nd_f64, lo: vec3, hi: vec3, out: nd_f64
):
    """out = [non-finite count, count outside [lo, hi], max speed^2, kinetic energy (trans. + rot.)]."""
    bad = 0.0
    outside = 0.0
    vmax2 = 0.0
    energy = 0.0
    for i in x:
        p = x[i]
        u = v[i]
        w = omega[i]
        s = p.sum() + u.sum() + w.sum()
        if not (s == s) or ti.abs(s) > 1e300:
            bad += 1.0
        elif (p < lo).any() or (p > hi).any():
            outside += 1.0
        u2 = u.norm_sqr()
        ti.atomic_max(vmax2, u2)
        energy += 0.5 * mass[i] * u2 + 0.5 * inertia[i] * w.norm_sqr()
    out[0] = bad
    out[1] = outside
    out[2] = vmax2
    out[3] = energy
