"""Explicit central-difference update of the FE nodes and of the rigid hub (Taichi kernels).

Translations: v^{n+1/2} = [(1 - a dt/2) v^{n-1/2} + dt f^n / m] / (1 + a dt/2), x^{n+1} = x^n + dt v^{n+1/2}
(central difference with mass-proportional damping a [1/s], Belytschko, Liu & Moran, *Nonlinear Finite
Elements*, sec. 6.2.4), with v taken relative to the hub's rigid-body motion when there is a hub. Rotations: the same for the spin omega with the node's isotropic lumped rotary
inertia (no gyroscopic term for an isotropic inertia), then R^{n+1} = exp(dt omega^{n+1/2}) R^n.

Every node's force is gathered from the element-corner slots that touch it (a CSR list), so no two
threads ever write the same node.

The hub is a rigid body made of the hub nodes plus its own mass and inertia. Each of its six degrees
of freedom (translation and rotation about the global axes) is either *prescribed* (velocity set by
the caller, the force the rig needs is accumulated as the reaction) or *free* (integrated from the
net force: elastic forces from the structure, the caller's applied force and gravity). The free
rotational dofs use the diagonal of the global inertia tensor: exact for rotation about a principal
axis aligned with a global axis (a wheel's axle), an approximation otherwise.
"""

import taichi as ti

from wheelsoil.taichi_types import nd_f64, nd_vec3, vec3

from .rotation import exp_so3

# rows of the hub state array (vec3 each)
HUB_POSITION, HUB_VELOCITY, HUB_SPIN = 0, 1, 2
HUB_CMD_VELOCITY, HUB_CMD_SPIN = 3, 4
HUB_APPLIED_FORCE, HUB_APPLIED_MOMENT = 5, 6
HUB_REACTION_FORCE, HUB_REACTION_MOMENT = 7, 8
HUB_FREE_TRANSLATION, HUB_FREE_ROTATION = 9, 10
HUB_OWN_INERTIA = 11
HUB_ROWS = 12
# entries of the hub scalar array
HUB_OWN_MASS, HUB_SAMPLES = 0, 1


@ti.func
def node_update(
    n: ti.i32, dt: ti.f64, damping: ti.f64, gravity: vec3, x: ti.template(), v: ti.template(), rot: ti.template(),
    w: ti.template(), mass: ti.template(), inertia: ti.template(), free: ti.template(), f_ext: ti.template(),
    k_ext: ti.template(), x_anchor: ti.template(), m_ext: ti.template(), slot_start: ti.template(),
    slot_list: ti.template(), slot_f: ti.template(), slot_m: ti.template(), f_tot: ti.template(),
    m_tot: ti.template(), hub: ti.template(), j_ext: ti.template(), j_damp: ti.template(),
):
    """Gather node n's force and moment from its element slots; advance it if it is free.

    The damping acts on the node's velocity and spin relative to the hub's rigid-body motion
    (v - v_hub - omega_hub x (x - c_hub), omega - omega_hub), so a rolling wheel is not braked by it;
    a structure without a hub has a hub state of zeros, and the damping acts on absolute velocities.

    The external force is f_ext - k_ext (x - x_anchor): a coupling hands over its contact forces
    evaluated with the node at ``x_anchor`` together with their stiffness k_ext [N/m], so that within
    the sub-steps the force follows the node's own motion (otherwise a light node under stiff contacts
    would be driven unstably by forces held over the whole coupling interval).

    The node's momentum account (the force balance's record, :meth:`.structure.Structure.take_impulses`): ``j_ext``
    gathers the impulse dt (f_ext - k_ext (x - x_anchor)) [N s] the external (contact) force gives, ``j_damp`` that
    of the damping. The update below is m (v' - v) = dt f - d dt m ((v + v') / 2 - v_rigid) exactly (c1 = 1 - h,
    c2 = 1 / (1 + h), h = d dt / 2), so the damping's impulse is the last term, taken from the two velocities.
    """
    c1 = 1.0 - 0.5 * damping * dt
    c2 = 1.0 / (1.0 + 0.5 * damping * dt)
    f = f_ext[n] + mass[n] * gravity - k_ext[n] * (x[n] - x_anchor[n])
    # written out again, not shared through a local: the compiler then forms f as before (bit for bit; a shared
    # product changed how it fused the multiply-add, and the run's trajectory with it)
    j_ext[n] += dt * (f_ext[n] - k_ext[n] * (x[n] - x_anchor[n]))
    m = m_ext[n]
    for k in range(slot_start[n], slot_start[n + 1]):
        s = slot_list[k]
        f += slot_f[s]
        m += slot_m[s]
    f_tot[n] = f
    m_tot[n] = m
    if free[n]:
        spin = hub[HUB_SPIN]
        v_rigid = hub[HUB_VELOCITY] + spin.cross(x[n] - hub[HUB_POSITION])
        v_before = v[n]
        v[n] = v_rigid + (c1 * (v[n] - v_rigid) + (dt / mass[n]) * f) * c2
        j_damp[n] -= (damping * dt * mass[n]) * (0.5 * (v_before + v[n]) - v_rigid)
        x[n] += dt * v[n]
        w[n] = spin + (c1 * (w[n] - spin) + (dt / inertia[n]) * m) * c2
        rot[n] = exp_so3(dt * w[n]) @ rot[n]


