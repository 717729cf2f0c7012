"""The neighbour list of a scene: the grid its spheres are binned in, the Verlet rows, and the compact pair list
that carries each pair's contact history (tangential displacement and rolling torque) (the kernels are in :mod:`.neighbors`).

:meth:`NeighborList.rebuild` bins the spheres, gathers every sphere's partners j > i within r_i + r_j + skin,
writes the new pair list with the history carried over from the current one (two lists swap, so rebuilding
allocates nothing once sizes settle), lays out the partner slots the force pass writes, and lists the walls
within reach of each sphere.
"""

import math
from dataclasses import dataclass

import numpy as np
import taichi as ti

from . import integrator, neighbors
from .errors import CapacityError
from .grid import UniformGrid
from .particles import ParticleArrays
from .walls import WallArrays


@dataclass
class PairList:
    """Every listed pair once (owner i < j, runs by owner, sorted by partner), with its history.

    start: (N + 1,) run starts by owner; j: partner; xi: tangential displacement [m] as the owner sees it;
    roll: the rolling spring's torque on the owner [N m] (contacts under the EPSD law; zero under CDT); touching: whether the pair touched at its last evaluation; rev, rev_pair: the pair's place in its partner's
    run of slots and the inverse; partner_slot: what the pair exerts on its partner (written by the force pass);
    n_particles: spheres the list is for (0: an empty list to carry no history from).
    """

    capacity: int
    start: ti.Ndarray
    j: ti.Ndarray
    xi: ti.Ndarray
    roll: ti.Ndarray
    touching: ti.Ndarray
    rev: ti.Ndarray
    rev_pair: ti.Ndarray
    partner_slot: ti.Ndarray
    n_particles: int = 0

    @classmethod
    def allocate(cls, n: int, capacity: int) -> "PairList":
        """Arrays for ``n`` spheres with room for ``capacity`` pairs."""
        return cls(capacity, ti.ndarray(ti.i32, shape=n + 1), ti.ndarray(ti.i32, shape=capacity),
                   ti.Vector.ndarray(3, ti.f64, shape=capacity), ti.Vector.ndarray(3, ti.f64, shape=capacity),
                   ti.ndarray(ti.i32, shape=capacity),
                   ti.ndarray(ti.i32, shape=capacity), ti.ndarray(ti.i32, shape=capacity),
                   ti.ndarray(neighbors.mat23, shape=capacity))

    @classmethod
    def from_history(cls, n: int, pair_i: np.ndarray, pair_j: np.ndarray, pair_xi: np.ndarray,
                     pair_roll: np.ndarray) -> "PairList":
        """A list holding the given pairs (sorted by i, then j), their displacements and rolling torques, to carry
        them into the first build."""
        out = cls.allocate(n, max(1, len(pair_i)))
        if len(pair_i):
            start = np.zeros(n + 1, np.int32)
            start[1:] = np.cumsum(np.bincount(pair_i, minlength=n))
            out.start.from_numpy(start)
            out.j.from_numpy(np.ascontiguousarray(pair_j, dtype=np.int32))
            out.xi.from_numpy(np.ascontiguousarray(pair_xi, dtype=np.float64))
            out.roll.from_numpy(np.ascontiguousarray(pair_roll, dtype=np.float64))
            out.touching.from_numpy(np.any((pair_xi != 0.0) | (pair_roll != 0.0), axis=1).astype(np.int32))
            out.n_particles = n
        return out


def row_width(r_min: float, r_max: float, skin: float) -> int:
    """Upper estimate of the number of partners within r_i + r_j + skin of the largest sphere.

    Spheres of radius r_min whose centres lie within r_max + r_min + skin occupy at most 74 % (the
    densest packing) of the shell between r_max and r_max + 2 r_min + skin. Rows that still overflow
    are widened automatically.
    """
    outer = r_max + 2.0 * r_min + skin
    return int(np.ceil(0.74 * (outer**3 - r_max**3) / r_min**3)) + 2


