"""The wheel's contact surface on the device (:class:`SurfaceArrays`): the facets, their edges and nodes from
:class:`~.surface.ContactSurface`, the nodes' inverse masses, and the scratch arrays the facet binning fills at each
rebuild of the contact candidates (:class:`~.contact.WheelContact`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import taichi as ti

from wheelsoil.flexwheel.structure import Structure
from wheelsoil.taichi_types import ivec3, vec4
from wheelsoil.taichi_types import to_ndarray as _nd

from .surface import ContactSurface


@dataclass
class SurfaceArrays:
    """Device arrays of a wheel's contact surface.

    triangles (F, 3), edges, nodes, corner_start, corners: the surface's index arrays (i32); half_thickness (F,) [m];
    inverse_mass (N,) [1/kg]: of every structure node, 0 for the hub's and massless nodes (they take no contact
    force of their own); node_reference: vec3 per surface node, the positions at the last rebuild [m]; facet_lo,
    facet_hi: ivec3 per facet, the grid cells its grown box spans; facet_start (F + 1), facet_fill (F): the
    candidates' index by facet."""

    triangles: ti.Ndarray
    edges: ti.Ndarray
    half_thickness: ti.Ndarray
    nodes: ti.Ndarray
    corner_start: ti.Ndarray
    corners: ti.Ndarray
    inverse_mass: ti.Ndarray
    node_reference: ti.Ndarray
    facet_lo: ti.Ndarray
    facet_hi: ti.Ndarray
    facet_start: ti.Ndarray
    facet_fill: ti.Ndarray
    facet_plane: ti.Ndarray
    facet_ball: ti.Ndarray

    @classmethod
    def upload(cls, surface: ContactSurface, structure: Structure) -> "SurfaceArrays":
        free = np.ones(structure.mesh.n_nodes, bool)
        free[structure.hub_nodes] = False
        inverse_mass = np.where(free & (structure.mass > 0), 1.0 / np.maximum(structure.mass, 1e-300), 0.0)
        n_facets = surface.n_facets
        return cls(
            triangles=_nd(ti.i32, surface.triangles.astype(np.int32)),
            edges=_nd(ti.i32, surface.edges.astype(np.int32)),
            half_thickness=_nd(ti.f64, surface.half_thickness),
            nodes=_nd(ti.i32, surface.nodes.astype(np.int32)),
            corner_start=_nd(ti.i32, surface.corner_start.astype(np.int32)),
            corners=_nd(ti.i32, surface.corners.astype(np.int32)),
            inverse_mass=_nd(ti.f64, inverse_mass),
            node_reference=ti.Vector.ndarray(3, ti.f64, shape=len(surface.nodes)),
            facet_lo=ti.ndarray(ivec3, shape=n_facets),
            facet_hi=ti.ndarray(ivec3, shape=n_facets),
            facet_start=ti.ndarray(ti.i32, shape=n_facets + 1),
            facet_fill=ti.ndarray(ti.i32, shape=n_facets),
            facet_plane=ti.ndarray(vec4, shape=n_facets),
            facet_ball=ti.ndarray(vec4, shape=n_facets),
        )