@ti.func
def hub_update(
    dt: ti.f64, gravity: vec3, n_hub: ti.i32, hub_nodes: ti.template(), hub: ti.template(), hub_rot: ti.template(),
    hub_scalar: ti.template(), x: ti.template(), mass: ti.template(), inertia: ti.template(), f_tot: ti.template(),
    m_tot: ti.template(),
):
    """Advance the rigid hub one step from the forces on its nodes (serial: one thread)."""
    c = hub[HUB_POSITION]
    m_total = hub_scalar[HUB_OWN_MASS]
    force = hub[HUB_APPLIED_FORCE] + m_total * gravity
    moment = hub[HUB_APPLIED_MOMENT]
    inertia_diag = hub[HUB_OWN_INERTIA]
    for k in range(n_hub):
        n = hub_nodes[k]
        r = x[n] - c
        force += f_tot[n]
        moment += r.cross(f_tot[n]) + m_tot[n]
        m_total += mass[n]
        inertia_diag += mass[n] * vec3(r[1] ** 2 + r[2] ** 2, r[0] ** 2 + r[2] ** 2, r[0] ** 2 + r[1] ** 2)
        inertia_diag += vec3(inertia[n])
    vel = hub[HUB_VELOCITY]
    spin = hub[HUB_SPIN]
    reaction_f = vec3(0.0)
    reaction_m = vec3(0.0)
    for i in ti.static(range(3)):
        if hub[HUB_FREE_TRANSLATION][i] > 0.5:
            vel[i] += dt * force[i] / m_total
        else:
            reaction_f[i] = m_total * (hub[HUB_CMD_VELOCITY][i] - vel[i]) / dt - force[i]
            vel[i] = hub[HUB_CMD_VELOCITY][i]
        if hub[HUB_FREE_ROTATION][i] > 0.5:
            spin[i] += dt * moment[i] / inertia_diag[i]
        else:
            reaction_m[i] = inertia_diag[i] * (hub[HUB_CMD_SPIN][i] - spin[i]) / dt - moment[i]
            spin[i] = hub[HUB_CMD_SPIN][i]
    hub[HUB_VELOCITY] = vel
    hub[HUB_SPIN] = spin
    hub[HUB_POSITION] = c + dt * vel
    hub_rot[0] = exp_so3(dt * spin) @ hub_rot[0]
    hub[HUB_REACTION_FORCE] += reaction_f
    hub[HUB_REACTION_MOMENT] += reaction_m
    hub_scalar[HUB_SAMPLES] += 1.0


@ti.func
def hub_carry(
    k: ti.i32, hub_nodes: ti.template(), hub_offset: ti.template(), hub: ti.template(), hub_rot: ti.template(),
    x: ti.template(), v: ti.template(), rot: ti.template(), w: ti.template(),
):
    """Place hub node k rigidly with the hub."""
    n = hub_nodes[k]
    rh = hub_rot[0]
    r = rh @ hub_offset[k]
    x[n] = hub[HUB_POSITION] + r
    v[n] = hub[HUB_VELOCITY] + hub[HUB_SPIN].cross(r)
    rot[n] = rh
    w[n] = hub[HUB_SPIN]


@ti.func
def node_kinetic_energy(n: ti.i32, v: ti.template(), w: ti.template(), mass: ti.template(), inertia: ti.template()) -> ti.f64:
    return 0.5 * (mass[n] * v[n].norm_sqr() + inertia[n] * w[n].norm_sqr())


@ti.kernel
def kinetic_energy(n_nodes: ti.i32, v: nd_vec3, w: nd_vec3, mass: nd_f64, inertia: nd_f64) -> ti.f64:
    """Total kinetic energy of the nodes [J]."""
    total = 0.0
    for n in range(n_nodes):
        total += node_kinetic_energy(n, v, w, mass, inertia)
    return total


@ti.kernel
def max_speed_squared(v: nd_vec3, w: nd_vec3) -> ti.f64:
    """Largest |v|^2 over the nodes; NaN or inf anywhere gives +inf."""
    worst = 0.0
    for n in v:
        s = v[n].norm_sqr()
        if not (s < 1e300) or not (w[n].norm_sqr() < 1e300):
            s = 1e308
        ti.atomic_max(worst, s)
    return worst
