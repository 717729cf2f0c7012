"""The single-wheel testbed at a tiny scale: force balance, signs, no particle inside the wheel, bad input."""

import json
from dataclasses import replace

import numpy as np
import pytest

from wheelsoil.cases import build
from wheelsoil.cases.schema import load_case
from wheelsoil.coupling.surface import ContactSurface
from wheelsoil.coupling.testbed import Testbed
from wheelsoil.coupling.rig import DriveStage, TestbedSpec, check_fits, plan_rig
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.granular import prepare_bed

#: The mini case (preset ``mini-1g-steer``): a small flexible wheel (r = 0.15 m, b = 0.1 m, 8 grousers) of the
#: seed-004 wheel material, and its bin of 10-15 mm particles, here static (the preset's is periodic: a moving patch)
#: so that these tests see the plain testbed; one definition, the preset's.
MINI_CASE = load_case("mini-1g-steer")
MINI_WHEEL = build.wheel_geometry(MINI_CASE)
MINI_BED = replace(build.bed_spec(MINI_CASE), periodic=False)
MINI_RUN = TestbedSpec(slip=0.3, slip_angle=10.0, load=80.0, angular_velocity=2.0, settle_time=0.05,
                       drive_time=0.3, average_time=0.1, stop_when_steady=False)


@pytest.fixture(scope="module")
def mini_bed(bed_cache):
    return prepare_bed(MINI_BED, cache_dir=bed_cache)


@pytest.fixture(scope="module")
def steering_run(mini_bed):
    bench = Testbed(mini_bed, MINI_WHEEL, MINI_RUN)
    return bench, bench.run()


def test_steady_state_force_balance_and_signs(steering_run):
    bench, result = steering_run
    s = result.summary
    w = MINI_RUN.load
    # the axle is free vertically under W: in steady state the soil carries W
    assert s.vertical_force.mean == pytest.approx(w, rel=0.15)
    # the rig commands slip and slip angle exactly (the hub's); the tread's are measured and recorded beside them
    assert s.slip.mean == pytest.approx(0.3, abs=1e-9)
    assert s.slip_angle.mean == pytest.approx(10.0, abs=1e-9)
    assert s.commanded_slip == 0.3 and np.isfinite(s.tread_slip.mean)
    # a 0.3 s drive of a winding-up wheel is not a steady state, and the summary says why
    assert not s.steady and s.reasons
    # a driven wheel at 30 % slip pulls and needs torque; the soil resists the lateral slip (v_y > 0)
    assert s.drawbar_pull.mean > 0.0
    assert s.torque.mean > 0.0
    assert s.lateral_force.mean < 0.0
    assert 0.0 < s.sinkage.mean < 0.5 * MINI_WHEEL.radius
    # series are complete and finite
    n = len(result.series["t"])
    assert all(len(v) == n and np.all(np.isfinite(v)) for v in result.series.values())
    assert result.info["fe_substeps"] >= result.info["dem_steps"]


def test_the_vertical_force_balance_closes_to_round_off_at_every_sample(steering_run):
    """Issue 35 item 1: the flexible wheel's momentum changes by the impulses the record holds (the soil's force as
    the sub-steps applied it, the rig's load, the slide's damper and reaction, the structural damping, the weight),
    at every sample of every phase -- lowered at a held speed, released, spun up, driven -- to round-off; the summary
    gives the residual's mean, and the force the wheel integrated beside the one the contact reported."""
    bench, result = steering_run
    s, w, weight = result.series, MINI_RUN.load, bench.wheel_mass * bench.gravity
    assert np.abs(s["balance_residual"]).max() < 1e-9 * w
    lowering = s["slide_reaction"] != 0.0  # the slide held while the wheel is lowered: its reaction is recorded
    assert lowering[0] and not lowering[-1]
    assert np.allclose(s["rig_load"][~lowering], -(w - weight), rtol=1e-12)  # W - m g down once released
    assert np.allclose(s["weight"], -weight, rtol=1e-12)
    assert np.any(s["structural_damping"] != 0.0)  # a flexible wheel's damping has a resultant
    assert abs(result.summary.balance_residual.mean) < 1e-9 * w
    # the soil's force as the wheel integrated it is the reported one to within a fraction of a per cent here
    assert result.summary.vertical_force_applied.mean == pytest.approx(result.summary.vertical_force.mean, rel=0.01)


