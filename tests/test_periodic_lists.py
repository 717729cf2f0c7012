"""The neighbour lists along a periodic x against brute force (granular.neighbors.build_neighbor_lists and
widen_clearance): each block row is read as runs of consecutive columns, some of them wrapped around from the grid's
other end (neighbors.column_runs); every pair within reach across the boundary must be listed once and every
clearance must stay a lower bound on the nearest-image gap to each sphere not listed, on grids of three columns (each
block holds every column) and more."""

import numpy as np
import pytest

from wheelsoil.granular import Scene

from lifted_grains import lift


def _periodic_box(period: float, seed: int) -> Scene:
    """Spheres of 6-10.5 mm in a box periodic along x (length ``period`` [m]), 0.15 m wide, stirred at 0.5 m/s and
    stepped 300 times, so that spheres sit across the boundary."""
    rng = np.random.default_rng(seed)
    nx = int(period / 0.0215)
    grid = np.stack(np.meshgrid(np.arange(nx), np.arange(6), np.arange(6), indexing="ij"), -1).reshape(-1, 3)
    x = np.array([period / nx, 0.021, 0.021]) * (grid + 0.5) + rng.uniform(-1e-3, 1e-3, grid.shape)
    x[:, 1:] += 0.004
    s = Scene((0, 0, 0), (period, 0.15, 0.3), periodic_x=True)
    s.add_box_walls()
    s.add_spheres(x, rng.uniform(0.006, 0.0105, len(x)), velocities=rng.normal(0, 0.5, x.shape))
    s.time_step = 5e-5
    s.step(300)
    return s


def _nearest_image_gaps(s: Scene) -> np.ndarray:
    """Gap [m] between every two spheres at the last rebuild, along x to the nearest image."""
    x = s.device.particles.x_ref.to_numpy()
    r = s.radii
    d = x[:, None] - x[None]
    d[..., 0] -= s.period * np.round(d[..., 0] / s.period)
    return np.linalg.norm(d, axis=-1) - r[:, None] - r[None]


@pytest.mark.parametrize("period, seed", [(0.07, 0), (0.07, 1), (0.13, 2)])
def test_periodic_lists_hold_every_pair_across_the_boundary_and_bound_every_gap(period, seed):
    s = _periodic_box(period, seed)
    nl = s.device.neighbor_list
    assert nl.grid.dims[0] == (3 if period < 0.1 else 5)
    gap = _nearest_image_gaps(s)
    n = s.n_particles
    owners = np.repeat(np.arange(n), np.diff(nl.pairs.start.to_numpy()))
    partners = nl.pairs.j.to_numpy()[: nl.n_pairs]
    ii, jj = np.nonzero(np.triu(gap < nl.skin, k=1))
    x = s.device.particles.x_ref.to_numpy()
    across = np.abs(x[ii, 0] - x[jj, 0]) > 0.5 * s.period  # pairs that meet only across the boundary
    assert across.sum() >= 3
    np.testing.assert_array_equal(owners, ii)
    np.testing.assert_array_equal(partners, jj)
    listed = np.zeros((n, n), bool)
    listed[ii, jj] = listed[jj, ii] = True
    np.fill_diagonal(listed, True)
    clearance = nl.clearance.to_numpy()
    unlisted = np.where(listed, np.inf, gap).min(axis=1)
    assert np.all(clearance <= unlisted * (1 + 1e-12))
    assert np.all(clearance >= nl.skin * (1 - 1e-12))


@pytest.mark.parametrize("period", [0.07, 0.13])
def test_a_grain_in_the_air_at_the_boundary_searches_around_it(period):
    """A grain lifted clear of the bed at the boundary, rising: its widened clearance (7 columns, more than the grid
    holds at 0.07 m) is a lower bound on its nearest-image gap to every sphere it does not list."""
    s = _periodic_box(period, 3)
    top = int(np.argmax(s.positions[:, 2]))
    lift(s, [top], [(0.001, 0.075, 0.2)], 3.0)
    nl = s.device.neighbor_list
    assert nl.widened >= 1
    gap = _nearest_image_gaps(s)
    np.fill_diagonal(gap, np.inf)
    assert nl.clearance.to_numpy()[top] <= gap[top].min() * (1 + 1e-12)
    assert nl.clearance.to_numpy()[top] > 2 * nl.grid.cell  # the bed and walls, not the 27 cells, bound it
