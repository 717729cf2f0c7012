"""Small-strain stiffness of the flat triangular shell element in its own local frame.

The element is the classic flat facet: a constant-strain membrane (CST) with a drilling-rotation
penalty, plus the Discrete Kirchhoff Triangle (DKT) for bending. Both are linear in the element's
local frame; the corotational kernel (``shell.py``) removes the rigid motion and feeds them the
deformational displacements and rotations. Everything here is vectorised NumPy over elements and
runs once when a mesh is set up.

Local degrees of freedom, per node a = 0, 1, 2:
  membrane ``[u_a, v_a, theta_z,a]``  (in-plane translations, drilling rotation),
  bending  ``[w_a, theta_x,a, theta_y,a]`` (normal translation, rotations about local x and y).

References
----------
* CST: Zienkiewicz & Taylor, *The Finite Element Method* vol. 1, sec. 6.2 (B = [b_a, c_a] / 2A).
* Drilling penalty: Hughes & Brezzi (1989), energy 1/2 k_d sum_a (theta_z,a - omega_z)^2 with
  omega_z = 1/2 (dv/dx - du/dy) the continuum in-plane rotation; k_d = alpha_d G t A / 3.
* DKT: Batoz, Bathe & Ho (1980), Int. J. Numer. Meth. Eng. 15, 1771-1812. The rotations of the
  normal beta_x, beta_y are quadratic (6-node) and tied to the 9 corner dofs by the Kirchhoff
  conditions: at the corners beta_x = theta_y, beta_y = -theta_x (so that beta = -grad w); at each
  mid-side k of edge i->j (length l, unit tangent s, in-plane normal n)
      beta_s,k = -3/(2 l) (w_j - w_i) - 1/4 (beta_s,i + beta_s,j)     (Kirchhoff along the edge, w cubic)
      beta_n,k =  1/2 (beta_n,i + beta_n,j)                           (beta_n linear along the edge)
  Curvatures kappa = [d beta_x/dx, d beta_y/dy, d beta_x/dy + d beta_y/dx], moments M = D_b kappa with
  D_b = E t^3 / (12 (1 - nu^2)) [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu)/2]], integrated exactly by
  the 3-point rule at the mid-sides.
"""

from __future__ import annotations

import numpy as np

#: Default drilling penalty factor alpha_d (dimensionless); small enough not to stiffen the membrane.
DRILLING_PENALTY = 1.0e-2