def test_no_particle_inside_the_wheel(steering_run):
    bench, result = steering_run
    surface = ContactSurface.from_mesh(bench.mesh)
    x, r = result.final_particles["position"], result.final_particles["radius"]
    hub = bench.structure.hub_position
    near = np.linalg.norm(x - hub, axis=1) < MINI_WHEEL.radius + MINI_WHEEL.grouser_height + 0.02
    dist, facet = surface.closest_distance(x[near], result.final_wheel_nodes)
    # every centre stays outside the shell by most of its radius (overlaps are a small fraction of r)
    assert np.all(dist > 0.5 * r[near] + surface.half_thickness[facet])


def test_render_of_the_last_state_shows_wheel_and_soil(steering_run, tmp_path):
    import matplotlib.image as mpimg

    from wheelsoil.cases.render import render_testbed

    _, result = steering_run
    img = mpimg.imread(render_testbed(result, tmp_path / "final.png", size=(320, 240)))[..., :3]
    assert img.shape[:2] == (240, 320)
    # steel-grey wheel (equal channels, mid grey) and coloured particles both cover a visible area
    grey = (np.ptp(img, axis=2) < 0.06) & (img.mean(axis=2) > 0.3) & (img.mean(axis=2) < 0.8)
    coloured = np.ptp(img, axis=2) > 0.15
    assert grey.mean() > 0.005
    assert coloured.mean() > 0.05


@pytest.mark.slow  # a 28 s run; the fast tier keeps the flexible wheel's tread-slip checks
def test_rigid_wheel_tread_turns_with_the_hub(mini_bed):
    """A rigid wheel cannot wind up: its tread slip and slip angle are the commanded ones, to round-off."""
    bench = Testbed(mini_bed, MINI_WHEEL, replace(MINI_RUN, rigid=True, drive_time=0.15, average_time=0.05))
    result = bench.run()
    drive = result.series["t"] > result.info["t_wind_up"] + 0.01
    assert np.abs(result.series["wind_up"]).max() < 1e-9
    assert np.allclose(result.series["tread_slip"][drive], 0.3, atol=1e-6)
    assert np.allclose(result.series["tread_slip_angle"][drive], 10.0, atol=1e-6)
    # its force balance closes too, with no structural damping
    assert np.abs(result.series["balance_residual"]).max() < 1e-9 * MINI_RUN.load
    assert np.all(result.series["structural_damping"] == 0.0)


@pytest.mark.slow  # three 30 s runs
@pytest.mark.parametrize("slip, beta", [(-1.0, 0.0), (-0.5, 0.0), (0.5, 90.0)])
def test_braking_dragged_and_sideways_wheels_follow_the_rigs_convention(mini_bed, bed_cache, slip, beta):
    """The measured rigs' convention (architecture; the CMU rig's README), slip taken against the carriage's
    whole speed: braking, the carriage travels at r omega_0 and the hub spins at (1 + i) omega_0, so i = -1 is a
    wheel dragged without turning; at 90 deg the wheel ploughs sideways. A rigid wheel's measured hub and tread
    slips are the commanded one and its slip angle the commanded; the soil resists the travel: a braked or
    dragged wheel has drawbar pull < 0, the dragged wheel's rig holds it against the soil's turning moment
    (torque < 0), and the sideways wheel's lateral force opposes its travel (< 0)."""
    # Ploughing sideways, the wheel's 0.3 m rim spans most of the 0.25 m bin across its heading. Once the bed's
    # stored contact history got its signs right (bed format 4), a grain left the domain at 0.54-0.6 s, in a
    # walled or a periodic bin and at a DEM step of 2.5e-5 s as well. With the old, wrong signs it happened to pass.
    # The likely cause, a grain squeezed between the rim and a side wall, is not yet shown. The sideways case runs
    # in a bin wide enough for the rim (0.45 m), where it passes.
    bed = mini_bed if beta != 90.0 else prepare_bed(replace(MINI_BED, width=0.45), cache_dir=bed_cache)
    bench = Testbed(bed, MINI_WHEEL, replace(MINI_RUN, rigid=True, slip=slip, slip_angle=beta, slip_speed="travel",
                                             windup="none", drive_time=0.15, average_time=0.05))
    result = bench.run()
    drive = result.series["t"] > result.info["t_wind_up"] + 0.01
    r, omega0 = MINI_WHEEL.radius, MINI_RUN.angular_velocity
    spin, speed = (omega0, (1.0 - slip) * r * omega0) if slip >= 0 else ((1.0 + slip) * omega0, r * omega0)
    assert np.allclose(result.series["omega"][drive], spin, atol=1e-9)
    assert bench.travel_speed == pytest.approx(speed)
    for q in ("slip", "tread_slip"):
        assert np.allclose(result.series[q][drive], slip, atol=1e-6), q
    assert np.allclose(result.series["slip_angle"][drive], beta, atol=1e-6)
    s = result.summary
    if slip < 0.0:
        assert s.drawbar_pull.mean < 0.0
    if slip == -1.0:
        assert s.torque.mean < 0.0
    if beta == 90.0:
        assert s.lateral_force.mean < 0.0


