"""Soil-bed preparation: settling, levelling, measurements, HDF5 round trip, cache reuse."""

import h5py
import numpy as np
import pytest

from wheelsoil.granular import BedSpec, WheelsoilInputError, column_order, load_bed, prepare_bed
from wheelsoil.granular.bed import bed_cache_path, measure_packing_fraction

TINY = dict(length=0.16, width=0.1, depth=0.06, diameter_min=0.016, diameter_max=0.024, periodic=False)


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("beds")


@pytest.mark.parametrize("g", [9.81, 9.81 / 6])
def test_bed_settles_and_levels_under_its_gravity(cache, g):
    spec = BedSpec(**TINY, gravity=(0, 0, -g))
    bed = prepare_bed(spec, cache_dir=cache)
    assert not bed.meta["from_cache"]
    # settled: kinetic energy per particle below the threshold
    m = spec.material.density * 4 / 3 * np.pi * bed.radii**3
    ke = 0.5 * np.sum(m * np.sum(bed.velocities**2, axis=1)) / bed.n_particles
    assert ke < spec.settle_threshold
    # levelled: no centre above the target, surface within one particle diameter of it
    assert bed.positions[:, 2].max() <= spec.depth
    assert abs(bed.surface_height - spec.depth) < spec.diameter_max
    # inside the bin, radii within the requested distribution
    assert np.all(bed.positions[:, :2] > 0) and np.all(bed.positions[:, 0] < spec.length)
    assert bed.radii.min() >= spec.diameter_min / 2 and bed.radii.max() <= spec.diameter_max / 2
    # a random loose-to-dense packing of spheres: between random loose (0.55) and close (0.64) packing,
    # with a margin for wall effects in so small a bin
    assert 0.45 < bed.packing_fraction < 0.66


def test_same_bed_is_reused_from_cache(cache):
    spec = BedSpec(**TINY)
    first = prepare_bed(spec, cache_dir=cache)
    again = prepare_bed(spec, cache_dir=cache)
    assert again.meta["from_cache"]
    np.testing.assert_array_equal(again.positions, first.positions)
    # any parameter that shapes the bed changes the key
    for change in (dict(seed=1), dict(gravity=(0, 0, -1.62)), dict(diameter_max=0.022), dict(depth=0.07),
                   dict(pour_friction_factor=0.5)):
        assert bed_cache_path(BedSpec(**{**TINY, **change}), cache) != bed_cache_path(spec, cache)
    # a loose pour (the default) keeps the key it had before the pour's friction could be set
    assert "pour_friction_factor" not in spec.to_dict()


@pytest.mark.slow  # six beds of ~600 spheres, ~45 s
@pytest.mark.parametrize("seed", [0, 1])
def test_the_pour_friction_sets_the_packing_and_the_bed_keeps_its_friction(cache, seed):
    """Salot et al. (2009): the friction while the sample is made sets its density. Spheres with sliding and rolling
    friction 0.5 pour loose (random loose packing, about 0.55-0.58); poured frictionless they slide towards random
    close packing (0.64 for equal spheres, a little more for these 12-18 mm ones); poured with twice their friction
    they lock sooner, looser (on the CMU sand's particles a factor 1.5 took 0.515-0.520 to 0.474-0.486 in a
    0.12 m box, two seeds). Every bed is tested with the pair's own friction."""
    from wheelsoil.material import PairProperties

    rough = PairProperties(restitution=0.5, static_friction=0.5, rolling_friction=0.5)
    base = dict(length=0.15, width=0.15, depth=0.08, diameter_min=0.012, diameter_max=0.018, periodic=False, seed=seed,
                pair=rough)
    loose = prepare_bed(BedSpec(**base), cache_dir=cache)
    dense = prepare_bed(BedSpec(**base, pour_friction_factor=0.0), cache_dir=cache)
    assert dense.packing_fraction > loose.packing_fraction + 0.03, (loose.packing_fraction, dense.packing_fraction)
    assert dense.packing_fraction < np.pi / (3 * np.sqrt(2))  # below the densest packing of spheres (Kepler)
    assert dense.spec.pair == rough and dense.spec.pour_pair(rough).static_friction == 0.0
    rougher = prepare_bed(BedSpec(**base, pour_friction_factor=2.0), cache_dir=cache)
    assert rougher.packing_fraction < loose.packing_fraction - 0.02, (rougher.packing_fraction, loose.packing_fraction)
    assert rougher.spec.pair == rough and rougher.spec.pour_pair(rough).rolling_friction == 1.0


