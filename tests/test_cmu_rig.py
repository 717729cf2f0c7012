"""The CMU rig as case presets: every measured trial's steering angle and slip is a valid case of the preset of its
wheel, and the rig's command reproduces the trial's rim-to-carriage speed ratio (the lab's slip definitions);
conditions outside the rig's range are refused at the key that holds them."""

import csv
from pathlib import Path

import pytest

from wheelsoil.cases.build import specs
from wheelsoil.cases.schema import CaseError, load_case
from wheelsoil.coupling.kinematics import longitudinal_slip
from wheelsoil.coupling.rig import carriage_speed
from wheelsoil.parameters import cmu_k10


def _trials(measured_dir):
    folder = Path(measured_dir) / "cmu_3d_terramechanics"
    rows = []
    for wheel in ("smooth", "grouser"):
        with open(folder / f"{wheel}_wheel_trials.csv", newline="") as fh:
            rows += list(csv.DictReader(fh))
    return rows


def test_every_trial_is_a_case_whose_command_gives_its_rim_to_carriage_ratio(measured_dir):
    rows = _trials(measured_dir)
    assert len(rows) == 108 + 189
    presets = {w: load_case(f"cmu-{w}") for w in ("smooth", "grouser")}
    for w, case in presets.items():
        _, wheel, _ = specs(case)
        assert wheel.radius == cmu_k10.RADIUS and wheel.width == cmu_k10.WIDTH
        assert wheel.grouser_count == (cmu_k10.GROUSER_COUNT if w == "grouser" else 0)
        assert case.wheel.rigid and case.test.slip_speed == "travel"
    checked = 0
    for row in rows:
        slip, beta = float(row["slip"]), float(row["steering_angle_deg"])
        rim, carriage = float(row["rim_speed_mm_s"]), float(row["carriage_speed_mm_s"])
        # the rig's slip of a commanded 0.9 is recorded as 0.887-0.900; the range's top is open at 1
        case = load_case(f"cmu-{row['wheel']}", [f"test.slip={slip}", f"test.slip_angle={beta}",
                                                 f"test.load={float(row['vertical_load_N'])}"])
        _, wheel, test = specs(case)
        spin, speed = carriage_speed(test, wheel.radius)
        ours = wheel.radius * spin / speed
        # the lab's slip of the trial, from its definitions (driving 1 - V / (r omega), braking r omega / V - 1)
        lab = 1.0 / (1.0 - slip) if slip >= 0 else 1.0 + slip
        assert ours == pytest.approx(lab, rel=1e-12, abs=1e-12), row
        # and the slip of the nominal rim speed against the carriage's within 0.015 (the slip column comes from the
        # measured speeds, the rim speed is the commanded one), except the rows labelled 12 mm/s: their recorded
        # slips (about 0.23) say the rim ran at 13 mm/s. The twin commands the recorded slip, what validation pairs on
        nominal = longitudinal_slip(carriage, rim, 1.0)
        if rim != 12.0:
            assert nominal == pytest.approx(slip, abs=0.015), row
            checked += 1
        else:
            assert carriage / (1.0 - slip) == pytest.approx(13.0, abs=0.3) or slip < 0.2, row
    assert checked >= 0.85 * len(rows)


@pytest.mark.parametrize("override, key", [
    ("test.slip_angle=95", "test.slip_angle"),
    ("test.slip=1.0", "test.slip"),
    ("test.slip=-1.2", "test.slip"),
    ("test.slip_speed=sideways", "test.slip_speed"),
])
def test_conditions_outside_the_rigs_range_are_refused_at_their_key(override, key):
    with pytest.raises(CaseError, match=key.replace(".", r"\.")):
        load_case("cmu-grouser", [override])


