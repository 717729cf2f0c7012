"""The structure's time step as Taichi kernels, serial or parallel, each launched once for many steps.

One central-difference step is: element forces into corner slots (facets, beams), node gather and
update, hub update, hub nodes carried along, and (for static relaxation only) kinetic damping.

* Serial form (:data:`steps_serial`): ``n_steps`` whole steps inside one kernel launch, every loop serial.
  On a CPU a parallel loop costs tens of microseconds to dispatch, more than a small mesh's whole step, so
  small structures (the verification problems, the miniature wheel) run this way.
* Parallel form (:func:`steps_parallel`): a kernel per number of steps n, compiled on first use, whose body
  holds the n steps one after the other (unrolled at compile time), each three tasks (the elements and the
  nodes in parallel, the hub serially) -- one launch for the whole interval a coupling asks for, with every
  core on the elements and nodes.
All are launched as compute graphs (:class:`wheelsoil.graph_launch.GraphKernel`): their 30-odd array
arguments are set in C++, not in Taichi's Python launch path (~9 us each). The results are the same to
round-off in every form (the serial and parallel loops sum every node's slots in the same order).
"""

from dataclasses import dataclass, fields
from functools import cached_property

import taichi as ti

from wheelsoil.graph_launch import GraphKernel
from wheelsoil.taichi_types import nd_f64, nd_f64_2d, nd_i32, nd_ivec2, nd_ivec3, nd_mat3, nd_mat32, nd_vec3, nd_vec4, vec3

from . import integrator as itg
from .beam import beam_element
from .shell import shell_element

@dataclass
class StructureArrays:
    """The structure's device arrays (Taichi ndarrays), in the order every stepping kernel takes them after its
    scalars (:meth:`kernel_args`).

    Nodes: x, v, rot, w (position [m], velocity [m/s], rotation, angular velocity [rad/s]); mass [kg], inertia
    [kg m^2], free (1: integrated; 0: tied to the hub); f_ext, m_ext (held external force [N], moment [N m]);
    k_ext, x_anchor (the contact's lumped normal stiffness [N/m] and the position it was taken at); f_tot, m_tot
    (the last step's resultant per node). Element corners: slot_start, slot_list (each node's corner slots),
    slot_f, slot_m (the corners' forces and moments). Facets: tri, frame0, local0, km, kb (corners, reference
    frame and local coordinates, membrane and bending stiffness, packed: :func:`.shell.pack_stiffness`). Beams:
    ends, bframe0, blen0, rigidity. Hub: hub_nodes, hub_offset, hub (its rows, :data:`.integrator.HUB_ROWS`),
    hub_rot, hub_scalar. peak: kinetic damping's last energy. j_ext, j_damp: each node's impulse [N s] from its
    external (contact) force and from the damping since they were last zeroed (the force balance's record).
    """

    x: ti.Ndarray
    v: ti.Ndarray
    rot: ti.Ndarray
    w: ti.Ndarray
    mass: ti.Ndarray
    inertia: ti.Ndarray
    free: ti.Ndarray
    f_ext: ti.Ndarray
    k_ext: ti.Ndarray
    x_anchor: ti.Ndarray
    m_ext: ti.Ndarray
    slot_start: ti.Ndarray
    slot_list: ti.Ndarray
    slot_f: ti.Ndarray
    slot_m: ti.Ndarray
    f_tot: ti.Ndarray
    m_tot: ti.Ndarray
    tri: ti.Ndarray
    frame0: ti.Ndarray
    local0: ti.Ndarray
    km: ti.Ndarray
    kb: ti.Ndarray
    ends: ti.Ndarray
    bframe0: ti.Ndarray
    blen0: ti.Ndarray
    rigidity: ti.Ndarray
    hub_nodes: ti.Ndarray
    hub_offset: ti.Ndarray
    hub: ti.Ndarray
    hub_rot: ti.Ndarray
    hub_scalar: ti.Ndarray
    peak: ti.Ndarray
    j_ext: ti.Ndarray
    j_damp: ti.Ndarray

    @cached_property
    def kernel_args(self) -> tuple:
        """Every array in field order: the stepping kernels' arguments after their scalars (built once: the
        arrays are written in place, never replaced)."""
        return tuple(getattr(self, f.name) for f in fields(self))



@ti.func
def _kinetic_restart(n_nodes, v: ti.template(), w: ti.template(), mass: ti.template(), inertia: ti.template(),
                     free: ti.template(), peak: ti.template()):
    """Kinetic damping: zero the free nodes' velocities once the kinetic energy has passed a maximum
    (``peak[0]``: the kinetic energy after the previous step; 0 after a reset)."""
    total = 0.0
    for n in range(n_nodes):
        total += itg.node_kinetic_energy(n, v, w, mass, inertia)
    if total < peak[0]:
        peak[0] = 0.0
        for n in range(n_nodes):
            if free[n]:
                v[n] = vec3(0.0)
                w[n] = vec3(0.0)
    else:
        peak[0] = total


