"""Planar walls: their description (:class:`Wall`) and their device arrays with the spheres' wall contacts
(:class:`WallArrays`).

Every sphere keeps one tangential history per wall and a bit mask of the walls it touches, so a scene holds at
most :data:`MAX_WALLS` walls. The contact parameters of each wall with the soil (seed 004 eqs. 9--12) are
computed once, when the arrays are made.
"""

from dataclasses import dataclass

import numpy as np
import taichi as ti

from . import forces
from .contact import ROLLING_MODELS
from .materials import Material, PairProperties, effective_modulus, effective_shear_modulus

#: Most planar walls per scene: each particle keeps a 32-bit mask of the walls it touches.
MAX_WALLS = 31


@dataclass(frozen=True)
class Wall:
    """An infinite rigid plane. ``normal`` points into the side where particles live.

    ``material=None`` makes the wall perfectly rigid (E = infinity).
    """

    point: tuple[float, float, float]
    normal: tuple[float, float, float]
    material: Material | None
    pair: PairProperties


@dataclass
class WallArrays:
    """Device arrays of the walls and of N spheres' contacts with them.

    point, normal: (walls,) vec3; props: (walls, 6) the pair's E*, G*, beta, mu_s, mu_r and rolling law
    (``forces.WALL_*``); xi: (N, walls) vec3 tangential displacements [m]; roll: (N, walls) vec3 rolling spring
    torques [N m] (EPSD walls; zero otherwise); touching: (N,) bit mask of the walls a sphere touches;
    near: (N,) bit mask of the walls within reach since the last neighbour rebuild.
    """

    point: ti.Ndarray
    normal: ti.Ndarray
    props: ti.Ndarray
    xi: ti.Ndarray
    roll: ti.Ndarray
    touching: ti.Ndarray
    near: ti.Ndarray
    count: int

    @classmethod
    def upload(cls, walls: list[Wall], soil: Material, n: int, xi_history: np.ndarray | None = None,
               roll_history: np.ndarray | None = None) -> "WallArrays":
        """The arrays of ``walls`` against ``n`` spheres of ``soil``; ``xi_history`` (n, walls, 3) [m] and
        ``roll_history`` (n, walls, 3) [N m] carry the spheres' wall contacts over (a sphere with a nonzero
        displacement or rolling torque touches that wall)."""
        count = len(walls)
        point = ti.Vector.ndarray(3, ti.f64, shape=count)
        normal = ti.Vector.ndarray(3, ti.f64, shape=count)
        if count:
            point.from_numpy(np.array([w.point for w in walls], dtype=np.float64))
            normal.from_numpy(np.array([w.normal for w in walls], dtype=np.float64))
        props = np.zeros((max(count, 1), 6))
        for k, w in enumerate(walls):
            props[k, forces.WALL_E_EFF] = effective_modulus(soil, w.material)
            props[k, forces.WALL_G_EFF] = effective_shear_modulus(soil, w.material)
            props[k, forces.WALL_BETA] = w.pair.damping_ratio
            props[k, forces.WALL_MU_S] = w.pair.static_friction
            props[k, forces.WALL_MU_R] = w.pair.rolling_friction
            props[k, forces.WALL_ROLLING] = ROLLING_MODELS[w.pair.rolling_model]
        props_arr = ti.ndarray(ti.f64, shape=props.shape)
        props_arr.from_numpy(props)
        xi = ti.Vector.ndarray(3, ti.f64, shape=(n, max(count, 1)))
        roll = ti.Vector.ndarray(3, ti.f64, shape=(n, max(count, 1)))
        touching = ti.ndarray(ti.i32, shape=n)
        touching.fill(0)
        touches = np.zeros((n, count), bool)
        for array, history in ((xi, xi_history), (roll, roll_history)):
            array.fill(0.0)
            if history is not None and count:
                array.from_numpy(np.ascontiguousarray(history))
                touches |= np.any(history != 0.0, axis=2)  # (n, walls)
        if count:
            touching.from_numpy((touches * (1 << np.arange(count))).sum(axis=1).astype(np.int32))
        return cls(point, normal, props_arr, xi, roll, touching, ti.ndarray(ti.i32, shape=n), count)

    def history(self) -> dict:
        """The spheres' wall contacts: ``xi_wall`` tangential displacements [m] and ``roll_wall`` rolling torques
        [N m], each (N, walls, 3)."""
        return {"xi_wall": self.xi.to_numpy()[:, : self.count], "roll_wall": self.roll.to_numpy()[:, : self.count]}