def test_a_longer_drive_copies_the_one_row_it_names_and_refuses_an_ambiguous_name():
    """cmu_sweep.longer_drives: a copy of the named trial's row with the longer drive, nothing else changed; an entry
    that names no row, or more than one, is an input error naming the trial."""
    from wheelsoil.cases.cmu_sweep import longer_drives
    from wheelsoil.errors import WheelsoilInputError

    rows = [{"wheel.preset": "cmu-k10-grouser", "case.seed": 1, "test.slip": s, "test.slip_angle": a,
             "test.load": 23.0, "test.drive_time": 20.0} for a, s in ((30.0, 0.497), (75.0, 0.499), (75.0, 0.9))]
    (copy,) = longer_drives(rows, (("grouser", 75.0, 0.5, 30.0),))
    assert copy == {**rows[1], "test.drive_time": 30.0} and rows[1]["test.drive_time"] == 20.0
    assert longer_drives(rows, ()) == []
    for entry in (("grouser", 45.0, 0.5, 30.0), ("smooth", 75.0, 0.5, 30.0)):
        with pytest.raises(WheelsoilInputError, match="matches 0 rows"):
            longer_drives(rows, (entry,))
    with pytest.raises(WheelsoilInputError, match="matches 2 rows"):
        longer_drives(rows + [dict(rows[1])], (("grouser", 75.0, 0.5, 30.0),))


def test_the_trial_sweeps_are_written_from_the_data_and_pair_with_every_trial(measured_dir, tmp_path):
    """The committed sweep presets are what the generator writes from the measured files; the full sweep has one
    case per trial and the comparison (validate --model) pairs every measured trial, braking and dragged included,
    with a case at its conditions."""
    import numpy as np

    from wheelsoil.cases.cmu_sweep import write_presets
    from wheelsoil.cases.sweep import load_sweep
    from wheelsoil.validation.compare import match_conditions
    from wheelsoil.slip import heading_slip_from_travel
    from wheelsoil.validation.measured import Measurements, load_cmu_trials

    folder = Path(measured_dir) / "cmu_3d_terramechanics"
    committed = Path(__file__).parents[1] / "cases" / "presets" / "sweeps"
    for written in write_presets(folder, tmp_path):
        assert written.read_text() == (committed / written.name).read_text(), written.name
    full, part = load_sweep("cmu-trials"), load_sweep("cmu-trials-subset")
    assert (len(full.cases), len(part.cases)) == (297, 25)
    assert {c.case.case_hash() for c in part.cases} <= {c.case.case_hash() for c in full.cases}
    # the wheel candidate's sweep: its held-out angles, their longer drive, and the angles that chose it (run once
    # accepted), each one case of the full sweep's trials with the wheel closed
    closed = load_sweep("cmu-candidate-closed-wheel")
    assert sorted((c.case.test.slip_angle, c.case.test.drive_time) for c in closed.cases) == [
        (30.0, 20.0), (45.0, 20.0), (75.0, 20.0), (75.0, 30.0), (90.0, 20.0)]
    assert all(c.case.wheel.side_walls for c in closed.cases)
    # the repeats of a condition are replicas: other seeds
    seeds = {}
    for c in full.cases:
        seeds.setdefault((c.case.wheel.preset, c.case.test.slip_angle, round(c.case.test.slip, 1)), set()).add(
            c.case.case.seed)
    assert max(len(s) for s in seeds.values()) >= 3

    geometry = [specs(c.case)[1] for c in full.cases]
    n = len(full.cases)
    # the rig's slip (travel) read along the heading, as load_sweep_summary reads a travel-convention run
    assert all(c.case.test.slip_speed == "travel" for c in full.cases)
    simulated = Measurements(
        name="cmu-trials", slip=heading_slip_from_travel([c.case.test.slip for c in full.cases],
                                                         [c.case.test.slip_angle for c in full.cases]),
        slip_angle=np.array([c.case.test.slip_angle for c in full.cases]),
        load=np.array([c.case.test.load for c in full.cases]),
        gravity=np.array([-c.case.soil.gravity_vector[2] for c in full.cases]),
        radius=np.array([g.radius for g in geometry]), width=np.array([g.width for g in geometry]),
        grouser_height=np.array([g.grouser_height if g.grouser_count else 0.0 for g in geometry]),
        grouser_count=np.array([g.grouser_count for g in geometry], float), group=np.full(n, "1g"),
        responses={q: np.full(n, np.nan) for q in ("drawbar_pull", "lateral_force", "sinkage", "torque")},
        std={}, notes="conditions only",
        # and its travel slip kept, as load_sweep_summary keeps it: at 90 deg only the travel slip tells the trials apart
        travel_slip=np.array([c.case.test.slip for c in full.cases]))
    data = load_cmu_trials(folder)
    pairs, unmatched = match_conditions(data, simulated)
    assert len(data) == 297 and unmatched.size == 0 and len(pairs) == 297


