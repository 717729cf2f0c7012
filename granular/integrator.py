"""Velocity-Verlet (kick--drift--kick) integration of sphere translation and rotation.

The scheme is symplectic and second-order for conservative forces (Hairer, Lubich & Wanner,
*Geometric Numerical Integration*, sec. I.1.4); it is the ``nve/sphere`` integrator of LAMMPS and
LIGGGHTS. Spheres need no orientation for their contact mechanics, so only the angular velocity
omega is integrated: I domega/dt = T (seed 004 eq. 2 for a sphere, I = 2/5 m r^2).

Every drift also refreshes the *contact view* of the particles (:func:`write_contact_view`): three
arrays of 4-vectors, (x, r), (v, m) and (omega, I), from which the force pass reads a partner's state
in three cache lines instead of six (:mod:`.forces`).
"""


import taichi as ti

from wheelsoil.graph_launch import GraphKernel

from .neighbors import nd_f64, nd_vec3, nd_vec4, vec3, vec4


@ti.func
def write_contact_view(
    i,
    x: ti.template(),
    v: ti.template(),
    omega: ti.template(),
    radius: ti.template(),
    mass: ti.template(),
    inertia: ti.template(),
    x_r: ti.template(),
    v_m: ti.template(),
    w_i: ti.template(),
):
    """x_r[i] = (x, r) [m], v_m[i] = (v [m/s], m [kg]), w_i[i] = (omega [rad/s], I [kg m^2])."""
    p = x[i]
    u = v[i]
    w = omega[i]
    x_r[i] = vec4(p[0], p[1], p[2], radius[i])
    v_m[i] = vec4(u[0], u[1], u[2], mass[i])
    w_i[i] = vec4(w[0], w[1], w[2], inertia[i])


@ti.kernel
def contact_view(
    x: nd_vec3,
    v: nd_vec3,
    omega: nd_vec3,
    radius: nd_f64,
    mass: nd_f64,
    inertia: nd_f64,
    x_r: nd_vec4,
    v_m: nd_vec4,
    w_i: nd_vec4,
):
    """The contact view of every particle (after the state is uploaded)."""
    for i in x:
        write_contact_view(i, x, v, omega, radius, mass, inertia, x_r, v_m, w_i)


@ti.func
def half_kick(
    i,
    v: ti.template(),
    omega: ti.template(),
    force: ti.template(),
    torque: ti.template(),
    mass: ti.template(),
    inertia: ti.template(),
    mobile: ti.template(),
    gravity,
    half,
):
    """v += dt/2 (F/m + g), omega += dt/2 T/I for particle i; both times ``mobile[i]`` (1, or 0 for a sphere
    held where it is: it keeps zero velocity and spin, so it never moves, and acts on the others as a wall)."""
    v[i] = mobile[i] * (v[i] + half * (force[i] / mass[i] + gravity))
    omega[i] = mobile[i] * (omega[i] + half * (torque[i] / inertia[i]))


@ti.kernel
def kick_drift(
    x: nd_vec3,
    v: nd_vec3,
    omega: nd_vec3,
    force: nd_vec3,
    torque: nd_vec3,
    mass: nd_f64,
    inertia: nd_f64,
    mobile: nd_f64,
    gx: ti.f64,
    gy: ti.f64,
    gz: ti.f64,
    dt: ti.f64,
    x_ref: nd_vec3,
    allowance_inv2: nd_f64,
    radius: nd_f64,
    x_r: nd_vec4,
    v_m: nd_vec4,
    w_i: nd_vec4,
    result: nd_f64,
):
    """Half kick of v and omega, full drift of x, and the contact view of the new state; writes the
    largest squared displacement since the last neighbour-list build over the sphere's squared allowance
    (``allowance_inv2`` [1/m^2], :func:`.neighbors.displacement_allowance`; a rebuild is due above 1) to
    ``result[0]`` (it runs as a compute graph, :data:`kick_drift_graph`, which cannot return values).
    Gravity (gx, gy, gz) [m/s^2] comes as three scalars: a vector argument costs Taichi ~40 us per launch on
    the Python side."""
    half = 0.5 * dt
    gravity = vec3(gx, gy, gz)
    largest = 0.0
    for i in x:
        half_kick(i, v, omega, force, torque, mass, inertia, mobile, gravity, half)
        x[i] += dt * v[i]
        write_contact_view(i, x, v, omega, radius, mass, inertia, x_r, v_m, w_i)
        ti.atomic_max(largest, (x[i] - x_ref[i]).norm_sqr() * allowance_inv2[i])
    result[0] = largest


@ti.kernel
def kick(
    v: nd_vec3,
    omega: nd_vec3,
    force: nd_vec3,
    torque: nd_vec3,
    mass: nd_f64,
    inertia: nd_f64,
    mobile: nd_f64,
    gx: ti.f64,
    gy: ti.f64,
    gz: ti.f64,
    dt: ti.f64,
):
    """Second half kick of v and omega with the forces at the new positions."""
    half = 0.5 * dt
    gravity = vec3(gx, gy, gz)
    for i in v:
        half_kick(i, v, omega, force, torque, mass, inertia, mobile, gravity, half)


@ti.kernel
def copy_vec3(src: nd_vec3, dst: nd_vec3):
    for i in src:
        dst[i] = src[i]


@ti.kernel
def state_health(
    x: nd_vec3, v: nd_vec3, omega: nd_vec3, mass: nd_f64, inertia: nd_f64, lo: vec3, hi: vec3, top: ti.f64,
    out: nd_f64
):
    """out = [non-finite count, count outside [lo, hi], max speed^2, kinetic energy (trans. + rot.), count inside
    [lo, hi] but above ``top``]."""
    bad = 0.0
    outside = 0.0
    above = 0.0
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
        elif p[2] > top:
            above += 1.0
        u2 = u.norm_sqr()
        ti.atomic_max(vmax2, u2)
        energy += 0.5 * mass[i] * u2 + 0.5 * inertia[i] * w.norm_sqr()
    out[0] = bad
    out[1] = outside
    out[2] = vmax2
    out[3] = energy
    out[4] = above


#: :func:`kick_drift` and :func:`kick` as compute graphs (same arguments; :mod:`wheelsoil.graph_launch`).
kick_drift_graph = GraphKernel(kick_drift)
kick_graph = GraphKernel(kick)
