"""The uniform grid of cells over a scene's domain: one sizing, one cell order, shared by the soil's neighbour
search (:mod:`.neighbors`: spheres binned by centre) and the wheel contact (``wheelsoil.coupling.kernels``:
facets binned by their grown boxes, each sphere reading its own cell).

Cells are cubes of edge ``cell`` from ``origin``; ``dims`` counts them per axis, and a cell's flat index runs x
fastest, then y, then z (:func:`cell_index`). Points outside the grid fall into the nearest boundary cell
(:func:`cell_coords`), so the grid needs to cover only the domain. In a domain periodic along x the cell edge
divides the period exactly, so that the cells wrap around (:meth:`UniformGrid.covering`).
"""

import math
from dataclasses import dataclass

import numpy as np
import taichi as ti

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.taichi_types import ivec3, vec3

#: Largest number of cells a grid may have (cell indices and prefix sums are 32-bit).
MAX_CELLS = 2**31 - 2


@dataclass(frozen=True)
class UniformGrid:
    """Cubic cells of edge ``cell`` [m] from ``origin`` [m], ``dims`` cells along x, y, z; ``period`` [m] > 0: the
    domain is periodic along x with that length (0: not periodic)."""

    origin: tuple[float, float, float]
    cell: float
    dims: tuple[int, int, int]
    period: float = 0.0

    @classmethod
    def covering(cls, lo, hi, cell: float, *, period: float = 0.0) -> "UniformGrid":
        """The grid of cells of edge at least ``cell`` [m] over the box [lo, hi]; with ``period`` > 0 the domain is
        periodic along x with that length, and the edge is stretched to divide it exactly (at least 3 cells)."""
        lo = np.asarray(lo, float).reshape(3)
        extent = np.asarray(hi, float).reshape(3) - lo
        cell = float(cell)
        along = 0
        if period > 0.0:
            along = int(math.floor(period / cell * (1 + 1e-12)))
            if along < 3:
                raise WheelsoilInputError(
                    f"the periodic length {period:g} m holds {along} neighbour cells of {cell:.4g} m; it must hold at "
                    f"least 3 (a period of at least {3 * cell:.4g} m)")
            cell = period / along
        dims = np.maximum(1, np.ceil(extent / cell).astype(np.int64))
        if along:
            dims[0] = along
        if int(np.prod(dims)) > MAX_CELLS:
            raise WheelsoilInputError(f"neighbour grid of {dims.tolist()} cells is too large; raise cell_size")
        return cls(tuple(float(v) for v in lo), cell, tuple(int(v) for v in dims), float(period))

    @property
    def inv_cell(self) -> float:
        return 1.0 / self.cell

    @property
    def inv_period(self) -> float:
        """1 / period (0 when not periodic: the kernels' nearest-image distances are then the plain ones)."""
        return 1.0 / self.period if self.period > 0 else 0.0

    @property
    def n_cells(self) -> int:
        return int(np.prod(self.dims))

    def kernel_args(self) -> tuple:
        """(origin, inv_cell, dims) as the Taichi kernels take them."""
        return vec3(*self.origin), self.inv_cell, ivec3(*self.dims)


@ti.func
def cell_coords(p: vec3, origin: vec3, inv_cell: ti.f64, dims: ivec3) -> ivec3:
    """Integer cell coordinates of the point p, clamped to the grid."""
    c = ti.cast(ti.floor((p - origin) * inv_cell), ti.i32)
    return ti.max(ti.min(c, dims - 1), 0)


@ti.func
def cell_index(c: ivec3, dims: ivec3) -> ti.i32:
    """Flat index of cell c: x fastest, then y, then z."""
    return (c[2] * dims[1] + c[1]) * dims[0] + c[0]
