"""Assembled linear stiffness of a structure in its reference configuration (SciPy sparse).

The same small-strain element matrices the corotational kernels use, rotated to the global frame and
assembled over 6 dofs per node ``[u_x, u_y, u_z, theta_x, theta_y, theta_z]``. It is the tangent of
the corotational internal forces at the undeformed state (``tests/test_flexwheel_elements.py``
checks this against finite differences of the Taichi forces), and it gives small-load stiffnesses
(e.g. the wheel's radial point-load stiffness) with one sparse solve.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .beam_section import beam_frames, beam_section_stiffness
from .mesh import StructureMesh
from .shell import shell_setup

# positions of the local membrane [u, v, theta_z] and bending [w, theta_x, theta_y] dofs in a node's 6
_MEMBRANE = (0, 1, 5)
_BENDING = (2, 3, 4)


def _rotate_blocks(k_local: np.ndarray, frames: np.ndarray, n_nodes_per_element: int) -> np.ndarray:
    """K_global = T K_local T^T with T block-diagonal of the element frame (one 3x3 per vector)."""
    n_blocks = 2 * n_nodes_per_element
    t = np.zeros((len(frames), 3 * n_blocks, 3 * n_blocks))
    for b in range(n_blocks):
        t[:, 3 * b: 3 * b + 3, 3 * b: 3 * b + 3] = frames
    return np.einsum("nij,njk,nlk->nil", t, k_local, t)


def facet_stiffness_global(mesh: StructureMesh) -> np.ndarray:
    """(T, 18, 18) facet stiffness in global axes, dofs ordered node by node."""
    frames, _, km, kb = shell_setup(mesh.nodes, mesh.triangles, mesh.thickness, mesh.material, mesh.drilling_penalty)
    k = np.zeros((len(frames), 18, 18))
    for a in range(3):
        for b in range(3):
            for i, di in enumerate(_MEMBRANE):
                for j, dj in enumerate(_MEMBRANE):
                    k[:, 6 * a + di, 6 * b + dj] += km[:, 3 * a + i, 3 * b + j]
            for i, di in enumerate(_BENDING):
                for j, dj in enumerate(_BENDING):
                    k[:, 6 * a + di, 6 * b + dj] += kb[:, 3 * a + i, 3 * b + j]
    return _rotate_blocks(k, frames, 3)


def beam_stiffness_global(mesh: StructureMesh) -> np.ndarray:
    """(B, 12, 12) Euler-Bernoulli beam stiffness in global axes (Przemieniecki, sec. 5.6)."""
    frames, length = beam_frames(mesh.nodes, mesh.beams, mesh.beam_orientation)
    ea, gj, eiy, eiz = beam_section_stiffness(mesh.beam_section, mesh.material).T
    L = length
    k = np.zeros((len(L), 12, 12))

    def put(i, j, val):
        k[:, i, j] += val
        if i != j:
            k[:, j, i] += val

    put(0, 0, ea / L); put(6, 6, ea / L); put(0, 6, -ea / L)
    put(3, 3, gj / L); put(9, 9, gj / L); put(3, 9, -gj / L)
    # bending in x-y (v, theta_z): EI_z
    for (v1, r1, v2, r2, ei, s) in ((1, 5, 7, 11, eiz, 1.0), (2, 4, 8, 10, eiy, -1.0)):
        put(v1, v1, 12 * ei / L**3); put(v2, v2, 12 * ei / L**3); put(v1, v2, -12 * ei / L**3)
        put(r1, r1, 4 * ei / L); put(r2, r2, 4 * ei / L); put(r1, r2, 2 * ei / L)
        put(v1, r1, s * 6 * ei / L**2); put(v1, r2, s * 6 * ei / L**2)
        put(v2, r1, -s * 6 * ei / L**2); put(v2, r2, -s * 6 * ei / L**2)
    return _rotate_blocks(k, frames, 2)


def assemble_stiffness(mesh: StructureMesh) -> sp.csr_matrix:
    """Global linear stiffness (6N x 6N, CSR)."""
    rows, cols, vals = [], [], []
    for conn, ke in ((mesh.triangles, facet_stiffness_global(mesh) if len(mesh.triangles) else None),
                     (mesh.beams, beam_stiffness_global(mesh) if len(mesh.beams) else None)):
        if ke is None:
            continue
        dofs = (6 * conn[:, :, None] + np.arange(6)).reshape(len(conn), -1)
        rows.append(np.repeat(dofs, dofs.shape[1], axis=1).ravel())
        cols.append(np.tile(dofs, (1, dofs.shape[1])).ravel())
        vals.append(ke.ravel())
    n = 6 * mesh.n_nodes
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
