"""Corotational flat triangular shell: element set-up (NumPy) and internal forces (Taichi).

Element-independent corotational (EICR) formulation of Rankin & Nour-Omid (1988) in the notation of
Felippa & Haugen (2005), CMAME 194, 2285-2335:

1. the current element frame T = [e1, e2, n] has e1 along side 0->1 and n normal to the facet;
   the reference frame T0 is the same construction on the undeformed mesh;
2. deformational translations are the nodes' local coordinates about the centroid minus the
   reference ones, u_d = T^T (x_a - x_c) - p0_a; the normal one vanishes for a flat facet;
3. deformational rotations are theta_a = log(T^T R_a T0) (R_a the node's rotation from the
   reference configuration);
4. the small-strain element of ``shell_stiffness`` gives local resisting forces f = K d;
5. moments are mapped to spin variations by H(theta_a)^T (Felippa & Haugen eq. 4.4), and the
   projector P = I - Psi G (their eq. 5.8) removes the rigid-rotation content, so the nodal forces
   are self-equilibrated in the current configuration (linear and angular momentum are conserved).
   G is the "spin-lever" of this frame: omega_x = dw/dy, omega_y = -dw/dx (tilt of the facet) and
   omega_z = (v_1 - v_0) / l_01 (rotation of side 0->1).
6. forces go to the global frame with T and are written per element corner into a slot array that
   the node update gathers (no float atomics).

The two 9x9 blocks are stored packed (:func:`pack_stiffness`): both are symmetric (K = int B^T D B), and the
bending block only ever multiplies the facet's bending deformation, whose normal translations (entries 0, 3 and
6) vanish because the nodes lie in the facet's own plane (step 2). Membrane: the 45 entries of the upper
triangle; bending: the 21 of the upper triangle over the six rotation entries and the 18 that turn them into
normal forces -- 84 numbers a facet instead of 162, which the element loop reads every sub-step.
"""


import numpy as np
import taichi as ti

from wheelsoil.taichi_types import mat3, nd_f64, nd_f64_2d, nd_ivec3, nd_mat3, nd_mat32, nd_vec3, vec3, vec9

from .rotation import log_so3, spin_jacobian_inverse
from .shell_stiffness import bending_stiffness, membrane_stiffness