def test_bed_hdf5_round_trip_and_provenance(cache, tmp_path):
    bed = prepare_bed(BedSpec(**TINY), cache_dir=cache)
    path = bed.save(tmp_path / "bed.h5")
    loaded = load_bed(path)
    assert loaded.spec == bed.spec
    np.testing.assert_array_equal(loaded.radii, bed.radii)
    np.testing.assert_array_equal(loaded.angular_velocities, bed.angular_velocities)
    assert loaded.surface_height == bed.surface_height
    with h5py.File(path) as f:
        for key in ("version", "git_rev", "taichi_version", "arch", "seed", "created", "spec"):
            assert key in f.attrs
        assert f["particles/position"].attrs["units"] == "m"
    assert not list(tmp_path.glob(".*partial"))


def test_bed_to_scene_stays_at_rest(cache):
    bed = prepare_bed(BedSpec(**TINY), cache_dir=cache)
    scene = bed.to_scene()
    scene.step(200)
    drift = np.abs(scene.positions - bed.positions).max()
    assert drift < 0.05 * bed.spec.diameter_min


@pytest.mark.parametrize(
    "change, fragment",
    [
        (dict(length=-1.0), "bed length = -1.0"),
        (dict(diameter_min=0.03), "diameter_max = 0.024 m is smaller than diameter_min = 0.03"),
        (dict(gravity=(0, 0, 9.81)), "pointing down"),
        (dict(width=0.05), "too narrow"),
        (dict(depth=0.01), "at least two of the largest particles"),
    ],
)
def test_bad_bed_spec_is_named(change, fragment):
    with pytest.raises(WheelsoilInputError, match=fragment.replace("(", r"\(")):
        BedSpec(**{**TINY, **change})


def test_missing_bed_file_is_named(tmp_path):
    with pytest.raises(WheelsoilInputError, match="does not exist"):
        load_bed(tmp_path / "nope.h5")


@pytest.mark.parametrize("height_cells", [1, 2, 5])
def test_packing_fraction_of_a_simple_cubic_lattice_is_pi_over_6(height_cells):
    """Touching spheres on a simple cubic lattice fill pi/6 of space. The core region is a whole
    number of lattice cells, as short as one cell, and the estimate must be exact for each."""
    a = 0.02  # lattice spacing = diameter [m]
    spec = BedSpec(length=12 * a, width=9 * a, depth=0.1, diameter_min=a, diameter_max=a, periodic=False)
    # region [a, L - a] x [a, W - a] x [a, surface - a]: 10 x 7 x height_cells lattice cells
    surface = (2 + height_cells) * a
    # centres offset by 0.3 a from the region's faces so none lies on a boundary
    n = (12, 9, 3 + height_cells)
    idx = np.stack(np.meshgrid(*[np.arange(k) for k in n], indexing="ij"), -1).reshape(-1, 3)
    positions = (idx + 0.3) * a
    radii = np.full(len(positions), a / 2)
    assert measure_packing_fraction(positions, radii, spec, surface) == pytest.approx(np.pi / 6, rel=1e-12)


def test_column_order_groups_spheres_into_columns():
    rng = np.random.default_rng(3)
    positions = rng.uniform([0, 0, 0], [0.5, 0.2, 0.1], (2000, 3))
    perm = column_order(positions, 0.05)
    assert sorted(perm) == list(range(len(positions)))  # a permutation
    p = positions[perm]
    # columns (counted from the lowest x and y) are contiguous runs, bottom to top; the shorter
    # side (y) varies fastest
    col = np.floor((p[:, :2] - positions[:, :2].min(axis=0)) / 0.05).astype(int)
    key = col[:, 0] * 1000 + col[:, 1]
    assert np.all(np.diff(key) >= 0)
    same = np.diff(key) == 0
    assert np.all(np.diff(p[:, 2])[same] > 0)
    # applying it to ordered positions gives the identity
    assert np.array_equal(column_order(p, 0.05), np.arange(len(p)))
    with pytest.raises(ValueError, match="cell"):
        column_order(positions, 0.0)
    with pytest.raises(ValueError, match="shape"):
        column_order(positions[:, :2], 0.05)


@pytest.mark.parametrize("periodic", [False, True])
def test_fill_particle_estimate_is_the_lattice_count(periodic):
    from wheelsoil.granular.bed import initial_packing
    from wheelsoil.granular.bed_spec import fill_particles

    spec = BedSpec(length=0.6, width=0.25, depth=0.05, diameter_min=0.010, diameter_max=0.015, periodic=periodic)
    positions, _, _ = initial_packing(spec)
    assert fill_particles(spec) == len(positions)


