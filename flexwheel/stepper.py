"""The structure's time step as Taichi kernels, in a parallel and a serial form.

One central-difference step is: element forces into corner slots (facets, beams), node gather and
update, hub update, hub nodes carried along, and (for static relaxation only) kinetic damping.

* Parallel form: one kernel per phase, each a parallel loop. Right for large meshes.
* Serial form: ``n_steps`` whole steps inside one kernel launch, every loop serial. On a CPU a
  parallel loop costs tens of microseconds to dispatch, more than a small mesh's whole step, so
  small structures (the verification problems, coarse wheels) run this way; the result is the same
  to round-off.
"""

import taichi as ti

from . import integrator as itg
from .beam import beam_element
from wheelsoil.taichi_types import nd_f64, nd_i32, nd_vec3, vec3

from .shell import shell_element


@ti.kernel
def nodes_parallel(
    n_nodes: ti.i32, dt: ti.f64, damping: ti.f64, gravity: vec3, x: nd_vec3, v: nd_vec3, rot: ti.types.ndarray(),
    w: nd_vec3, mass: nd_f64, inertia: nd_f64, free: nd_i32, f_ext: nd_vec3, k_ext: nd_f64, x_anchor: nd_vec3, m_ext: nd_vec3, slot_start: nd_i32,
    slot_list: nd_i32, slot_f: nd_vec3, slot_m: nd_vec3, f_tot: nd_vec3, m_tot: nd_vec3, plane: nd_vec3,
    plane_k: ti.f64, contact: nd_i32, hub: nd_vec3,
):
    for n in range(n_nodes):
        itg.node_update(n, dt, damping, gravity, x, v, rot, w, mass, inertia, free, f_ext, k_ext, x_anchor, m_ext, slot_start,
                        slot_list, slot_f, slot_m, f_tot, m_tot, plane, plane_k, contact, hub)


@ti.kernel
def hub_parallel(
    n_hub: ti.i32, dt: ti.f64, gravity: vec3, hub_nodes: nd_i32, hub_offset: nd_vec3, hub: nd_vec3,
    hub_rot: ti.types.ndarray(), hub_scalar: nd_f64, x: nd_vec3, v: nd_vec3, rot: ti.types.ndarray(), w: nd_vec3,
    mass: nd_f64, inertia: nd_f64, f_tot: nd_vec3, m_tot: nd_vec3,
):
    for _ in range(1):
        itg.hub_update(dt, gravity, n_hub, hub_nodes, hub, hub_rot, hub_scalar, x, mass, inertia, f_tot, m_tot)
    for k in range(n_hub):
        itg.hub_carry(k, hub_nodes, hub_offset, hub, hub_rot, x, v, rot, w)


@ti.kernel
def steps_serial(
    n_steps: ti.i32, dt: ti.f64, damping: ti.f64, gravity: vec3, kinetic: ti.i32, counts: ti.types.vector(4, ti.i32),
    x: nd_vec3, v: nd_vec3, rot: ti.types.ndarray(), w: nd_vec3, mass: nd_f64, inertia: nd_f64, free: nd_i32,
    f_ext: nd_vec3, k_ext: nd_f64, x_anchor: nd_vec3, m_ext: nd_vec3, slot_start: nd_i32, slot_list: nd_i32,
    slot_f: nd_vec3, slot_m: nd_vec3,
    f_tot: nd_vec3, m_tot: nd_vec3,
    tri: ti.types.ndarray(), frame0: ti.types.ndarray(), local0: ti.types.ndarray(), km: ti.types.ndarray(),
    kb: ti.types.ndarray(),
    ends: ti.types.ndarray(), bframe0: ti.types.ndarray(), blen0: nd_f64, rigidity: ti.types.ndarray(),
    hub_nodes: nd_i32, hub_offset: nd_vec3, hub: nd_vec3, hub_rot: ti.types.ndarray(), hub_scalar: nd_f64,
    peak: nd_f64, plane: nd_vec3, plane_k: ti.f64, contact: nd_i32,
):
    """``n_steps`` complete steps in one launch; counts = (nodes, facets, beams, hub nodes)."""
    ti.loop_config(serialize=True)
    for _ in range(n_steps):
        for e in range(counts[1]):
            shell_element(e, x, rot, tri, frame0, local0, km, kb, slot_f, slot_m, 0, 1)
        for e in range(counts[2]):
            beam_element(e, x, rot, ends, bframe0, blen0, rigidity, slot_f, slot_m, 3 * counts[1], 1)
        for n in range(counts[0]):
            itg.node_update(n, dt, damping, gravity, x, v, rot, w, mass, inertia, free, f_ext, k_ext, x_anchor, m_ext, slot_start,
                            slot_list, slot_f, slot_m, f_tot, m_tot, plane, plane_k, contact, hub)
        if counts[3] > 0:
            itg.hub_update(dt, gravity, counts[3], hub_nodes, hub, hub_rot, hub_scalar, x, mass, inertia, f_tot, m_tot)
            for k in range(counts[3]):
                itg.hub_carry(k, hub_nodes, hub_offset, hub, hub_rot, x, v, rot, w)
        if kinetic:
            total = 0.0
            for n in range(counts[0]):
                total += itg.node_kinetic_energy(n, v, w, mass, inertia)
            if total < peak[0]:
                peak[0] = 0.0
                for n in range(counts[0]):
                    if free[n]:
                        v[n] = vec3(0.0)
                        w[n] = vec3(0.0)
            else:
                peak[0] = total