def facet_frames(x: np.ndarray, tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Element frames T (n, 3, 3; columns e1, e2, n) and local node coordinates (n, 3, 2)."""
    p = x[tri]
    a = p[:, 1] - p[:, 0]
    e1 = a / np.linalg.norm(a, axis=1)[:, None]
    nrm = np.cross(a, p[:, 2] - p[:, 0])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    e2 = np.cross(nrm, e1)
    frames = np.stack([e1, e2, nrm], axis=2)
    centroid = p.mean(axis=1, keepdims=True)
    local = np.einsum("nji,naj->nai", frames, p - centroid)[..., :2]
    return frames, local


def _upper(n: int) -> list[tuple[int, int]]:
    return [(i, j) for i in range(n) for j in range(i, n)]


#: (row, column) of each packed membrane entry: the upper triangle of the 9x9 block
MEMBRANE_PACK = _upper(9)
#: the bending deformation's non-zero entries (rotations about the facet's two in-plane axes at each corner)
BENDING_ROTATIONS = (1, 2, 4, 5, 7, 8)
#: (row, column) of each packed bending entry: the upper triangle over the rotations, then the normal-force rows
BENDING_PACK = ([(BENDING_ROTATIONS[i], BENDING_ROTATIONS[j]) for i, j in _upper(6)]
                + [(r, c) for r in (0, 3, 6) for c in BENDING_ROTATIONS])


def pack_stiffness(km: np.ndarray, kb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, 9, 9) membrane and bending blocks -> (n, 45) and (n, 39) (see the module docstring). Checks the
    symmetry the packing relies on."""
    for name, k in (("membrane", km), ("bending", kb)):
        scale = max(float(np.abs(k).max()), 1e-300)
        if not np.allclose(k, np.swapaxes(k, 1, 2), rtol=0.0, atol=1e-10 * scale):
            raise ValueError(f"{name} stiffness blocks are not symmetric")
    rm, cm = np.array(MEMBRANE_PACK).T
    rb, cb = np.array(BENDING_PACK).T
    return np.ascontiguousarray(km[:, rm, cm]), np.ascontiguousarray(kb[:, rb, cb])


def shell_setup(nodes, triangles, thickness, material, drilling_penalty):
    """Reference frames, local coordinates and the two 9x9 stiffness blocks of every facet."""
    frames, local = facet_frames(nodes, triangles)
    e, nu = material.youngs_modulus, material.poisson_ratio
    km = membrane_stiffness(local, thickness, e, nu, drilling_penalty)
    kb = bending_stiffness(local, thickness, e, nu)
    return frames, local, km, kb


@ti.func
def _membrane_times(k: ti.template(), e: ti.i32, d: vec9) -> vec9:
    """K_m d of facet e from its packed upper triangle ``k[e, :]`` (45 entries, :data:`MEMBRANE_PACK`)."""
    f = vec9(0.0)
    for i in ti.static(range(9)):
        for j in ti.static(range(i, 9)):
            p = ti.static(MEMBRANE_PACK.index((i, j)))
            f[i] += k[e, p] * d[j]
            if ti.static(i != j):
                f[j] += k[e, p] * d[i]
    return f


@ti.func
def _bending_times(k: ti.template(), e: ti.i32, d: vec9) -> vec9:
    """K_b d of facet e from its packed bending entries ``k[e, :]`` (39, :data:`BENDING_PACK`), for d with
    d[0] = d[3] = d[6] = 0."""
    f = vec9(0.0)
    for a in ti.static(range(6)):
        for b in ti.static(range(a, 6)):
            i, j = ti.static(BENDING_ROTATIONS[a], BENDING_ROTATIONS[b])
            p = ti.static(BENDING_PACK.index((i, j)))
            f[i] += k[e, p] * d[j]
            if ti.static(i != j):
                f[j] += k[e, p] * d[i]
    for r in ti.static((0, 3, 6)):
        for c in ti.static(BENDING_ROTATIONS):
            p = ti.static(BENDING_PACK.index((r, c)))
            f[r] += k[e, p] * d[c]
    return f


@ti.func
def facet_frame(x0: vec3, x1: vec3, x2: vec3) -> mat3:
    e1 = (x1 - x0).normalized()
    nrm = (x1 - x0).cross(x2 - x0).normalized()
    return ti.Matrix.cols([e1, nrm.cross(e1), nrm])


@ti.func
def shell_element(
    e: ti.i32, x: ti.template(), rot: ti.template(), tri: ti.template(), frame0: ti.template(),
    local0: ti.template(), km: ti.template(), kb: ti.template(), slot_f: ti.template(),
    slot_m: ti.template(), slot_base: ti.i32, write: ti.i32,
) -> ti.f64:
    """Internal forces of facet e into its three slots (if ``write``); returns its strain energy [J]."""
    n0, n1, n2 = tri[e][0], tri[e][1], tri[e][2]
    xs = [x[n0], x[n1], x[n2]]
    rs = [rot[n0], rot[n1], rot[n2]]
    t = facet_frame(xs[0], xs[1], xs[2])
    tt = t.transpose()
    xc = (xs[0] + xs[1] + xs[2]) / 3.0
    dm = vec9(0.0)
    db = vec9(0.0)
    p = [vec3(0.0), vec3(0.0), vec3(0.0)]
    th = [vec3(0.0), vec3(0.0), vec3(0.0)]
    for a in ti.static(range(3)):
        p[a] = tt @ (xs[a] - xc)
        th[a] = log_so3(tt @ rs[a] @ frame0[e])
        dm[3 * a] = p[a][0] - local0[e][a, 0]
        dm[3 * a + 1] = p[a][1] - local0[e][a, 1]
        dm[3 * a + 2] = th[a][2]
        db[3 * a + 1] = th[a][0]
        db[3 * a + 2] = th[a][1]
    fm = _membrane_times(km, e, dm)
    fb = _bending_times(kb, e, db)
    energy = 0.5 * (dm.dot(fm) + db.dot(fb))
    if write:
        f = [vec3(0.0), vec3(0.0), vec3(0.0)]
        m = [vec3(0.0), vec3(0.0), vec3(0.0)]
        mtot = vec3(0.0)
        for a in ti.static(range(3)):
            f[a] = vec3(fm[3 * a], fm[3 * a + 1], fb[3 * a])
            m[a] = spin_jacobian_inverse(th[a]).transpose() @ vec3(fb[3 * a + 1], fb[3 * a + 2], fm[3 * a + 2])
            mtot += p[a].cross(f[a]) + m[a]
        # projector: f <- f - G^T (Psi^T f), G from the current local coordinates
        bx = [p[1][1] - p[2][1], p[2][1] - p[0][1], p[0][1] - p[1][1]]
        cy = [p[2][0] - p[1][0], p[0][0] - p[2][0], p[1][0] - p[0][0]]
        two_area = bx[0] * cy[1] - bx[1] * cy[0]
        l01 = p[1][0] - p[0][0]
        dz = [-1.0, 1.0, 0.0]
        for a in ti.static(range(3)):
            corr = vec3(0.0, dz[a] / l01 * mtot[2], (cy[a] * mtot[0] - bx[a] * mtot[1]) / two_area)
            slot_f[slot_base + 3 * e + a] = -(t @ (f[a] - corr))
            slot_m[slot_base + 3 * e + a] = -(t @ m[a])
    return energy


@ti.kernel
def shell_forces(
    x: nd_vec3, rot: nd_mat3, tri: nd_ivec3, frame0: nd_mat3, local0: nd_mat32, km: nd_f64_2d,
    kb: nd_f64_2d, slot_f: nd_vec3, slot_m: nd_vec3, slot_base: ti.i32,
):
    """Internal nodal forces and moments of every facet (one slot per facet corner)."""
    for e in tri:
        shell_element(e, x, rot, tri, frame0, local0, km, kb, slot_f, slot_m, slot_base, 1)


@ti.kernel
def shell_energies(
    x: nd_vec3, rot: nd_mat3, tri: nd_ivec3, frame0: nd_mat3, local0: nd_mat32, km: nd_f64_2d,
    kb: nd_f64_2d, slot_f: nd_vec3, slot_m: nd_vec3, energy: nd_f64,
):
    """Strain energy of every facet [J]."""
    for e in tri:
        energy[e] = shell_element(e, x, rot, tri, frame0, local0, km, kb, slot_f, slot_m, 0, 0)