@ti.kernel
def _steps_serial(
    n_steps: ti.i32, dt: ti.f64, damping: ti.f64, gx: ti.f64, gy: ti.f64, gz: ti.f64, kinetic: ti.i32,
    n_nodes: ti.i32, n_facets: ti.i32, n_beams: ti.i32, n_hub: ti.i32,
    x: nd_vec3, v: nd_vec3, rot: nd_mat3, w: nd_vec3, mass: nd_f64, inertia: nd_f64, free: nd_i32,
    f_ext: nd_vec3, k_ext: nd_f64, x_anchor: nd_vec3, m_ext: nd_vec3, slot_start: nd_i32, slot_list: nd_i32,
    slot_f: nd_vec3, slot_m: nd_vec3, f_tot: nd_vec3, m_tot: nd_vec3,
    tri: nd_ivec3, frame0: nd_mat3, local0: nd_mat32, km: nd_f64_2d, kb: nd_f64_2d,
    ends: nd_ivec2, bframe0: nd_mat3, blen0: nd_f64, rigidity: nd_vec4,
    hub_nodes: nd_i32, hub_offset: nd_vec3, hub: nd_vec3, hub_rot: nd_mat3, hub_scalar: nd_f64, peak: nd_f64,
    j_ext: nd_vec3, j_damp: nd_vec3,
):
    """``n_steps`` complete steps in one launch, every loop serial."""
    gravity = vec3(gx, gy, gz)
    ti.loop_config(serialize=True)
    for _ in range(n_steps):
        for e in range(n_facets):
            shell_element(e, x, rot, tri, frame0, local0, km, kb, slot_f, slot_m, 0, 1)
        for e in range(n_beams):
            beam_element(e, x, rot, ends, bframe0, blen0, rigidity, slot_f, slot_m, 3 * n_facets, 1)
        for n in range(n_nodes):
            itg.node_update(n, dt, damping, gravity, x, v, rot, w, mass, inertia, free, f_ext, k_ext, x_anchor,
                            m_ext, slot_start, slot_list, slot_f, slot_m, f_tot, m_tot, hub, j_ext, j_damp)
        if n_hub > 0:
            itg.hub_update(dt, gravity, n_hub, hub_nodes, hub, hub_rot, hub_scalar, x, mass, inertia, f_tot, m_tot)
            for k in range(n_hub):
                itg.hub_carry(k, hub_nodes, hub_offset, hub, hub_rot, x, v, rot, w)
        if kinetic:
            _kinetic_restart(n_nodes, v, w, mass, inertia, free, peak)


#: The serial stepping kernel as a compute graph: (n_steps, dt, damping, gx, gy, gz, kinetic, n_nodes,
#: n_facets, n_beams, n_hub, *StructureArrays.kernel_args).
steps_serial = GraphKernel(_steps_serial)

_PARALLEL: dict = {}


def steps_parallel(n_steps: int, beams: bool = True) -> GraphKernel:
    """The parallel stepping kernel for exactly ``n_steps`` steps (compiled once per count), as a compute graph
    taking (dt, damping, gx, gy, gz, kinetic, n_nodes, n_facets, n_beams, n_hub, *StructureArrays.kernel_args).
    Without ``beams`` the kernel holds no beam element (``n_beams`` must be 0): the beam's code is half the
    compile time of a shell-only wheel's kernel.
    """
    key = (int(n_steps), bool(beams))
    if key in _PARALLEL:
        return _PARALLEL[key]
    n_steps = key[0]

    @ti.kernel
    def _steps(
        dt: ti.f64, damping: ti.f64, gx: ti.f64, gy: ti.f64, gz: ti.f64, kinetic: ti.i32,
        n_nodes: ti.i32, n_facets: ti.i32, n_beams: ti.i32, n_hub: ti.i32,
        x: nd_vec3, v: nd_vec3, rot: nd_mat3, w: nd_vec3, mass: nd_f64, inertia: nd_f64, free: nd_i32,
        f_ext: nd_vec3, k_ext: nd_f64, x_anchor: nd_vec3, m_ext: nd_vec3, slot_start: nd_i32, slot_list: nd_i32,
        slot_f: nd_vec3, slot_m: nd_vec3, f_tot: nd_vec3, m_tot: nd_vec3,
        tri: nd_ivec3, frame0: nd_mat3, local0: nd_mat32, km: nd_f64_2d, kb: nd_f64_2d,
        ends: nd_ivec2, bframe0: nd_mat3, blen0: nd_f64, rigidity: nd_vec4,
        hub_nodes: nd_i32, hub_offset: nd_vec3, hub: nd_vec3, hub_rot: nd_mat3, hub_scalar: nd_f64, peak: nd_f64,
        j_ext: nd_vec3, j_damp: nd_vec3,
    ):
        gravity = vec3(gx, gy, gz)
        for _step in ti.static(range(n_steps)):
            # three tasks a step: the elements (facets, then beams, in one parallel loop), the nodes, and one
            # serial task for the hub, its nodes and kinetic damping. Every task costs a dispatch and, after a
            # serial one, waking the other workers; the hub's 10-100 nodes take a microsecond or two on one thread.
            for e in range(n_facets + n_beams):
                if e < n_facets:
                    shell_element(e, x, rot, tri, frame0, local0, km, kb, slot_f, slot_m, 0, 1)
                else:
                    if ti.static(beams):
                        beam_element(e - n_facets, x, rot, ends, bframe0, blen0, rigidity, slot_f, slot_m,
                                     3 * n_facets, 1)
            for n in range(n_nodes):
                itg.node_update(n, dt, damping, gravity, x, v, rot, w, mass, inertia, free, f_ext, k_ext, x_anchor,
                                m_ext, slot_start, slot_list, slot_f, slot_m, f_tot, m_tot, hub, j_ext, j_damp)
            ti.loop_config(serialize=True)
            for _ in range(1):
                if n_hub > 0:
                    itg.hub_update(dt, gravity, n_hub, hub_nodes, hub, hub_rot, hub_scalar, x, mass, inertia, f_tot,
                                   m_tot)
                    for k in range(n_hub):
                        itg.hub_carry(k, hub_nodes, hub_offset, hub, hub_rot, x, v, rot, w)
                if kinetic:
                    _kinetic_restart(n_nodes, v, w, mass, inertia, free, peak)

    _PARALLEL[key] = GraphKernel(_steps)
    return _PARALLEL[key]