@pytest.mark.parametrize(
    "change, key",
    [
        (dict(slip=1.0), "slip"),
        (dict(slip=-1.5), "slip"),
        (dict(slip_angle=90.0), "slip_angle"),
        (dict(slip_angle=-95.0), "slip_angle"),
        (dict(slip_angle=-90.0, slip_speed="travel"), "slip_angle"),
        (dict(slip_speed="sideways"), "slip_speed"),
        (dict(load=0.0), "load"),
        (dict(load=-10.0), "load"),
        (dict(angular_velocity=0.0), "angular_velocity"),
        (dict(drive_time=float("nan")), "drive_time"),
        (dict(axle_damping=-1.0), "axle_damping"),
        (dict(average_time=0.5), "average_time"),
        (dict(windup="fast"), "windup"),
        (dict(max_wind_up=2.0), "max_wind_up"),
        (dict(slip_tolerance=0.0), "slip_tolerance"),
    ],
)
def test_bad_rig_settings_name_the_key_value_and_range(change, key):
    with pytest.raises(WheelsoilInputError, match=rf"testbed {key} = .* allowed"):
        replace(MINI_RUN, **change)


@pytest.mark.parametrize("slip, beta, reference, spin, speed", [
    (0.5, 60.0, "travel", 2.0, 0.15),           # the CMU rig at 60 deg: rim 2 x carriage is i = 0.5
    (0.5, 60.0, "heading", 2.0, 0.3),           # the architecture's: v_x = 0.15 along the heading, 0.3 along the bin
    (-0.5, 0.0, "travel", 1.0, 0.3),            # braking: carriage at r omega_0, hub at half of omega_0
    (-1.0, 90.0, "travel", 0.0, 0.3),           # dragged sideways
    (0.9, 90.0, "travel", 2.0, 0.03),           # ploughing sideways at the CMU's highest slip
])
def test_the_carriage_and_hub_give_the_commanded_slip_against_the_named_speed(slip, beta, reference, spin, speed):
    from wheelsoil.coupling.kinematics import longitudinal_slip, slip_angle_deg
    from wheelsoil.coupling.rig import carriage_speed

    spec = replace(MINI_RUN, slip=slip, slip_angle=beta, slip_speed=reference)
    hub_spin, along_bin = carriage_speed(spec, MINI_WHEEL.radius)
    assert (hub_spin, along_bin) == (pytest.approx(spin), pytest.approx(speed))
    # the wheel yawed by -beta: the carriage's velocity in the wheel frame, in components
    b = np.radians(beta)
    v_x, v_y = along_bin * np.cos(b), along_bin * np.sin(b)
    v = np.hypot(v_x, v_y) if reference == "travel" else v_x
    assert longitudinal_slip(v, hub_spin, MINI_WHEEL.radius) == pytest.approx(slip, abs=1e-12)
    assert slip_angle_deg([v_x, v_y, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]) == pytest.approx(beta)


def test_wheel_wider_than_the_bin_short_bin_and_missing_bed_are_refused(mini_bed, tmp_path):
    with pytest.raises(WheelsoilInputError, match="does not fit the bed width"):
        Testbed(mini_bed, replace(MINI_WHEEL, width=0.3), MINI_RUN)
    with pytest.raises(WheelsoilInputError, match="does not fit the bed width"):
        Testbed(mini_bed, replace(MINI_WHEEL, width=0.2), replace(MINI_RUN, slip_angle=30.0))
    with pytest.raises(WheelsoilInputError, match=r"too short for test.drive_time = 5.0 s.*periodic bed"):
        Testbed(mini_bed, MINI_WHEEL, replace(MINI_RUN, drive_time=5.0))
    with pytest.raises(WheelsoilInputError, match="does not exist"):
        Testbed(tmp_path / "missing.h5", MINI_WHEEL, MINI_RUN)


