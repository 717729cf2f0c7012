"""Triangle meshes of the lab's rigid tools, plain NumPy: a circular plate, a rectangular panel, the open boxes of
a direct shear box. Nodes in metres, triangles counter-clockwise seen from the side their normal points to."""

from __future__ import annotations

import math

import numpy as np

from wheelsoil.errors import WheelsoilInputError


def disc(radius: float, rings: int) -> tuple[np.ndarray, np.ndarray]:
    """A flat disc in the plane z = 0 centred on the origin, normal -z (towards soil below it).

    Ring k (k = 1..rings) has 6 k nodes at radius k/rings * radius; rings k-1 and k are zipped into 6 (2k - 1)
    triangles, so the elements are nearly equilateral of edge radius / rings. Returns (nodes, triangles)."""
    if not (radius > 0 and int(rings) == rings and rings >= 1):
        raise WheelsoilInputError(f"disc radius = {radius!r} m and rings = {rings!r} must be > 0 and a whole number >= 1")
    nodes = [np.zeros((1, 3))]
    ring_ids = [np.array([0])]
    count = 1
    for k in range(1, int(rings) + 1):
        angles = 2.0 * math.pi * np.arange(6 * k) / (6 * k)
        rk = radius * k / rings
        nodes.append(np.c_[rk * np.cos(angles), rk * np.sin(angles), np.zeros(6 * k)])
        ring_ids.append(count + np.arange(6 * k))
        count += 6 * k
    tri = []
    for k in range(1, int(rings) + 1):
        inner, outer = ring_ids[k - 1], ring_ids[k]
        ni, no = len(inner), len(outer)
        i = j = 0
        while i < ni or j < no:
            # advance along whichever ring's next node comes first in angle (the zipper)
            next_outer = (j + 1) / no
            next_inner = (i + 1) / ni if ni > 1 else math.inf
            if j < no and (next_outer <= next_inner + 1e-12 or i >= ni):
                tri.append((inner[i % ni], outer[j % no], outer[(j + 1) % no]))
                j += 1
            else:
                tri.append((inner[i % ni], outer[j % no], inner[(i + 1) % ni]))
                i += 1
            if ni == 1 and j >= no:
                break
    triangles = np.asarray(tri, np.int64)[:, ::-1]  # the zipper runs counter-clockwise seen from +z: flip to -z
    return np.vstack(nodes), triangles


def panel(origin, edge_u, edge_v, n_u: int, n_v: int) -> tuple[np.ndarray, np.ndarray]:
    """A flat rectangle spanned by ``edge_u`` and ``edge_v`` [m] from ``origin`` [m], n_u x n_v cells of two
    triangles; its normal is edge_u x edge_v. Returns (nodes, triangles)."""
    origin, eu, ev = (np.asarray(a, float).reshape(3) for a in (origin, edge_u, edge_v))
    if n_u < 1 or n_v < 1:
        raise WheelsoilInputError(f"panel needs at least one cell each way, got {n_u} x {n_v}")
    u, v = np.meshgrid(np.linspace(0, 1, n_u + 1), np.linspace(0, 1, n_v + 1), indexing="ij")
    nodes = origin + u.reshape(-1, 1) * eu + v.reshape(-1, 1) * ev
    tri = []
    for i in range(n_u):
        for j in range(n_v):
            a, b, c, d = i * (n_v + 1) + j, (i + 1) * (n_v + 1) + j, (i + 1) * (n_v + 1) + j + 1, i * (n_v + 1) + j + 1
            tri += [(a, b, c), (a, c, d)]
    return nodes, np.asarray(tri, np.int64)


def merge(parts: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """One mesh of several (nodes, triangles) parts (nodes are not shared between parts)."""
    nodes, tris, offset = [], [], 0
    for x, t in parts:
        nodes.append(x)
        tris.append(t + offset)
        offset += len(x)
    return np.vstack(nodes), np.vstack(tris)


def square_ring(side: float, z0: float, z1: float, cells: int, flange: float = 0.0,
                flange_at: str = "top") -> tuple[np.ndarray, np.ndarray]:
    """Four vertical walls of a square box [0, side]^2 from height z0 to z1 [m], normals pointing inwards, plus an
    optional horizontal flange of width ``flange`` outside the walls at the ``top`` or ``bottom`` edge (normal up
    for a top flange: spheres that spill over rest on it)."""
    if not (side > 0 and z1 > z0):
        raise WheelsoilInputError(f"square ring side = {side!r} m and heights {z0!r}..{z1!r} m are not a box")
    h = z1 - z0
    nv = max(1, math.ceil(cells * h / side))
    s = side
    up = (0.0, 0.0, h)
    parts = [
        panel((0, 0, z0), up, (s, 0, 0), nv, cells),  # y = 0 wall, normal +y
        panel((s, s, z0), up, (-s, 0, 0), nv, cells),  # y = side, normal -y
        panel((0, s, z0), up, (0, -s, 0), nv, cells),  # x = 0, normal +x
        panel((s, 0, z0), up, (0, s, 0), nv, cells),  # x = side, normal -x
    ]
    if flange > 0:
        z = z1 if flange_at == "top" else z0
        f = flange
        nf = max(1, math.ceil(cells * f / side))
        outer = s + 2 * f
        parts += [
            panel((-f, -f, z), (outer, 0, 0), (0, f, 0), cells, nf),
            panel((-f, s, z), (outer, 0, 0), (0, f, 0), cells, nf),
            panel((-f, 0, z), (f, 0, 0), (0, s, 0), nf, cells),
            panel((s, 0, z), (f, 0, 0), (0, s, 0), nf, cells),
        ]
    return merge(parts)
