"""A beam's cross-section and reference frames: the NumPy set-up of the corotational beam (:mod:`.beam` holds
its Taichi internal forces), kept apart so that a wheel's geometry and mesh can be described without Taichi."""

import numpy as np


def rectangular_section(width: float, height: float) -> tuple[float, float, float, float]:
    """(A, I_y, I_z, J) [m^2, m^4] of a solid rectangle; ``width`` along local y, ``height`` along z.

    I_y = w h^3 / 12 resists bending in the x-z plane. J is Roark's approximation for a rectangle,
    J = a b^3 (1/3 - 0.21 (b/a) (1 - b^4 / (12 a^4))) with a >= b the long and short sides.
    """
    a, b = max(width, height), min(width, height)
    j = a * b**3 * (1.0 / 3.0 - 0.21 * (b / a) * (1.0 - b**4 / (12.0 * a**4)))
    return width * height, width * height**3 / 12.0, height * width**3 / 12.0, j


def beam_frames(nodes: np.ndarray, beams: np.ndarray, orientation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reference frames (n, 3, 3; columns e1, e2, e3) and lengths; e2 is ``orientation`` made normal to e1."""
    d = nodes[beams[:, 1]] - nodes[beams[:, 0]]
    length = np.linalg.norm(d, axis=1)
    e1 = d / length[:, None]
    e2 = orientation - np.sum(orientation * e1, axis=1)[:, None] * e1
    e2 /= np.linalg.norm(e2, axis=1)[:, None]
    e3 = np.cross(e1, e2)
    return np.stack([e1, e2, e3], axis=2), length


def beam_section_stiffness(section: np.ndarray, material) -> np.ndarray:
    """(EA, GJ, EI_y, EI_z) per beam from (A, I_y, I_z, J)."""
    e, g = material.youngs_modulus, material.shear_modulus
    return np.stack([e * section[:, 0], g * section[:, 3], e * section[:, 1], e * section[:, 2]], axis=1)