def test_a_bed_past_the_machine_memory_is_refused_before_any_work_naming_the_keys():
    """A 2 x 0.9 x 0.2 m bin of 1-1.5 mm particles (about 2e8 spheres: the 'bin of 1e9 particles' that used to
    end in MemoryError) is refused by the estimate alone, without allocating; the message names the keys."""
    import time

    from wheelsoil.granular.bed_spec import BYTES_PER_PARTICLE, check_memory, fill_particles

    spec = BedSpec(length=2.0, width=0.9, depth=0.2, diameter_min=0.001, diameter_max=0.0015, periodic=False)
    t0 = time.perf_counter()
    with pytest.raises(WheelsoilInputError) as info:
        check_memory(spec, available=24 * 2**30)
    assert time.perf_counter() - t0 < 1.0
    text = str(info.value)
    assert "soil.diameter_min" in text and "soil.length" in text and "GiB" in text
    with pytest.raises(WheelsoilInputError):
        prepare_bed(spec, use_cache=False)  # the same check, before the lattice is built
    small = BedSpec(length=0.6, width=0.25, depth=0.05, diameter_min=0.010, diameter_max=0.015, periodic=False)
    assert check_memory(small, available=24 * 2**30) == fill_particles(small) * BYTES_PER_PARTICLE


def test_history_in_column_order_turns_around_the_pairs_whose_owner_changes():
    """A pair's history is as its owner (the lower index) sees it: renumbering that swaps the two spheres of a pair
    must negate its displacement and rolling torque; pairs apart are dropped; wall rows follow their spheres."""
    from wheelsoil.granular.contact_history import ContactHistory

    a, b = np.array([1.0, 2.0, 3.0]), np.array([-4.0, 5.0, 0.5])
    hist = ContactHistory(np.array([0, 0, 1]), np.array([1, 2, 2]), np.array([a, np.zeros(3), b]),
                          np.array([2 * a, np.zeros(3), np.zeros(3)]), np.arange(9.0).reshape(3, 1, 3),
                          np.zeros((3, 1, 3)))
    out = hist.in_order(np.array([2, 0, 1]))  # new 0 = old 2, new 1 = old 0, new 2 = old 1
    # old (0, 1) -> new (1, 2): same order; old (1, 2) -> new (2, 0): turned around; old (0, 2) is apart
    assert out.pair_i.tolist() == [0, 1] and out.pair_j.tolist() == [2, 2]
    np.testing.assert_array_equal(out.pair_xi, [-b, a])
    np.testing.assert_array_equal(out.pair_roll, [np.zeros(3), 2 * a])
    np.testing.assert_array_equal(out.xi_wall[:, 0], hist.xi_wall[[2, 0, 1], 0])


def test_a_bed_file_keeps_its_contact_history(cache, tmp_path):
    bed = prepare_bed(BedSpec(**TINY), cache_dir=cache)
    assert bed.history is not None and bed.history.n_pairs > 0
    loaded = load_bed(bed.save(tmp_path / "bed.h5"))
    for key, value in bed.history.to_arrays().items():
        np.testing.assert_array_equal(getattr(loaded.history, key), value)
    np.testing.assert_array_equal(loaded.wall_planes, bed.wall_planes)


@pytest.mark.parametrize("periodic", [False, True])
def test_bed_spec_reads_back_as_written(periodic):
    """to_dict leaves out keys at their pre-existing values (cache keys kept); from_dict must read them back as
    those values, not as today's defaults (a walled bed read from the cache once came back periodic)."""
    spec = BedSpec(**{**TINY, "periodic": periodic})
    assert BedSpec.from_dict(spec.to_dict()) == spec


def test_a_grain_thrown_over_an_open_end_of_a_moving_patch_leaves_the_soil(tmp_path):
    """A moving patch's bin has no end walls (it holds the spheres there): a grain thrown over an end (launched from
    under the wheel) is not an escape that stops the run but soil leaving the patch, as the rut behind the rear
    end does at each shift; the patch removes it and counts it, its bookkeeping stays in step with the scene."""
    from wheelsoil.coupling.patch import MovingPatch

    bed = prepare_bed(BedSpec(**{**TINY, "periodic": True}), cache_dir=tmp_path)
    scene = bed.to_scene(periodic_x=False, end_walls=False)
    assert scene.open_ends_x
    patch = MovingPatch(bed, wheel_reach=0.02, shift=0.01)
    patch.start(scene)
    n = scene.n_particles
    free = np.flatnonzero(~scene.held)
    top = int(free[np.argmax(scene.positions[free, 2])])  # a free surface grain, thrown up and back over the end
    v = np.zeros((n, 3))
    v[top] = (-2.0, 0.0, 3.0)
    scene.set_velocities(v)
    scene.step(int(round(0.1 / scene.time_step)))  # the health check passes while it flies beyond x = 0
    assert scene.positions[top, 0] < 0.0
    assert patch.drop_thrown_out(scene) == 1 and patch.thrown_out == 1
    assert scene.n_particles == n - 1 == len(patch.ids) == len(patch.expected)
    assert (scene.positions[:, 0] >= 0.0).all() and patch.drop_thrown_out(scene) == 0