class NeighborList:
    """Cells, rows and the pair list of ``n`` spheres of radius up to ``r_max`` [m] on ``grid`` (periodic along x
    where the grid is) with Verlet ``skin`` [m]; ``pairs`` holds the history the first build carries over.

    Each rebuild also gives every sphere its displacement allowance until the next one
    (:func:`.neighbors.displacement_allowance`, from its clearance to whatever it does not list): ``allowance_inv2``
    holds 1 / a_i^2 [1/m^2], and the steps ask for a rebuild once some sphere's |x_i - x_ref_i|^2 / a_i^2 exceeds 1.
    """

    #: Widest row allowed: more partners with higher indices than this means an unreasonable size ratio or skin.
    MAX_ROW = 4096

    def __init__(self, n: int, grid: UniformGrid, skin: float, width: int, pairs: PairList, r_max: float) -> None:
        self.n, self.grid, self.skin, self.r_max = n, grid, float(skin), float(r_max)
        #: each sphere's clearance at the last rebuild [m] and its displacement allowance as 1 / a^2 [1/m^2];
        #: until the first rebuild, an allowance of 1e-15 m (any drift asks for one)
        self.clearance = ti.ndarray(ti.f64, shape=max(n, 1))
        self.allowance_inv2 = ti.ndarray(ti.f64, shape=max(n, 1))
        self.allowance_inv2.fill(1e30)
        #: the cap on every allowance at the last rebuild [m], and the spheres whose search was widened then
        #: (:meth:`rebuild`)
        self.cap = math.inf
        self.widened = 0
        self.cell_of = ti.ndarray(ti.i32, shape=n)
        self.cell_count = ti.ndarray(ti.i32, shape=grid.n_cells)
        self.cell_start = ti.ndarray(ti.i32, shape=grid.n_cells + 1)
        self.sorted_ids = ti.ndarray(ti.i32, shape=n)
        self._alloc_rows(width)
        self.partnered = ti.ndarray(ti.i32, shape=n)
        self.cursor = ti.ndarray(ti.i32, shape=n)
        self.rev_start = ti.ndarray(ti.i32, shape=n + 1)
        self.pairs = pairs
        self.spare: PairList | None = None
        self.n_pairs = 0

    def _alloc_rows(self, width: int) -> None:
        """Neighbour rows (scratch for building the pair list; they carry no history)."""
        self.width = width
        self.nbr = ti.ndarray(ti.i32, shape=(self.n, width))
        self.count = ti.ndarray(ti.i32, shape=self.n)

    def rebuild(self, p: ParticleArrays, walls: WallArrays, cap: float = math.inf, horizon: float = 0.0) -> None:
        """Rebin the spheres, rebuild the rows and the pair list (history carried over), list the walls in reach,
        give every sphere its displacement allowance (at most ``cap`` [m]), and take the positions as the new
        Verlet reference. A sphere in the air that would cross its allowance within ``horizon`` [s] at its speed
        searches further for its clearance (:func:`.neighbors.widen_clearance`; ``widened`` counts them)."""
        grid = self.grid
        if grid.period > 0.0:
            neighbors.wrap_positions(p.x, p.x_r, grid.origin[0], grid.period)
        origin, inv_cell, dims = grid.kernel_args()
        neighbors.bin_particles(p.x, origin, inv_cell, dims, self.cell_of, self.cell_count)
        neighbors.exclusive_scan(self.cell_count, self.cell_start)
        neighbors.scatter_to_cells(self.cell_of, self.cell_start, self.cell_count, self.sorted_ids)

        def build_rows() -> int:
            return neighbors.build_neighbor_lists(
                p.x, p.r, self.cell_start, self.sorted_ids, origin, inv_cell, dims, self.skin, self.r_max,
                grid.period, grid.inv_period, self.nbr, self.count, self.clearance,
            )

        most = build_rows()
        fitted = most + max(4, most // 4)
        if most > self.width or 2 * fitted < self.width:
            # Rows too narrow, or far wider than needed (wide rows waste cache): refit them.
            if fitted > self.MAX_ROW:
                raise CapacityError(
                    f"a particle has {most} neighbours with higher indices; the size ratio or skin is unreasonable"
                )
            self._alloc_rows(fitted)
            build_rows()

        # The new pair list (the rows, compact), with history carried from the current one.
        old = self.pairs
        new = self.spare or PairList.allocate(self.n, 1)
        n_pairs = neighbors.exclusive_scan(self.count, new.start)
        if n_pairs > new.capacity:
            new = PairList.allocate(self.n, int(n_pairs * 1.25) + 16)
            neighbors.exclusive_scan(self.count, new.start)
        neighbors.fill_pairs(
            self.nbr, self.count, new.start, new.j, new.xi, new.roll, new.touching,
            old.start, old.j, old.xi, old.roll, old.touching, old.n_particles,
        )
        new.n_particles = self.n
        # Partner slots by partner; zero, as the force pass expects of pairs that are apart (a pair
        # touching now writes its slot in the next force pass).
        neighbors.count_partners(new.j, n_pairs, self.partnered)
        neighbors.exclusive_scan(self.partnered, self.rev_start)
        neighbors.fill_reverse_index(new.j, n_pairs, self.rev_start, self.cursor, new.rev_pair, new.rev)
        new.partner_slot.fill(0.0)
        self.pairs, self.spare, self.n_pairs = new, old, n_pairs
        self.widened = 0
        if horizon > 0.0:
            self.widened = neighbors.widen_clearance(p.x, p.v, p.r, self.cell_start, self.sorted_ids, origin, inv_cell,
                                                     dims, self.skin, self.r_max, grid.period, grid.inv_period,
                                                     float(horizon), self.clearance)
        neighbors.near_walls(p.x, p.r, walls.point, walls.normal, self.skin, walls.near, self.clearance)
        self.cap = float(cap)
        neighbors.displacement_allowance(self.clearance, self.skin, min(self.cap, 1e300), self.allowance_inv2)
        integrator.copy_vec3(p.x, p.x_ref)

    def history(self) -> dict:
        """The pair list's history as NumPy arrays: ``pair_i``, ``pair_j``, ``pair_xi``, ``pair_roll``."""
        pairs, n_pairs = self.pairs, self.n_pairs
        owned = np.diff(pairs.start.to_numpy())
        return {
            "pair_i": np.repeat(np.arange(len(owned), dtype=np.int32), owned),
            "pair_j": pairs.j.to_numpy()[:n_pairs],
            "pair_xi": pairs.xi.to_numpy()[:n_pairs],
            "pair_roll": pairs.roll.to_numpy()[:n_pairs],
        }