@pytest.mark.parametrize("preset", ["cmu-grouser", "cmu-smooth"])
def test_the_rig_runs_on_the_calibrated_sand(preset):
    """The CMU presets hold wheelsoil.parameters.cmu_sand's particles at the wheels' scale, so the twin and the soil
    lab's calibration cannot drift apart."""
    from wheelsoil.parameters import cmu_sand

    soil = load_case(preset).soil
    pair, material = cmu_sand.PARTICLE_PAIR, cmu_sand.PARTICLE_MATERIAL
    assert (soil.static_friction, soil.rolling_friction, soil.rolling_model, soil.restitution) == (
        pair.static_friction, pair.rolling_friction, pair.rolling_model, pair.restitution)
    assert (soil.density, soil.youngs_modulus, soil.poisson_ratio) == (
        material.density, material.youngs_modulus, material.poisson_ratio)
    assert (soil.diameter_min, soil.diameter_max) == pytest.approx(cmu_sand.TWIN_DIAMETERS)


def test_a_candidate_sweep_changes_the_soil_only_and_runs_subset_trials():
    """A DEM-side candidate (issue 34 item 3) is the twin with its soil changed: every candidate case is a subset case
    (same wheel, rig and trial) on the candidate's particles, and the replicas are the same trial's other seeds."""
    from wheelsoil.cases.cmu_sweep import CANDIDATES
    from wheelsoil.cases.sweep import load_sweep
    from wheelsoil.parameters import cmu_sand

    subset = {(c.case.wheel.model_dump_json(), c.case.test.model_dump_json(), c.case.case.seed): c.case
              for c in load_sweep("cmu-trials-subset").cases}
    for name, (overrides, _) in CANDIDATES.items():
        cases = load_sweep(f"cmu-candidate-{name}").cases
        assert {c.case.test.slip_angle for c in cases} == {0.0, 45.0, 90.0}
        for c in cases:
            twin = subset[(c.case.wheel.model_dump_json(), c.case.test.model_dump_json(), c.case.case.seed)]
            changed = {k for k, v in c.case.soil.model_dump().items() if twin.soil.model_dump()[k] != v}
            assert changed == {k.split(".")[1] for k in overrides}, name
            assert all(getattr(c.case.soil, k.split(".")[1]) == v for k, v in overrides.items()), name
    plate = CANDIDATES["plate-soil"][0]
    assert (plate["soil.static_friction"], plate["soil.rolling_friction"], plate["soil.density"]) == (
        cmu_sand.PLATE_FIT_PAIR.static_friction, cmu_sand.PLATE_FIT_PAIR.rolling_friction,
        cmu_sand.PLATE_FIT_MATERIAL.density)
    scale = CANDIDATES["particle-scale"][0]
    assert (scale["soil.diameter_min"], scale["soil.diameter_max"]) == pytest.approx(
        tuple(0.8 * d for d in cmu_sand.TWIN_DIAMETERS), rel=1e-9)
    replicas = load_sweep("cmu-replicas").cases
    first = [c for c in load_sweep("cmu-trials-subset").cases
             if (c.case.test.slip_angle, round(c.case.test.slip, 1), c.case.wheel.preset) == (0.0, 0.5, "cmu-k10-grouser")]
    assert len(first) == 1 and len(replicas) >= 2
    assert {c.case.case.seed for c in replicas}.isdisjoint({first[0].case.case.seed})
    assert all(c.case.soil == first[0].case.soil and c.case.wheel == first[0].case.wheel for c in replicas)
