"""The wheel's start pose (coupling/placement.py): its lowest point a gap above the highest sphere beneath it."""

import numpy as np

from wheelsoil.coupling.placement import wheel_start_centre


def test_the_lowest_node_starts_a_gap_above_the_highest_sphere_beneath_it():
    angle = np.linspace(0.0, 2 * np.pi, 64, endpoint=False)
    ring = np.column_stack([0.1 * np.cos(angle), np.zeros_like(angle), 0.1 * np.sin(angle)])  # r = 0.1 m wheel
    positions = np.array([[0.5, 0.2, 0.05], [0.52, 0.21, 0.06], [0.9, 0.2, 0.3]])  # the last one far away
    radii = np.array([0.005, 0.004, 0.005])
    centre = wheel_start_centre(ring, positions, radii, start_x=0.5, width=0.4, diameter_max=0.01,
                                surface_height=0.05, gap=0.001)
    assert centre[:2].tolist() == [0.5, 0.2]
    assert abs((ring + centre)[:, 2].min() - (0.06 + 0.004 + 0.001)) < 1e-15
    # no sphere beneath the footprint: the mean surface
    empty = wheel_start_centre(ring, positions[2:], radii[2:], start_x=0.5, width=0.4, diameter_max=0.01,
                               surface_height=0.05, gap=0.001)
    assert abs((ring + empty)[:, 2].min() - 0.051) < 1e-15
