"""The contacts' memory on the host: what a scene, a prepared bed and a moving soil patch hand each other.

A contact that lasts keeps two vectors (:mod:`.contact`): the tangential spring's displacement xi [m] and the
rolling spring's torque [N m] (EPSD law; zero under CDT). Sphere pairs keep them per listed pair, owned by the lower
index and stated as the owner sees them; spheres keep them per wall. :class:`ContactHistory` holds both, with the
operations the scene's structural edits need, each returning a new history (NumPy only, no Taichi).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields, replace

import numpy as np

from .errors import WheelsoilInputError


@dataclass(frozen=True)
class ContactHistory:
    """The contact history of N spheres and W walls.

    pair_i, pair_j: (P,) the pairs, pair_i < pair_j, sorted by pair_i then pair_j (int32);
    pair_xi, pair_roll: (P, 3) tangential displacement [m] and rolling spring torque [N m] as sphere pair_i sees them
    (zero for a pair listed but apart);
    xi_wall, roll_wall: (N, W, 3) the same for each sphere at each wall.
    """

    pair_i: np.ndarray
    pair_j: np.ndarray
    pair_xi: np.ndarray
    pair_roll: np.ndarray
    xi_wall: np.ndarray
    roll_wall: np.ndarray

    @classmethod
    def empty(cls, n_spheres: int, n_walls: int) -> ContactHistory:
        """No pair and no wall contact."""
        none = np.zeros((0, 3))
        return cls(np.zeros(0, np.int32), np.zeros(0, np.int32), none, none.copy(),
                   np.zeros((n_spheres, n_walls, 3)), np.zeros((n_spheres, n_walls, 3)))

    @classmethod
    def from_arrays(cls, arrays: Mapping) -> ContactHistory:
        """From named arrays (:meth:`to_arrays`, a checkpoint or a bed file); the rolling torques are zero where they
        are missing (states and beds written before the rolling history existed)."""
        missing = [k for k in ("pair_i", "pair_j", "pair_xi", "xi_wall") if k not in arrays]
        if missing:
            raise WheelsoilInputError(f"contact history without {', '.join(missing)}")
        xi, xi_wall = np.asarray(arrays["pair_xi"], float), np.asarray(arrays["xi_wall"], float)
        return cls(np.asarray(arrays["pair_i"], np.int32), np.asarray(arrays["pair_j"], np.int32), xi,
                   np.asarray(arrays.get("pair_roll", np.zeros_like(xi)), float), xi_wall,
                   np.asarray(arrays.get("roll_wall", np.zeros_like(xi_wall)), float))

    def to_arrays(self) -> dict[str, np.ndarray]:
        """The history as named arrays (copies)."""
        return {f.name: np.array(getattr(self, f.name)) for f in fields(self)}

    @property
    def n_pairs(self) -> int:
        return len(self.pair_i)

    def with_wall(self) -> ContactHistory:
        """One more wall, which no sphere touches yet."""
        column = np.zeros((self.xi_wall.shape[0], 1, 3))
        return replace(self, xi_wall=np.concatenate([self.xi_wall, column], axis=1),
                             roll_wall=np.concatenate([self.roll_wall, column], axis=1))

    def with_spheres(self, n: int, xi_wall=None, roll_wall=None) -> ContactHistory:
        """``n`` more spheres (indices after the present ones), with no pairs yet and the given wall contacts
        ((n, W, 3); default none)."""
        rows = np.zeros((n,) + self.xi_wall.shape[1:])
        return replace(self, 
            xi_wall=np.concatenate([self.xi_wall, rows if xi_wall is None else np.asarray(xi_wall, float)]),
            roll_wall=np.concatenate([self.roll_wall, rows if roll_wall is None else np.asarray(roll_wall, float)]))

    def with_pairs(self, pair_i, pair_j, pair_xi, pair_roll=None) -> ContactHistory:
        """The pairs (pair_i[k], pair_j[k]) given pair_xi[k] [m] and pair_roll[k] [N m] (default zero), replacing
        what they had. Both are as sphere pair_i[k] sees them; a pair given with pair_i > pair_j is turned around
        (both negated). Indices must lie below the number of spheres."""
        i = np.asarray(pair_i, np.int64).ravel()
        j = np.asarray(pair_j, np.int64).ravel()
        xi = np.asarray(pair_xi, float).reshape(-1, 3)
        roll = np.zeros_like(xi) if pair_roll is None else np.asarray(pair_roll, float).reshape(-1, 3)
        n = self.xi_wall.shape[0]
        if not (len(i) == len(j) == len(xi) == len(roll)) or (
                len(i) and (min(i.min(), j.min()) < 0 or max(i.max(), j.max()) >= n)):
            raise WheelsoilInputError(f"pair history: pair_i, pair_j (indices below {n}), pair_xi and pair_roll "
                                      "(pairs, 3) must have one row per pair")
        if np.any(i == j):
            raise WheelsoilInputError("pair history: a sphere cannot pair with itself")
        turned = (i > j)[:, None]
        all_i = np.concatenate([np.minimum(i, j), self.pair_i])
        all_j = np.concatenate([np.maximum(i, j), self.pair_j])
        _, first = np.unique(all_i * n + all_j, return_index=True)  # the given rows come first: they win
        order = first[np.lexsort((all_j[first], all_i[first]))]
        return replace(self, 
            pair_i=all_i[order].astype(np.int32), pair_j=all_j[order].astype(np.int32),
            pair_xi=np.concatenate([np.where(turned, -xi, xi), self.pair_xi])[order],
            pair_roll=np.concatenate([np.where(turned, -roll, roll), self.pair_roll])[order])

    def kept(self, mask: np.ndarray) -> ContactHistory:
        """Only the spheres where ``mask`` is true, renumbered in order, with the pairs among them."""
        new_index = np.full(mask.size, -1, np.int64)
        new_index[mask] = np.arange(int(mask.sum()))
        pi, pj = new_index[self.pair_i], new_index[self.pair_j]
        kept = (pi >= 0) & (pj >= 0)  # the renumbering is monotone: pairs stay sorted
        return ContactHistory(pi[kept].astype(np.int32), pj[kept].astype(np.int32), self.pair_xi[kept],
                              self.pair_roll[kept], self.xi_wall[mask], self.roll_wall[mask])

    def in_order(self, order: np.ndarray) -> ContactHistory:
        """The touching pairs and the wall contacts with the spheres renumbered so that new sphere k is old sphere
        ``order[k]`` (a permutation). A pair whose two spheres swap order is turned around: its owner changes, so
        its displacement and rolling torque are negated."""
        new_index = np.empty(len(order), np.int64)
        new_index[order] = np.arange(len(order))
        pi, pj = new_index[self.pair_i], new_index[self.pair_j]
        touching = np.any((self.pair_xi != 0.0) | (self.pair_roll != 0.0), axis=1)
        sign = np.where(pi > pj, -1.0, 1.0)[:, None]
        pi, pj = np.minimum(pi, pj)[touching], np.maximum(pi, pj)[touching]
        srt = np.lexsort((pj, pi))
        return ContactHistory(pi[srt].astype(np.int32), pj[srt].astype(np.int32),
                              (sign * self.pair_xi)[touching][srt], (sign * self.pair_roll)[touching][srt],
                              self.xi_wall[order], self.roll_wall[order])
