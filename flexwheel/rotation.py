"""Finite rotations for the corotational elements (Taichi functions).

Node orientations are 3x3 rotation matrices updated by the exponential map; deformational rotations
are small rotation vectors extracted by the logarithm. ``spin_jacobian_inverse`` is the matrix H of
Felippa & Haugen (2005), CMAME 194, eq. (4.3)/(4.4): for R = exp(spin(theta)) and a left spin
variation dR = spin(d omega) R, d theta = H(theta) d omega with
    H = I - 1/2 Theta + eta Theta^2,   eta = (1 - (g/2) cot(g/2)) / g^2,   g = |theta|.
"""

import taichi as ti

from wheelsoil.taichi_types import mat3, vec3


@ti.func
def spin(a: vec3) -> mat3:
    """Skew matrix with spin(a) b = a x b."""
    return mat3([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


@ti.func
def exp_so3(theta: vec3) -> mat3:
    """Rodrigues: exp(spin(theta)), with series for small angles."""
    g2 = theta.dot(theta)
    s = spin(theta)
    a = 1.0
    b = 0.5
    if g2 < 1e-8:
        a = 1.0 - g2 / 6.0
        b = 0.5 - g2 / 24.0
    else:
        g = ti.sqrt(g2)
        a = ti.sin(g) / g
        b = (1.0 - ti.cos(g)) / g2
    return ti.Matrix.identity(ti.f64, 3) + a * s + b * (s @ s)


@ti.func
def log_so3(r: mat3) -> vec3:
    """Rotation vector theta with exp(spin(theta)) = r, for |theta| < pi.

    theta = (g / sin g) w with w = sin(g) axis from the skew part of r and g = atan2(|w|, (tr r - 1) / 2).
    The deformational rotations of the corotational elements are small, so below |w| = 0.01 (and with
    cos g > 0) the factor g / sin g = arcsin(s) / s comes from its series 1 + s^2/6 + 3 s^4/40 + 5 s^6/112
    (truncation below 1e-16 there) instead of the two square roots and the arc tangent.
    """
    w = 0.5 * vec3(r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1])  # sin(g) * axis
    s2 = w.norm_sqr()
    c = 0.5 * (r[0, 0] + r[1, 1] + r[2, 2] - 1.0)
    factor = 1.0 + s2 * (1.0 / 6.0 + s2 * (3.0 / 40.0 + s2 * (5.0 / 112.0)))
    if s2 >= 1e-4 or c <= 0.0:
        s = ti.sqrt(s2)
        g = ti.atan2(s, c)
        factor = g / s
    return factor * w


@ti.func
def spin_jacobian_inverse(theta: vec3) -> mat3:
    """H(theta) = d theta / d omega (see module docstring)."""
    g2 = theta.dot(theta)
    # series of (1 - (g/2) cot(g/2)) / g^2 = 1/12 + g^2/720 + g^4/30240 + g^6/1209600 (below 1e-17 for g^2 < 1e-4)
    eta = 1.0 / 12.0 + g2 * (1.0 / 720.0 + g2 * (1.0 / 30240.0 + g2 / 1209600.0))
    if g2 >= 1e-4:
        g = ti.sqrt(g2)
        eta = (1.0 - 0.5 * g / ti.tan(0.5 * g)) / g2
    s = spin(theta)
    return ti.Matrix.identity(ti.f64, 3) - 0.5 * s + eta * (s @ s)
