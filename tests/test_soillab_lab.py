"""The virtual soil lab's tests on small beds, with the checks whose answer is known: a plate at rest carries its
own weight; the shear box's measured normal stress equals the imposed one; the plate's force rises with sinkage from
zero above the surface. (Coarse particles: these check the machinery, not the calibrated soil.)"""

import numpy as np
import pytest

from wheelsoil.granular import BedSpec, Material, PairProperties
from wheelsoil.soillab import PlateSpec, ShearSpec, plate_test, poured_bed_test, shear_test
from wheelsoil.soillab.penetration import resting_plate

#: The two checks whose answer is known -- the plate at rest carries its weight, the shear cap holds the imposed
#: stress -- run in the fast tier on one small bed (about 25 s on 2 cores with its preparation); the rest of this
#: file's small DEM tests (about 50 s) in the slow tier, with the lab's plain parts, fits and errors fast in
#: tests/test_soillab_plain.py.
slow = pytest.mark.slow

SOIL = Material("test particles", youngs_modulus=5e7, poisson_ratio=0.3, density=2300.0)
PAIR = PairProperties(restitution=0.5, static_friction=0.5, rolling_friction=0.1)


def small_bed(seed=0, **kw):
    values = dict(length=0.15, width=0.15, depth=0.05, diameter_min=0.006, diameter_max=0.008, material=SOIL,
                  pair=PAIR, periodic=False, seed=seed)
    values.update(kw)
    return BedSpec(**values)


@pytest.mark.parametrize("mass", [pytest.param(0.5, marks=slow), 2.0])
def test_plate_at_rest_carries_its_own_weight(bed_cache, mass):
    """Laid on the bed and left under gravity, the soil's force on the plate over the last quarter of a 0.25 s rest
    equals its weight (to 2 %: what the rest's last motion leaves; the plate comes to rest within about 0.1 s)."""
    rest = resting_plate(small_bed(), PlateSpec(diameter=0.05), mass=mass, cache_dir=bed_cache)
    assert rest.soil_force == pytest.approx(rest.weight, rel=0.02)
    assert rest.settlement > 0 and abs(rest.final_speed) < 0.01


@slow
def test_plate_force_starts_at_zero_and_rises(bed_cache):
    spec = PlateSpec(diameter=0.05, speed=0.1, max_sinkage=0.008, sample_interval=0.001)
    result = plate_test(small_bed(), spec, cache_dir=bed_cache)
    c = result.curve
    # the plate starts above every sphere: no force until its face reaches the highest sphere top
    assert 0.0 < result.top_offset < 0.008 * 1.5
    clear = c.sinkage + 0.5 * 0.001 < -result.top_offset  # the whole sample above the highest top
    assert clear.any() and np.all(c.force[clear] == 0.0)
    deep = c.sinkage > 0.002
    assert np.all(c.force[deep] > 0)
    slope = np.polyfit(c.sinkage[~clear], c.force[~clear], 1)[0]
    assert slope > 0
    assert result.bulk_density == pytest.approx(result.packing_fraction * SOIL.density)
    assert 0.5 < result.packing_fraction < 0.65


@slow
def test_an_interrupted_plate_test_continues_to_the_same_curve(bed_cache, tmp_path, monkeypatch):
    """A plate test killed after its second checkpoint and run again continues from it to the curve, bit for bit, of
    the same test run through (both keep a state every 2 samples); the finished test leaves no checkpoint."""
    from wheelsoil.soillab import penetration

    spec = PlateSpec(diameter=0.05, speed=0.1, max_sinkage=0.008, sample_interval=0.001)
    through = plate_test(small_bed(), spec, cache_dir=bed_cache, checkpoint=tmp_path / "a.h5", checkpoint_every=2)
    assert not (tmp_path / "a.h5").exists()

    saved = []
    real_save = penetration.save_state

    def save_then_die(path, state, meta):
        real_save(path, state, meta)
        saved.append(meta["samples"])
        if len(saved) == 2:
            raise KeyboardInterrupt("killed after the second checkpoint")

    monkeypatch.setattr(penetration, "save_state", save_then_die)
    with pytest.raises(KeyboardInterrupt):
        plate_test(small_bed(), spec, cache_dir=bed_cache, checkpoint=tmp_path / "b.h5", checkpoint_every=2)
    assert saved == [2, 4] and (tmp_path / "b.h5").is_file()
    later = []
    monkeypatch.setattr(penetration, "save_state", lambda p, st, meta: (later.append(meta["samples"]),
                                                                        real_save(p, st, meta)))
    resumed = plate_test(small_bed(), spec, cache_dir=bed_cache, checkpoint=tmp_path / "b.h5", checkpoint_every=2)
    assert len(through.curve.force) > 6 and later[0] == 6  # it went on from the fourth sample, not from the start
    np.testing.assert_array_equal(resumed.curve.sinkage, through.curve.sinkage)
    np.testing.assert_array_equal(resumed.curve.force, through.curve.force)
    assert not (tmp_path / "b.h5").exists()
    # another test's checkpoint is never continued
    real_save(tmp_path / "c.h5", {"x": np.zeros(1)}, {"key": "another test"})
    with pytest.raises(penetration.WheelsoilInputError, match="checkpoint of another test"):
        plate_test(small_bed(), spec, cache_dir=bed_cache, checkpoint=tmp_path / "c.h5", checkpoint_every=2)


@slow
def test_poured_bed_over_seeds(bed_cache):
    """Bulk density = packing fraction x particle density, per seed; other seeds give other packings."""
    beds = poured_bed_test(small_bed(), seeds=(0, 1), cache_dir=bed_cache)
    mean, sd = beds.bulk_density
    assert beds.beds[0].particles != beds.beds[1].particles or sd > 0
    for b in beds.beds:
        assert b.bulk_density == pytest.approx(b.packing_fraction * SOIL.density, rel=1e-12)
    assert 0.5 * SOIL.density < mean < 0.66 * SOIL.density


SHEAR_BED = dict(diameter_min=0.005, diameter_max=0.0065)


def test_shear_box_holds_the_imposed_normal_stress(bed_cache):
    """The cap, free under sigma A, carries the imposed stress while the ring moves (to 1 % over the samples)."""
    spec = ShearSpec(normal_stresses=(4e3, 8e3, 12e3), side=0.08, height=0.04, speed=0.1, max_displacement=0.002,
                     sample_interval=0.0002, consolidation_time=0.02)
    result = shear_test(small_bed(), spec, cache_dir=bed_cache)
    for run in result.runs:
        assert run.mean_normal == pytest.approx(run.normal_stress, rel=0.01)
        assert np.all(run.shear_stress[2:] > 0)  # the soil resists the ring's motion