def triangle_geometry(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Area and shape-function gradients of linear triangles.

    ``xy`` has shape (n, 3, 2) (local coordinates of the three nodes). Returns ``area`` (n,),
    ``b`` and ``c`` (n, 3) with dL_a/dx = b_a / (2A), dL_a/dy = c_a / (2A),
    b_a = y_b - y_c, c_a = x_c - x_b for (a, b, c) cyclic.
    """
    x, y = xy[..., 0], xy[..., 1]
    b = np.stack([y[:, 1] - y[:, 2], y[:, 2] - y[:, 0], y[:, 0] - y[:, 1]], axis=1)
    c = np.stack([x[:, 2] - x[:, 1], x[:, 0] - x[:, 2], x[:, 1] - x[:, 0]], axis=1)
    area = 0.5 * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])
    return area, b, c


def plane_stress_matrix(e: np.ndarray, nu: np.ndarray) -> np.ndarray:
    """[[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]] * E / (1 - nu^2), shape (n, 3, 3)."""
    e = np.asarray(e, float)
    nu = np.asarray(nu, float)
    d = np.zeros(e.shape + (3, 3))
    f = e / (1.0 - nu**2)
    d[..., 0, 0] = d[..., 1, 1] = f
    d[..., 0, 1] = d[..., 1, 0] = f * nu
    d[..., 2, 2] = f * (1.0 - nu) / 2.0
    return d


def membrane_stiffness(xy, thickness, e, nu, drilling_penalty=DRILLING_PENALTY) -> np.ndarray:
    """CST membrane + drilling penalty, (n, 9, 9) over ``[u_a, v_a, theta_z,a]``."""
    n = xy.shape[0]
    thickness, e, nu = (np.broadcast_to(np.asarray(v, float), (n,)) for v in (thickness, e, nu))
    area, b, c = triangle_geometry(xy)
    bm = np.zeros((n, 3, 9))
    for a in range(3):
        bm[:, 0, 3 * a] = b[:, a]
        bm[:, 1, 3 * a + 1] = c[:, a]
        bm[:, 2, 3 * a] = c[:, a]
        bm[:, 2, 3 * a + 1] = b[:, a]
    bm /= (2.0 * area)[:, None, None]
    dm = plane_stress_matrix(e, nu) * np.asarray(thickness, float)[..., None, None]
    k = np.einsum("nij,njk,nkl->nil", bm.transpose(0, 2, 1), dm, bm) * area[:, None, None]
    # Drilling: omega_z = 1/2 (dv/dx - du/dy) = sum_a (b_a v_a - c_a u_a) / (4A)
    g = np.zeros((n, 9))
    for a in range(3):
        g[:, 3 * a] = -c[:, a] / (4.0 * area)
        g[:, 3 * a + 1] = b[:, a] / (4.0 * area)
    shear = np.asarray(e, float) / (2.0 * (1.0 + np.asarray(nu, float)))
    kd = drilling_penalty * shear * np.asarray(thickness, float) * area / 3.0
    for a in range(3):
        r = -g.copy()
        r[:, 3 * a + 2] += 1.0
        k += kd[:, None, None] * np.einsum("ni,nj->nij", r, r)
    return k


def _dkt_rotation_maps(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Matrices (n, 6, 9) giving beta_x and beta_y at the 6 quadratic nodes from the 9 bending dofs."""
    n = xy.shape[0]
    ax = np.zeros((n, 6, 9))
    ay = np.zeros((n, 6, 9))
    for a in range(3):
        ax[:, a, 3 * a + 2] = 1.0  # beta_x = theta_y
        ay[:, a, 3 * a + 1] = -1.0  # beta_y = -theta_x
    # mid-side nodes 3, 4, 5 on edges (1,2), (2,0), (0,1)  (quadratic node k sits opposite corner k-3)
    for k, (i, j) in zip((3, 4, 5), ((1, 2), (2, 0), (0, 1))):
        d = xy[:, j] - xy[:, i]
        length = np.hypot(d[:, 0], d[:, 1])
        s = d / length[:, None]
        nrm = np.stack([s[:, 1], -s[:, 0]], axis=1)
        # corner beta_s and beta_n as rows over the 9 dofs
        bs_i = s[:, 0, None] * ax[:, i] + s[:, 1, None] * ay[:, i]
        bs_j = s[:, 0, None] * ax[:, j] + s[:, 1, None] * ay[:, j]
        bn_i = nrm[:, 0, None] * ax[:, i] + nrm[:, 1, None] * ay[:, i]
        bn_j = nrm[:, 0, None] * ax[:, j] + nrm[:, 1, None] * ay[:, j]
        bs_k = -0.25 * (bs_i + bs_j)
        bs_k[:, 3 * j] += -1.5 / length
        bs_k[:, 3 * i] += 1.5 / length
        bn_k = 0.5 * (bn_i + bn_j)
        ax[:, k] = s[:, 0, None] * bs_k + nrm[:, 0, None] * bn_k
        ay[:, k] = s[:, 1, None] * bs_k + nrm[:, 1, None] * bn_k
    return ax, ay


def _quadratic_gradients(area_coords: np.ndarray, b: np.ndarray, c: np.ndarray, area: np.ndarray):
    """x- and y-derivatives (n, 6) of the 6-node quadratic shape functions at one point."""
    l0, l1, l2 = area_coords
    lam = (l0, l1, l2)
    dn_dl = np.zeros((6, 3))
    for a in range(3):
        dn_dl[a, a] = 4.0 * lam[a] - 1.0
    for k, (i, j) in zip((3, 4, 5), ((1, 2), (2, 0), (0, 1))):
        dn_dl[k, i] = 4.0 * lam[j]
        dn_dl[k, j] = 4.0 * lam[i]
    dx = dn_dl @ (b / (2.0 * area[:, None])).T  # (6, n)
    dy = dn_dl @ (c / (2.0 * area[:, None])).T
    return dx.T, dy.T


def bending_curvature_operators(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """DKT curvature operators B (n, 3 gauss points, 3, 9) and the Gauss weights * area (n, 3)."""
    area, b, c = triangle_geometry(xy)
    ax, ay = _dkt_rotation_maps(xy)
    points = ((0.0, 0.5, 0.5), (0.5, 0.0, 0.5), (0.5, 0.5, 0.0))
    bmat = np.zeros((xy.shape[0], 3, 3, 9))
    for g, lc in enumerate(points):
        dx, dy = _quadratic_gradients(np.array(lc), b, c, area)
        bmat[:, g, 0] = np.einsum("nk,nkq->nq", dx, ax)
        bmat[:, g, 1] = np.einsum("nk,nkq->nq", dy, ay)
        bmat[:, g, 2] = np.einsum("nk,nkq->nq", dy, ax) + np.einsum("nk,nkq->nq", dx, ay)
    weights = np.repeat(area[:, None] / 3.0, 3, axis=1)
    return bmat, weights


def bending_stiffness(xy, thickness, e, nu) -> np.ndarray:
    """DKT bending stiffness, (n, 9, 9) over ``[w_a, theta_x,a, theta_y,a]``."""
    n = xy.shape[0]
    t, e, nu = (np.broadcast_to(np.asarray(v, float), (n,)) for v in (thickness, e, nu))
    db = plane_stress_matrix(e, nu) * (t**3 / 12.0)[..., None, None]
    bmat, w = bending_curvature_operators(xy)
    return np.einsum("ng,ngki,nkl,nglj->nij", w, bmat, db, bmat)
