"""The soil lab's longer checks (slow tier): the direct shear envelope of frictional spheres, the angle of repose
over packings, the CMU wheels pressed into a bed, and the command line end to end with the measured curves."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from wheelsoil.soillab import ReposeSpec, ShearSpec, WheelPressSpec, repose_test, shear_test, wheel_press_test

from test_soillab_lab import SHEAR_BED, small_bed

pytestmark = pytest.mark.slow


def test_shear_envelope_of_frictional_spheres(bed_cache):
    """Sliding friction 0.5 and rolling friction 0.1: a peak friction angle in 20-35 deg (a band, not a published
    value: frictionless spheres give about 6 deg, and this lab's 0.12 m box measured 28.6 deg for the same
    particles at 4.8 mm), a residual angle no larger than the peak, the imposed stress held by the cap."""
    spec = ShearSpec(normal_stresses=(4e3, 8e3, 12e3), side=0.08, height=0.04, speed=0.05, max_displacement=0.008,
                     sample_interval=0.0004, consolidation_time=0.05)
    result = shear_test(small_bed(**SHEAR_BED), spec, cache_dir=bed_cache)
    assert 20.0 < result.peak.friction_angle < 35.0
    assert result.residual.friction_angle <= result.peak.friction_angle + 2 * result.peak.friction_angle_se
    for run in result.runs:
        assert run.mean_normal == pytest.approx(run.normal_stress, rel=0.01)
        assert run.peak >= run.residual


def test_angle_of_repose_over_packings(bed_cache):
    """The draw-down slope of these spheres stands between 15 and 30 deg in every packing, at rest."""
    spec = ReposeSpec(length=0.1, width=0.05, height=0.06, run_out=0.12, max_time=2.0, seeds=(0, 1))
    result = repose_test(small_bed(diameter_min=0.006, diameter_max=0.008), spec, cache_dir=bed_cache)
    for run in result.runs:
        assert run.at_rest and 15.0 < run.angle < 30.0 and run.fitted.sum() >= 3
    mean, sd = result.angle
    assert math.isfinite(sd)


@pytest.mark.parametrize("wheel", ["smooth", "grouser"])
def test_cmu_wheel_pressed_into_a_bed(bed_cache, wheel):
    bed = small_bed(length=0.4, width=0.16, depth=0.05, diameter_min=0.006, diameter_max=0.008)
    result = wheel_press_test(bed, WheelPressSpec(wheel=wheel, speed=0.1, max_sinkage=0.01, sample_interval=0.001),
                              cache_dir=bed_cache)
    c = result.curve
    assert c.wheel == wheel and c.force[-1] > 0
    assert np.polyfit(c.sinkage[c.sinkage > 0], c.force[c.sinkage > 0], 1)[0] > 0


def test_soil_lab_plate_command_end_to_end(tmp_path, bed_cache, measured_dir):
    """``wheelsoil soil-lab plate`` on a small box writes CSV, JSON and PNG with the measured curves and the Bekker
    table computed the same way for both."""
    out = tmp_path / "lab"
    cmd = [sys.executable, "-m", "wheelsoil.cases.cli", "soil-lab", "plate", "--plate", "0.05", "--box", "0.15",
           "0.15", "0.05", "--dmin", "0.006", "--dmax", "0.008", "--speed", "0.1", "--max-sinkage", "0.012",
           "--measured", f"{measured_dir}/cmu_3d_terramechanics/force_displacement/plate_sinkage.csv",
           "--out", str(out), "--cache", str(bed_cache)]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr
    figures = json.loads((out / "plate.json").read_text())
    assert figures["test"] == "plate" and figures["bekker"]["simulated"]["curves"][0]["n"] > 0
    assert (out / "plate.png").stat().st_size > 0 and (out / "plate.csv").stat().st_size > 0


#: The calibration's twin experiment: three candidate particles (sliding, rolling friction; EPSD law), the middle one
#: the truth whose plate curve is "measured" on other seeds.
TWIN_CANDIDATES = ((0.3, 0.05), (0.5, 0.3), (0.8, 0.6))
TWIN_TRUTH = TWIN_CANDIDATES[1]
#: Where the curves are compared [m]: past the first grains' contact (see the test's docstring).
TWIN_SINKAGES = (0.008, 0.011, 0.014)


def _twin_plate_pressure(bed_cache, friction, rolling, seed):
    from wheelsoil.granular import PairProperties
    from wheelsoil.soillab import PlateSpec, mean_curve, plate_test

    pair = PairProperties(restitution=0.5, static_friction=friction, rolling_friction=rolling, rolling_model="epsd")
    spec = PlateSpec(diameter=0.05, speed=0.1, max_sinkage=0.015, sample_interval=0.001)
    result = plate_test(small_bed(seed=seed, pair=pair, wall_pair=pair), spec, cache_dir=bed_cache)
    force, _, _ = mean_curve([result.curve], np.asarray(TWIN_SINKAGES))
    return force / result.curve.area


def test_the_calibration_recovers_the_particles_that_made_the_measurement(bed_cache):
    """The calibration's loop on small beds (``docs/soillab_calibration.py`` runs it on the lab's box, 15 min a
    candidate): the plate curve of known particles, pressed on seeds 1 and 2 and averaged (as the calibration takes
    the mean of the sand's trials), is the measurement; three candidates, the known particles among them, are
    pressed on seed 0 and scored by the calibration's own objective (``wheelsoil.soillab.objective``: the plates'
    mean squared log-pressure error; the repose term held equal, at the sand's angle, so the plates alone choose).
    The choice (``objective.best``) must be the known particles.

    First written (2026-12-07) to compare each measurement seed alone at 3, 5 and 7 mm of an 8 mm press; it chose the
    strong candidate for seed 2: within a grain of first contact the same particles carried 12.3 kPa on seed 1 and
    5.8 on seed 2 at 3 mm, more than the candidates differ (the near-surface step the lab's README describes). The
    comparison moved past it, to 8-14 mm of a 15 mm press, with the seeds' mean; candidates and rule unchanged."""
    from wheelsoil.parameters import cmu_k10
    from wheelsoil.soillab.objective import best

    candidates = {c: _twin_plate_pressure(bed_cache, *c, seed=0) for c in TWIN_CANDIDATES}
    seeds = [_twin_plate_pressure(bed_cache, *TWIN_TRUTH, seed=seed) for seed in (1, 2)]
    measured = np.mean(seeds, axis=0)
    rows = [{"friction": mu, "rolling_friction": mu_r, "repose_deg": cmu_k10.ANGLE_OF_REPOSE,
             "plates": {"0.05": {"simulated_Pa": list(p), "measured_Pa": list(measured)}}}
            for (mu, mu_r), p in candidates.items()]
    chosen = best(rows)
    print(f"measured (seeds 1, 2) {[np.round(p / 1e3, 2) for p in seeds]} kPa; "
          + "; ".join(f"{c}: {np.round(p / 1e3, 2)} kPa" for c, p in candidates.items())
          + f"; chosen {chosen['friction'], chosen['rolling_friction']} (objective {chosen['objective']:.3f})")
    assert (chosen["friction"], chosen["rolling_friction"]) == TWIN_TRUTH