def test_a_testbed_from_a_checked_plan_is_the_one_from_wheel_and_spec(mini_bed):
    """A plan (plan_rig) carries the fit checks' result, so the testbed made from it checks nothing again and starts
    where the one made from wheel and spec starts; a plan made for another bed, or with a wheel beside it, is refused."""
    plan = plan_rig(mini_bed.spec, MINI_WHEEL, MINI_RUN)
    assert plan.start_x == check_fits(mini_bed.spec, MINI_WHEEL, MINI_RUN)
    direct, planned = Testbed(mini_bed, MINI_WHEEL, MINI_RUN), Testbed(mini_bed, plan=plan)
    assert (planned.wheel, planned.spec, planned.start_x) == (direct.wheel, direct.spec, direct.start_x)
    assert np.array_equal(planned.mesh.nodes, direct.mesh.nodes)
    with pytest.raises(WheelsoilInputError, match="not the one the plan was made for"):
        Testbed(mini_bed, plan=plan_rig(replace(MINI_BED, seed=MINI_BED.seed + 1), MINI_WHEEL, MINI_RUN))
    with pytest.raises(WheelsoilInputError, match="either a plan or a wheel and spec"):
        Testbed(mini_bed, MINI_WHEEL, plan=plan)


def _mean_and_error(result, name, blocks=4, window=None):
    """Steady mean and its standard error from block means (the series is correlated in time), over the summary's
    window from its start on, or over ``window`` (t0, t1] [s]."""
    t, (t0, t1) = result.series["t"], window or (result.summary.window[0], np.inf)
    y = result.series[name][(t >= t0) & (t <= t1)]
    means = np.array([b.mean() for b in np.array_split(y, blocks)])
    return means.mean(), means.std(ddof=1) / np.sqrt(blocks)


@pytest.mark.slow
def test_drawbar_pull_and_torque_rise_with_slip(mini_bed):
    """Straight driving at slip 0.1 and 0.6: more slip mobilises more shear, so DP and torque rise
    (seed 004 Figs. 7--8; Wong--Reece/Janosi shear grows with slip). The difference must exceed three
    combined standard errors of the steady means.

    The means are over one whole grouser pitch (45 deg of the mini wheel: 0.39 s at 2 rad/s): over a part of
    a pitch the mean depends on where the grousers stood (a 0.1 s window gave torque rises of 2.6 to 3.8 such
    errors on two packings of the same bed), and the block errors within the pitch count the grousers' pattern
    as noise, which errs on the safe side. Over the packings of bed seeds 0-2 (2026-11-26)
    the rises were 1.2-3.4 times the threshold."""
    run = replace(MINI_RUN, slip_angle=0.0, windup="none", drive_time=0.5, average_time=_PITCH_TIME)
    runs = {i: Testbed(mini_bed, MINI_WHEEL, replace(run, slip=i)).run() for i in (0.1, 0.6)}
    for q in ("drawbar_pull", "torque"):
        (lo, e_lo), (hi, e_hi) = (_mean_and_error(runs[i], q) for i in (0.1, 0.6))
        assert hi - lo > 3.0 * np.hypot(e_lo, e_hi), (q, lo, e_lo, hi, e_hi)


