"""One kernel launch per DEM step, with or without interactions (a wheel).

A velocity-Verlet step (:mod:`.integrator`) is kick--drift, forces, kick. Between two steps nothing
reads the state when no callback or health check is due, so the second half kick of step n and the first
half kick and drift of step n+1 can run in the same particle loop as the partner gather of step n.
Interactions evaluate their contacts at the drifted positions *before* this launch and leave their forces
in the external arrays, which the partner loop adds (and clears). :func:`contact_step` does that: the owner loop and
the partner loop of :func:`.forces.contact_forces`, then, per particle,

    v += dt/2 (F/m + g), omega += dt/2 T/I                 (second half kick of this step)
    and, when ``drift`` is set,
    v += dt/2 (F/m + g), omega += dt/2 T/I, x += dt v      (first half kick and drift of the next)
    and the contact view of the new state (:func:`.integrator.write_contact_view`)

with the same Taichi functions and in the same order as the separate kernels, so the trajectory is the
velocity-Verlet one. It saves two passes over the particle arrays and two kernel launches per step
(each parallel loop costs Taichi's CPU backend ~50 us of thread wake-up); :meth:`wheelsoil.granular.Scene.step`
uses it whenever it can, launched as a compute graph (:data:`contact_step_graph`), which sets its 26
array arguments in C++ instead of Python (~0.1 ms instead of ~0.3 ms per step).
"""

import taichi as ti

from wheelsoil.graph_launch import GraphKernel

from .forces import add_external, nd_f64_2d, owner_contacts, partner_contacts
from .integrator import half_kick, write_contact_view
from .neighbors import nd_f64, nd_i32, nd_mat23, nd_vec3, nd_vec3_2d, nd_vec4, vec3


@ti.kernel
def contact_step(
    x: nd_vec3,
    v: nd_vec3,
    omega: nd_vec3,
    radius: nd_f64,
    mass: nd_f64,
    inertia: nd_f64,
    mobile: nd_f64,
    pair_start: nd_i32,
    pair_j: nd_i32,
    pair_xi: nd_vec3,
    pair_roll: nd_vec3,
    pair_rev: nd_i32,
    touching_flag: nd_i32,
    partner_slot: nd_mat23,
    rev_start: nd_i32,
    wall_point: nd_vec3,
    wall_normal: nd_vec3,
    wall_props: nd_f64_2d,
    xi_wall: nd_vec3_2d,
    roll_wall: nd_vec3_2d,
    wall_touching: nd_i32,
    wall_near: nd_i32,
    e_eff: ti.f64,
    g_eff: ti.f64,
    beta: ti.f64,
    mu_s: ti.f64,
    mu_r: ti.f64,
    rolling: ti.i32,
    dt: ti.f64,
    period: ti.f64,
    inv_period: ti.f64,
    external: ti.i32,
    ext_force: nd_vec3,
    ext_torque: nd_vec3,
    force: nd_vec3,
    torque: nd_vec3,
    gx: ti.f64,
    gy: ti.f64,
    gz: ti.f64,
    drift: ti.i32,
    x_ref: nd_vec3,
    allowance_inv2: nd_f64,
    x_r: nd_vec4,
    v_m: nd_vec4,
    w_i: nd_vec4,
    result: nd_f64,
):
    """Contact forces at the current positions (read from the contact view ``x_r``, ``v_m``,
    ``w_i``), the step's second half kick and, if ``drift`` != 0, the next step's first half kick and
    drift, which also refresh the contact view. Writes the number of contacts to ``result[0]`` and
    the largest squared displacement since the last neighbour-list build over the sphere's squared allowance
    (``allowance_inv2`` [1/m^2], :func:`.neighbors.displacement_allowance`; 0 without drift; a rebuild is due
    above 1) to ``result[1]`` (it runs as a compute graph, :class:`wheelsoil.graph_launch.GraphKernel`, which
    cannot return values)."""
    n_contacts = 0
    for i in x:
        f, t, n = owner_contacts(
            i, x_r, v_m, w_i, pair_start, pair_j, pair_xi, pair_roll, pair_rev, touching_flag,
            partner_slot, wall_point, wall_normal, wall_props, xi_wall, roll_wall, wall_touching, wall_near,
            e_eff, g_eff, beta, mu_s, mu_r, rolling, dt, period, inv_period,
        )
        force[i] = f
        torque[i] = t
        n_contacts += n
    half = 0.5 * dt
    gravity = vec3(gx, gy, gz)
    largest = 0.0
    for j in x:
        f, t = partner_contacts(j, rev_start, partner_slot)
        force[j] += f
        torque[j] += t
        if external != 0:
            add_external(j, force, torque, ext_force, ext_torque)
        half_kick(j, v, omega, force, torque, mass, inertia, mobile, gravity, half)
        if drift != 0:
            half_kick(j, v, omega, force, torque, mass, inertia, mobile, gravity, half)
            x[j] += dt * v[j]
            write_contact_view(j, x, v, omega, radius, mass, inertia, x_r, v_m, w_i)
            ti.atomic_max(largest, (x[j] - x_ref[j]).norm_sqr() * allowance_inv2[j])
    result[0] = n_contacts
    result[1] = largest


#: :func:`contact_step` as a compute graph (same arguments; compiled on first use).
contact_step_graph = GraphKernel(contact_step)
