"""The structure's device arrays built from its mesh (:class:`.stepper.StructureArrays`, one builder per part):
the elements', the corners', the nodes' and the hub's."""

from __future__ import annotations

import numpy as np
import taichi as ti

from wheelsoil.taichi_types import ivec2, ivec3, mat3, mat32, vec3, vec4
from wheelsoil.taichi_types import to_ndarray as _nd

from . import integrator as itg
from .beam_section import beam_frames, beam_section_stiffness
from .mesh import StructureMesh
from .shell import BENDING_PACK, MEMBRANE_PACK, pack_stiffness, shell_setup


def _vec(values):
    return _nd(vec3, np.asarray(values, float).reshape(-1, 3))


def element_arrays(mesh: StructureMesh) -> dict:
    """The facets' (tri, frame0, local0, km, kb) and beams' (ends, bframe0, blen0, rigidity) device arrays; a mesh
    without facets or beams gets one-row placeholders the kernels take but never read."""
    d = {}
    if len(mesh.triangles):
        frames, local, km, kb = shell_setup(mesh.nodes, mesh.triangles, mesh.thickness, mesh.material, mesh.drilling_penalty)
        km_packed, kb_packed = pack_stiffness(km, kb)
        d.update(tri=_nd(ivec3, mesh.triangles.astype(np.int32)), frame0=_nd(mat3, frames), local0=_nd(mat32, local),
                 km=_nd(ti.f64, km_packed), kb=_nd(ti.f64, kb_packed))
    else:
        d.update(tri=_nd(ivec3, np.zeros((1, 3), np.int32)), frame0=_nd(mat3, np.eye(3)[None]),
                 local0=_nd(mat32, np.zeros((1, 3, 2))), km=_nd(ti.f64, np.zeros((1, len(MEMBRANE_PACK)))),
                 kb=_nd(ti.f64, np.zeros((1, len(BENDING_PACK)))))
    if len(mesh.beams):
        bframes, blen = beam_frames(mesh.nodes, mesh.beams, mesh.beam_orientation)
        d.update(ends=_nd(ivec2, mesh.beams.astype(np.int32)), bframe0=_nd(mat3, bframes), blen0=_nd(ti.f64, blen),
                 rigidity=_nd(vec4, beam_section_stiffness(mesh.beam_section, mesh.material)))
    else:
        d.update(ends=_nd(ivec2, np.array([[0, 0]], np.int32)), bframe0=_nd(mat3, np.eye(3)[None]),
                 blen0=_nd(ti.f64, np.ones(1)), rigidity=_nd(vec4, np.zeros((1, 4))))
    return d


def slot_arrays(mesh: StructureMesh, rigid: bool = False) -> dict:
    """The element corners: each node's corner slots (slot_start, slot_list; facets' corners first, then beams'
    ends) and the corners' forces and moments (slot_f, slot_m). A ``rigid`` structure evaluates no element, so its
    nodes gather from no slot (every run empty; the slots keep their size, which checkpoints hold): the CMU twin's
    rigid wheel then reads nothing per node that could only be zero (benchmarks/README.md, 2026-11-29)."""
    n = mesh.n_nodes
    slot_node = np.concatenate([mesh.triangles.reshape(-1), mesh.beams.reshape(-1)]).astype(np.int64)
    order = np.argsort(slot_node, kind="stable")
    start = np.zeros(n + 1, np.int32)
    if not rigid:
        np.add.at(start, slot_node + 1, 1)
    n_slots = len(slot_node)
    return {"slot_start": _nd(ti.i32, np.cumsum(start).astype(np.int32)), "slot_list": _nd(ti.i32, order.astype(np.int32)),
            "slot_f": _vec(np.zeros((n_slots, 3))), "slot_m": _vec(np.zeros((n_slots, 3)))}


def node_arrays(mesh: StructureMesh, mass: np.ndarray, inertia: np.ndarray, tied: np.ndarray) -> dict:
    """The nodes' state at rest in the mesh's positions, their lumped mass and inertia (1 where a node tied to the
    hub has none), ``free`` (not ``tied``), the held loads, the contact's stiffness and anchors, the resultants, the
    impulse accounts (zero)."""
    n = mesh.n_nodes
    zeros = np.zeros((n, 3))
    return {"x": _vec(mesh.nodes), "v": _vec(zeros), "rot": _nd(mat3, np.broadcast_to(np.eye(3), (n, 3, 3))),
            "w": _vec(zeros), "mass": _nd(ti.f64, np.where(mass > 0, mass, 1.0)),
            "inertia": _nd(ti.f64, np.where(inertia > 0, inertia, 1.0)), "free": _nd(ti.i32, (~tied).astype(np.int32)),
            "f_ext": _vec(zeros), "k_ext": _nd(ti.f64, np.zeros(n)), "x_anchor": _vec(mesh.nodes), "m_ext": _vec(zeros),
            "f_tot": _vec(zeros), "m_tot": _vec(zeros), "peak": _nd(ti.f64, np.zeros(2)), "j_ext": _vec(zeros),
            "j_damp": _vec(zeros)}


def hub_arrays(mesh: StructureMesh, hub: np.ndarray, center: np.ndarray, hub_mass: float, hub_inertia) -> dict:
    """The hub's nodes and their offsets from its ``center`` [m], its state rows (:data:`.integrator.HUB_ROWS`), its
    rotation and its own mass [kg] and inertia [kg m^2]; without a hub, placeholders the kernels never read."""
    if not hub.size:
        return {"hub_nodes": _nd(ti.i32, np.zeros(1, np.int32)), "hub_offset": _vec(np.zeros((1, 3))),
                "hub": _vec(np.zeros((itg.HUB_ROWS, 3))), "hub_rot": _nd(mat3, np.eye(3)[None]),
                "hub_scalar": _nd(ti.f64, np.zeros(2))}
    state = np.zeros((itg.HUB_ROWS, 3))
    state[itg.HUB_POSITION] = center
    state[itg.HUB_OWN_INERTIA] = np.asarray(hub_inertia, float)
    return {"hub_nodes": _nd(ti.i32, hub.astype(np.int32)), "hub_offset": _vec(mesh.nodes[hub] - center),
            "hub": _vec(state), "hub_rot": _nd(mat3, np.eye(3)[None]),
            "hub_scalar": _nd(ti.f64, np.array([float(hub_mass), 0.0]))}
