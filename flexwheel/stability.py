"""The structure's stable central-difference step: the largest circular frequency of each element (Irons' bound)
and of the assembled, lumped-mass structure (Lanczos). :class:`.structure.Structure` takes its critical step from
:func:`assembled_critical_frequency`."""

from __future__ import annotations

import math

import numpy as np

from .beam_section import beam_section_stiffness
from .mesh import StructureMesh
from .shell import shell_setup


def critical_frequency(mesh: StructureMesh) -> np.ndarray:
    """Largest circular frequency [rad/s] of every element with its own lumped mass (facets, then beams).

    The largest frequency of the assembled, lumped-mass system never exceeds the largest element one
    (Irons' element eigenvalue theorem; Hughes, *The Finite Element Method*, sec. 9.1), so the
    central-difference limit dt < 2 / omega_max computed from these is safe.
    """
    fm, fi, bm, bi = mesh.element_masses()
    out = []
    if len(mesh.triangles):
        _, _, km, kb = shell_setup(mesh.nodes, mesh.triangles, mesh.thickness, mesh.material, mesh.drilling_penalty)
        inv_m = 1.0 / np.sqrt(np.stack([fm, fm, fi] * 3, axis=1))
        inv_b = 1.0 / np.sqrt(np.stack([fm, fi, fi] * 3, axis=1))
        lam_m = np.linalg.eigvalsh(km * inv_m[:, :, None] * inv_m[:, None, :])[:, -1]
        lam_b = np.linalg.eigvalsh(kb * inv_b[:, :, None] * inv_b[:, None, :])[:, -1]
        out.append(np.sqrt(np.maximum(lam_m, lam_b)))
    if len(mesh.beams):
        rig = beam_section_stiffness(mesh.beam_section, mesh.material)
        length = mesh.beam_lengths()
        lam = np.maximum(2.0 * rig[:, 0] / (length * bm), 2.0 * rig[:, 1] / (length * bi))
        for ei in (rig[:, 2], rig[:, 3]):
            k = np.zeros((len(length), 4, 4))
            L = length
            entries = {(0, 0): 12, (0, 1): 6 * L, (0, 2): -12, (0, 3): 6 * L, (1, 1): 4 * L**2,
                       (1, 2): -6 * L, (1, 3): 2 * L**2, (2, 2): 12, (2, 3): -6 * L, (3, 3): 4 * L**2}
            for (i, j), val in entries.items():
                k[:, i, j] = k[:, j, i] = val * ei / L**3
            s = 1.0 / np.sqrt(np.stack([bm, bi, bm, bi], axis=1))
            lam = np.maximum(lam, np.linalg.eigvalsh(k * s[:, :, None] * s[:, None, :])[:, -1])
        out.append(np.sqrt(lam))
    return np.concatenate(out)


def assembled_critical_frequency(mesh: StructureMesh) -> float:
    """Largest circular frequency [rad/s] of the assembled, lumped-mass structure with every node free.

    omega_max^2 is the largest eigenvalue of M^-1/2 K M^-1/2 (K of :func:`.linear.assemble_stiffness`, M the
    lumped translational masses and rotary inertias), found by Lanczos iteration (``scipy.sparse.linalg.eigsh``;
    a Ritz value approaches it from below, so it is raised by the solver's tolerance). Tying nodes to a hub or
    holding them only removes freedom and cannot raise it (eigenvalue interlacing), so dt < 2 / omega_max is
    the central-difference limit of the structure as stepped. It is below the largest element frequency
    (:func:`critical_frequency`, Irons' bound) -- 28 % on the smoke wheel, where that bound set a step of
    5.3e-5 s against 6.8e-5 s, and three wheel sub-steps per DEM step instead of two. Falls back to the element
    bound if the iteration does not converge.
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from .linear import assemble_stiffness

    bound = float(critical_frequency(mesh).max())
    mass, inertia = mesh.lumped_mass()
    diag = np.c_[mass, mass, mass, inertia, inertia, inertia].reshape(-1)
    if np.any(diag <= 0.0):
        return bound
    scale = sp.diags(1.0 / np.sqrt(diag))
    a = (scale @ assemble_stiffness(mesh) @ scale).tocsr()
    tol = 1e-8
    try:
        # a fixed start vector: ARPACK's default is random, which moved the step by ~1e-11 between runs
        lam = float(spla.eigsh(a, k=1, which="LA", return_eigenvectors=False, tol=tol, maxiter=20 * a.shape[0],
                               v0=np.ones(a.shape[0]))[0])
    except (spla.ArpackNoConvergence, spla.ArpackError):
        return bound
    return min(bound, math.sqrt(lam * (1.0 + 1e3 * tol)))
