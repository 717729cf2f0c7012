"""Structured meshes of simple shapes: a flat strip, a cylindrical band, a circular beam ring.

Grids of quadrilaterals are split into two triangles each, with the diagonal alternating from cell
to cell so that the mesh has no preferred direction.
"""

from __future__ import annotations

import numpy as np

from wheelsoil.errors import WheelsoilInputError


def grid_triangles(n_u: int, n_v: int, periodic_u: bool = False) -> np.ndarray:
    """Triangles of an (n_u x n_v)-cell grid whose node (i, j) has index i * (n_v + 1) + j.

    With ``periodic_u`` the last column of cells wraps to column 0 (n_u columns of nodes).
    """
    cols = n_u if periodic_u else n_u + 1
    tris = []
    for i in range(n_u):
        i1 = (i + 1) % cols
        for j in range(n_v):
            a, b = i * (n_v + 1) + j, i1 * (n_v + 1) + j
            c, d = i1 * (n_v + 1) + j + 1, i * (n_v + 1) + j + 1
            if (i + j) % 2 == 0:
                tris += [(a, b, c), (a, c, d)]
            else:
                tris += [(a, b, d), (b, c, d)]
    return np.asarray(tris, dtype=np.int64)


def _check_counts(**counts) -> None:
    for name, value in counts.items():
        if int(value) != value or value < 1:
            raise WheelsoilInputError(f"{name}={value!r} must be a positive integer")


def strip(length: float, width: float, n_length: int, n_width: int) -> tuple[np.ndarray, np.ndarray]:
    """Flat strip in the x-y plane, x in [0, length], y in [-width/2, width/2]; (nodes, triangles)."""
    _check_counts(n_length=n_length, n_width=n_width)
    x = np.linspace(0.0, length, n_length + 1)
    y = np.linspace(-width / 2, width / 2, n_width + 1)
    xx, yy = np.meshgrid(x, y, indexing="ij")
    nodes = np.c_[xx.ravel(), yy.ravel(), np.zeros(xx.size)]
    return nodes, grid_triangles(n_length, n_width)


def cylinder_band(radius: float, width: float, n_around: int, n_width: int, angle0: float = 0.0):
    """Cylindrical band about the y axis (x = r cos phi, z = r sin phi), normals pointing outwards.

    Node (i, j) sits at phi_i = angle0 + 2 pi i / n_around and y_j; returns (nodes, triangles).
    """
    _check_counts(n_around=n_around, n_width=n_width)
    phi = angle0 + 2 * np.pi * np.arange(n_around) / n_around
    y = np.linspace(-width / 2, width / 2, n_width + 1)
    pp, yy = np.meshgrid(phi, y, indexing="ij")
    nodes = np.c_[radius * np.cos(pp.ravel()), yy.ravel(), radius * np.sin(pp.ravel())]
    tri = grid_triangles(n_around, n_width, periodic_u=True)
    # grid (phi, y) with (e_phi x e_y) = -e_r: flip to make the normals point outwards
    return nodes, tri[:, ::-1].copy()


def beam_ring(radius: float, n_around: int) -> tuple[np.ndarray, np.ndarray]:
    """Circular ring of beams in the x-z plane; (nodes, beams)."""
    _check_counts(n_around=n_around)
    phi = 2 * np.pi * np.arange(n_around) / n_around
    nodes = np.c_[radius * np.cos(phi), np.zeros(n_around), radius * np.sin(phi)]
    beams = np.c_[np.arange(n_around), (np.arange(n_around) + 1) % n_around]
    return nodes, beams
