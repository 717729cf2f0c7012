"""Where the wheel starts: just above the highest sphere beneath it (NumPy only)."""

from __future__ import annotations

import numpy as np


def wheel_start_centre(nodes: np.ndarray, positions: np.ndarray, radii: np.ndarray, start_x: float, width: float,
                       diameter_max: float, surface_height: float, gap: float) -> np.ndarray:
    """The hub centre [m] that puts a wheel whose nodes sit at ``nodes`` (N, 3) relative to its hub [m] at
    ``start_x`` along the bin, midway across its ``width``, its lowest point ``gap`` above the highest sphere
    (centres ``positions``, ``radii``) beneath its footprint widened by ``diameter_max`` (``surface_height`` where
    none is). Not the mean surface: spheres stand proud of it by up to a radius, and a deep first overlap would kick
    the tread."""
    center = np.array([start_x, 0.5 * width, 0.0])
    lo, hi = (nodes + center)[:, :2].min(axis=0), (nodes + center)[:, :2].max(axis=0)
    below = np.all((positions[:, :2] >= lo - diameter_max) & (positions[:, :2] <= hi + diameter_max), axis=1)
    top = float(np.max(positions[below, 2] + radii[below])) if below.any() else surface_height
    center[2] = top - nodes[:, 2].min() + gap
    return center