@pytest.mark.slow  # about 2.6 s simulated, and its last 0.8 s again: about 8 minutes on 2 cores
def test_a_slip_ramp_drives_each_stage_at_its_slip_and_resumes_inside_a_later_stage(mini_bed, bed_cache):
    """One run of two stages, slip 0.1 then 0.6 (``TestbedSpec.stages``; on the periodic bin, whose moving patch
    holds both drives): each stage's summary is at its own commanded slip, the hub's slip over its window is that
    slip, DP and torque rise from the first stage to the second by more than three combined standard errors (the
    two-run check above, in one run, here over two pitches: over one, the first try's torque rose by 2.2 such errors
    only, 1.39 N m at an error of 0.56 on the second stage), and a run restored from a state taken in the second stage
    continues bit for bit (the protocol's step and stage come back with it)."""
    bed = prepare_bed(replace(MINI_BED, periodic=True), cache_dir=bed_cache)
    spec = replace(MINI_RUN, slip=0.1, slip_angle=0.0, windup="none", drive_time=1.0, average_time=2 * _PITCH_TIME,
                   stages=(DriveStage(0.6),))
    taken = {}

    def keep(bench):  # the state one pitch into the second stage's drive
        loop = bench.protocol_state
        if loop.stage == 1 and bench.phase == "drive" and bench.scene.time > loop.t_hold + _PITCH_TIME and not taken:
            taken["state"], taken["t"] = bench.state(), bench.scene.time

    result = Testbed(bed, MINI_WHEEL, spec).run(progress=True, on_sample=keep)
    assert [s.commanded_slip for s in result.stages] == [0.1, 0.6] and result.stages[-1] is result.summary
    first, second = result.stages
    assert first.window[1] < second.window[0]
    t = result.series["t"]
    for stage in result.stages:
        inside = (t > stage.window[0]) & (t <= stage.window[1])
        assert result.series["slip"][inside] == pytest.approx(stage.commanded_slip, abs=1e-9)
    assert first.tread_slip.mean < second.tread_slip.mean  # the tread follows the hub (within its wind-up)
    for q in ("drawbar_pull", "torque"):
        (lo, e_lo), (hi, e_hi) = (_mean_and_error(result, q, window=st.window) for st in (first, second))
        assert hi - lo > 3.0 * np.hypot(e_lo, e_hi), (q, lo, e_lo, hi, e_hi)
    resumed = Testbed(bed, MINI_WHEEL, spec)
    resumed.restore_state(taken["state"])
    assert resumed.stage_spec.slip == 0.6 and resumed.phase == "drive"
    again = resumed.run()
    for name in result.series:
        np.testing.assert_array_equal(again.series[name], result.series[name], err_msg=name)
    assert json.dumps([s.to_dict() for s in again.stages]) == json.dumps([s.to_dict() for s in result.stages])


#: One grouser pitch of the mini wheel at its test spin [s] (and a little more, so the window holds it whole).
_PITCH_TIME = 1.02 * (2.0 * np.pi / MINI_WHEEL.grouser_count) / MINI_RUN.angular_velocity


def test_the_soil_domain_holds_grains_carried_over_the_wheel_top(steering_run):
    """Grains ride up in the grouser pockets: the soil's domain reaches above the standing wheel's top, so one
    carried over it is not taken for a blown-up run."""
    bench, _ = steering_run
    surface = bench.bed.surface_height
    top = surface + 2.0 * (MINI_WHEEL.radius + MINI_WHEEL.grouser_height)
    assert bench.scene.domain_max[2] >= top + 0.1 - 1e-9


@pytest.mark.parametrize("grousers, spokes, rows, period, batch", [
    (24, 12, (0.0, 0.0), 30.0, 30.0),   # seed 004's wheel: the spokes' pitch is two grouser pitches
    (8, 6, (0.0,), 180.0, 45.0),        # the mini wheel: grousers and spokes meet again after 180 deg
    (0, 12, (0.0,), 30.0, 30.0),        # smooth: the spokes alone
    (12, 12, (0.0, 15.0), 30.0, 30.0),  # two rows staggered by half a pitch: spokes every 15 deg
    (24, 12, (0.0, 10.0), 30.0, 30.0),  # staggered by 10 deg: the spoke layout repeats every 30 deg only
    (7, 5, (0.0,), 360.0, 360.0 / 7),   # nothing in common: one whole turn
])
def test_the_wheel_period_maps_grousers_and_spokes_onto_themselves(grousers, spokes, rows, period, batch):
    """wheel_period is 360 deg / gcd(grousers, spokes around); the statistics' batch is the period when one
    pitch is a multiple of the other, else the grouser pitch, and always divides the period."""
    from wheelsoil.coupling.rig import batches_per_period, statistics_pitch, wheel_period
    from wheelsoil.flexwheel.geometry import SpokeRow

    n = len(rows)
    from wheelsoil.flexwheel.geometry import LUNAR_ROVER

    wheel = replace(LUNAR_ROVER, grouser_count=grousers, spokes_per_row=spokes,
                    spoke_rows=tuple(SpokeRow(y_min=-0.5 + k / n, y_max=-0.5 + (k + 1) / n, angle=a)
                                     for k, a in enumerate(rows)))
    assert np.degrees(wheel_period(wheel)) == pytest.approx(period)
    assert np.degrees(statistics_pitch(wheel)) == pytest.approx(batch)
    ratio = wheel_period(wheel) / statistics_pitch(wheel)
    assert ratio == pytest.approx(round(ratio))
    assert batches_per_period(wheel) == round(period / batch)
