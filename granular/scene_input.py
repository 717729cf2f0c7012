"""Checks on what a user hands a :class:`~.scene.Scene` (plain NumPy, no Taichi): arrays of the right shape and
finite, spheres with positive radii, planes with a direction, options in range. Each check names the argument, the
value and what is allowed, before the scene changes.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import WheelsoilInputError
from .materials import Material, PairProperties


def as_array(name: str, value, shape_tail: tuple[int, ...], n: int | None = None) -> np.ndarray:
    """``value`` as a contiguous float64 array of shape (n, *shape_tail) (one item may be given without its leading
    axis); a wrong shape or a non-finite entry is refused with the argument's name."""
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == len(shape_tail):  # a single item
        arr = arr[None, ...]
    if arr.shape[1:] != shape_tail or (n is not None and arr.shape[0] != n):
        want = ("N" if n is None else str(n),) + tuple(str(s) for s in shape_tail)
        raise WheelsoilInputError(f"{name} has shape {arr.shape}; expected ({', '.join(want)})")
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = np.argwhere(bad)[0]
        raise WheelsoilInputError(
            f"{name} contains a non-finite value {float(arr[tuple(idx)])!r} at index {tuple(int(i) for i in idx)}"
        )
    return np.ascontiguousarray(arr)


def as_vector(name: str, value) -> np.ndarray:
    """One finite 3-vector."""
    return as_array(name, value, (3,), 1)[0]


def checked_spheres(positions, radii, velocities=None, angular_velocities=None):
    """Positions (N, 3) [m], radii (N,) or one radius [m] (> 0), velocities (N, 3) [m/s] and angular velocities
    (N, 3) [rad/s] (default zero), checked and returned as arrays ``(x, r, v, w)``."""
    x = as_array("positions", positions, (3,))
    n = x.shape[0]
    if np.ndim(radii) == 0 and not math.isfinite(float(radii)):
        raise WheelsoilInputError(f"radii = {radii!r} must be finite")
    r = as_array("radii", radii, (), n) if np.ndim(radii) else np.full(n, float(radii))
    bad = np.flatnonzero(r <= 0.0)
    if bad.size:
        raise WheelsoilInputError(
            f"radius {float(r[bad[0]])!r} m of sphere {int(bad[0])} is invalid: radii must be > 0")
    v = np.zeros((n, 3)) if velocities is None else as_array("velocities", velocities, (3,), n)
    w = np.zeros((n, 3)) if angular_velocities is None else as_array("angular_velocities", angular_velocities, (3,), n)
    return x, r, v, w


def checked_wall_rows(name: str, rows, n: int, n_walls: int) -> np.ndarray | None:
    """Per-sphere wall-contact rows (N, walls, 3) for ``n`` spheres and ``n_walls`` walls, or None."""
    if rows is None:
        return None
    rows = np.asarray(rows, float)
    if rows.shape != (n, n_walls, 3):
        raise WheelsoilInputError(f"{name} has shape {rows.shape}; expected ({n}, {n_walls}, 3)")
    return rows


def checked_mask(mask, n: int) -> np.ndarray:
    """A boolean mask over the scene's ``n`` spheres."""
    mask = np.asarray(mask, dtype=bool)
    if mask.shape != (n,):
        raise WheelsoilInputError(f"mask has shape {mask.shape}; expected ({n},)")
    return mask


def checked_plane(point, normal, material, pair, walls_so_far: int, max_walls: int):
    """A wall's point [m] and unit normal, after checking its direction, its material and pair and that the scene
    has room for it (at most ``max_walls``)."""
    p, nrm = as_vector("wall point", point), as_vector("wall normal", normal)
    length = float(np.linalg.norm(nrm))
    if length == 0.0:
        raise WheelsoilInputError("wall normal (0, 0, 0) has no direction")
    if walls_so_far >= max_walls:
        raise WheelsoilInputError(
            f"a scene holds at most {max_walls} planar walls (each particle tracks its wall contacts in a bit mask)"
        )
    if material is not None and not isinstance(material, Material):
        raise WheelsoilInputError(f"wall material must be a Material or None, got {type(material).__name__}")
    if not isinstance(pair, PairProperties):
        raise WheelsoilInputError(f"wall pair must be a PairProperties, got {type(pair).__name__}")
    return tuple(p), tuple(nrm / length)


def check_scene_options(material, pair, skin, cell_size, impact_speed, check_interval) -> None:
    """The scene's material and pair types, and its skin [m], cell size [m], impact speed [m/s] (finite, > 0) and
    health-check interval (>= 1 step)."""
    if not isinstance(material, Material):
        raise WheelsoilInputError(f"material must be a wheelsoil.granular.Material, got {type(material).__name__}")
    if not isinstance(pair, PairProperties):
        raise WheelsoilInputError(f"pair must be a PairProperties, got {type(pair).__name__}")
    for name, value in (("skin", skin), ("cell_size", cell_size)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise WheelsoilInputError(f"{name} = {value!r} m must be a finite number > 0")
    if not (math.isfinite(impact_speed) and impact_speed > 0):
        raise WheelsoilInputError(f"impact_speed = {impact_speed!r} m/s must be > 0")
    if int(check_interval) < 1:
        raise WheelsoilInputError(f"check_interval = {check_interval!r} must be >= 1")
