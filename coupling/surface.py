"""The wheel's contact surface as the contact interface sees it (plain NumPy, built once).

From the structure's surface facets (tread and grousers of a wheel) this gathers what the contact
kernels need: the facets' node indices and half thicknesses (a facet's contact surface lies half a
thickness either side of its mid-surface), a global id for every edge so that a contact with an edge
two facets share is counted once, and for every surface node the facet corners that touch it (the
static half of the force gather from contacts to nodes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.flexwheel.mesh import StructureMesh


@dataclass(frozen=True)
class ContactSurface:
    """Topology of the contact facets.

    Attributes
    ----------
    triangles: (S, 3) node indices (into the structure's nodes) of the contact facets.
    half_thickness: (S,) half shell thickness of each facet [m].
    edges: (S, 3) global edge id of the facet's edges ab, bc, ca.
    n_edges: number of distinct edges.
    nodes: (U,) the distinct nodes of the contact facets, ascending.
    corner_start, corners: CSR list over ``nodes``: the facet corners ``3 * facet + k`` at that node.
    """

    triangles: np.ndarray
    half_thickness: np.ndarray
    edges: np.ndarray
    n_edges: int
    nodes: np.ndarray
    corner_start: np.ndarray
    corners: np.ndarray

    @classmethod
    def from_mesh(cls, mesh: StructureMesh) -> ContactSurface:
        facets = np.asarray(mesh.surface if mesh.surface is not None else np.arange(len(mesh.triangles)), np.int64)
        if facets.size == 0:
            raise WheelsoilInputError("the structure has no contact-surface facets (mesh.surface is empty)")
        tri = mesh.triangles[facets].astype(np.int64)
        pairs = np.stack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]], axis=1)  # (S, 3, 2)
        pairs = np.sort(pairs, axis=2).reshape(-1, 2)
        _, edge_id = np.unique(pairs, axis=0, return_inverse=True)
        edge_id = edge_id.reshape(-1, 3)
        nodes, local = np.unique(tri.ravel(), return_inverse=True)
        order = np.argsort(local, kind="stable")
        start = np.zeros(len(nodes) + 1, np.int64)
        np.add.at(start, local + 1, 1)
        return cls(
            triangles=tri,
            half_thickness=0.5 * mesh.thickness[facets],
            edges=edge_id.astype(np.int64),
            n_edges=int(edge_id.max()) + 1,
            nodes=nodes,
            corner_start=np.cumsum(start),
            corners=order.astype(np.int64),
        )

    @property
    def n_facets(self) -> int:
        return int(len(self.triangles))

    def closest_distance(self, points: np.ndarray, node_positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Distance from every point to the nearest facet mid-surface [m] and that facet's index.

        Brute force over every facet (for checks and tests; the solver uses a grid on the device).
        """
        import taichi as ti

        from wheelsoil.taichi_types import to_ndarray, vec3

        from .closest_point import closest_points  # Taichi kernel

        p = np.asarray(points, float).reshape(-1, 3)
        corners = node_positions[self.triangles]  # (S, 3, 3)
        best = np.full(len(p), np.inf)
        which = np.full(len(p), -1, np.int64)
        chunk = max(1, 2_000_000 // max(1, self.n_facets))
        for s in range(0, len(p), chunk):
            q = p[s : s + chunk]
            rows = len(q) * self.n_facets
            tri = [to_ndarray(vec3, np.tile(corners[:, k], (len(q), 1))) for k in range(3)]
            bary = ti.ndarray(vec3, shape=rows)
            feat = ti.ndarray(ti.i32, shape=rows)
            closest_points(to_ndarray(vec3, np.repeat(q, self.n_facets, axis=0)), *tri, bary, feat)
            w = bary.to_numpy().reshape(len(q), self.n_facets, 3)
            cpt = np.einsum("psk,skd->psd", w, corners)
            dist = np.linalg.norm(cpt - q[:, None, :], axis=2)
            k = np.argmin(dist, axis=1)
            best[s : s + chunk] = dist[np.arange(len(q)), k]
            which[s : s + chunk] = k
        return best, which
