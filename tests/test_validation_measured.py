"""Measured-data loading: units from column names, the two shared datasets, clear errors for bad files."""

import csv
import os

import numpy as np
import pytest

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.validation.measured import load_cmu_trials, load_digitised, load_table, split_unit


def _raw(path, column):
    with open(path, newline="") as fh:
        return np.array([float(r[column]) for r in csv.DictReader(fh)])


@pytest.mark.parametrize("column, expected", [
    ("drawbar_pull_N", ("drawbar_pull", "N", 1.0)),
    ("sinkage_mm", ("sinkage", "m", 1e-3)),
    ("rim_speed_mm_s", ("rim_speed", "m/s", 1e-3)),
    ("meas_torque_nm", ("meas_torque", "N m", 1.0)),
    ("steering_angle_deg", ("steering_angle", "deg", 1.0)),
    ("slip", ("slip", None, 1.0)),
])
def test_units_come_from_the_column_suffix(column, expected):
    assert split_unit(column) == expected


def test_cmu_trials_in_si(measured_dir):
    folder = os.path.join(measured_dir, "cmu_3d_terramechanics")
    everything = load_cmu_trials(folder)
    driving = load_cmu_trials(folder, domain="driving")
    raw_sinkage = np.concatenate([_raw(os.path.join(folder, f"{w}_wheel_trials.csv"), "sinkage_mm")
                                  for w in ("grouser", "smooth")])
    np.testing.assert_allclose(everything.responses["sinkage"], raw_sinkage * 1e-3)
    assert len(everything) == len(raw_sinkage)
    assert 0 < len(driving) < len(everything)
    assert np.all((driving.slip >= 0) & (driving.slip < 1))
    assert set(np.unique(driving.group)) == {"grouser", "smooth"}
    # slip along the heading: a turning wheel at 90 deg has slip 1, outside the driving branch
    assert set(np.unique(driving.slip_angle)) >= {0.0, 30.0, 60.0} and 90.0 not in driving.slip_angle
    assert np.all(driving.load > 0) and np.all(driving.radius == 0.058)
    # the rows left out are counted by kind in the notes (the report prints them)
    for w in ("grouser", "smooth"):
        angles = _raw(os.path.join(folder, f"{w}_wheel_trials.csv"), "steering_angle_deg")
        kept = int(np.sum(driving.group == w))
        assert f"{w} wheel: {kept} of {len(angles)} rows kept" in driving.notes
        assert f"{int(np.sum(angles == 90.0))} at 90 deg" in driving.notes.split(f"{w} wheel: ")[1]
    # every row kept by default, its kind of motion from its own rim and carriage speeds, its rig slip kept as given
    rim, carriage, slip = (np.concatenate([_raw(os.path.join(folder, f"{w}_wheel_trials.csv"), c) for w in ("grouser", "smooth")])
                           for c in ("rim_speed_mm_s", "carriage_speed_mm_s", "slip"))
    kinds = everything.kinds()
    np.testing.assert_array_equal(kinds == "dragged", rim == 0.0)
    np.testing.assert_array_equal(kinds == "braking", (rim > 0.0) & (rim < 0.99 * carriage))
    np.testing.assert_allclose(everything.travel_slip, slip)
    assert "every row kept" in everything.notes and f"{int((rim == 0).sum())} dragged" not in driving.notes


def test_digitised_points_in_si(measured_dir):
    path = os.path.join(measured_dir, "digitised_single_wheel", "single_wheel_experiments.csv")
    data = load_digitised(path)
    np.testing.assert_allclose(data.responses["drawbar_pull"], _raw(path, "meas_drawbar_pull_n"))
    np.testing.assert_allclose(data.radius, _raw(path, "wheel_radius_m"))
    assert len(data) == len(_raw(path, "slip"))
    assert {g.split(":")[1] for g in data.group} == {"lug", "smooth"}


def test_bad_files_name_the_problem(tmp_path):
    with pytest.raises(WheelsoilInputError, match="does not exist"):
        load_table(tmp_path / "none.csv")
    ragged = tmp_path / "ragged.csv"
    ragged.write_text("slip,drawbar_pull_N\n0.1,3\n0.2\n")
    with pytest.raises(WheelsoilInputError, match="line 3: 1 fields, the header has 2"):
        load_table(ragged)
    text = tmp_path / "text.csv"
    text.write_text("slip,drawbar_pull_N\n0.1,three\n")
    with pytest.raises(WheelsoilInputError, match="'drawbar_pull_N' has unit N but holds 'three'"):
        load_table(text)
    missing = tmp_path / "grouser_wheel_trials.csv"
    missing.write_text("slip,drawbar_pull_N\n0.1,3\n")
    (tmp_path / "smooth_wheel_trials.csv").write_text("slip,drawbar_pull_N\n0.1,3\n")
    with pytest.raises(WheelsoilInputError, match=r"missing column\(s\) \['wheel', 'steering_angle'"):
        load_cmu_trials(tmp_path)
    header = "wheel,steering_angle_deg,slip,drawbar_pull_N,lateral_force_N,vertical_load_N,sinkage_mm\n"
    for bad, match in (("grouser,30,1.5,1,1,20,5", r"column 'slip' holds 1.5 in data row 2 .* \[-1, 1\]"),
                       ("grouser,120,0.5,1,1,20,5", r"column 'steering_angle' holds 120 deg in data row 2 .* "
                                                    r"\[-90, 90\] deg")):
        missing.write_text(header + "grouser,0,0.2,1,1,20,5\n" + bad + "\n")
        with pytest.raises(WheelsoilInputError, match=match):
            load_cmu_trials(tmp_path)
    # the rig's speeds tell a braked wheel from a dragged one: a braking row needs both, and they must agree with the slip
    speeds = "wheel,steering_angle_deg,rim_speed_mm_s,carriage_speed_mm_s,slip,drawbar_pull_N,lateral_force_N," \
             "vertical_load_N,sinkage_mm\n"
    good = "grouser,0,20,10,0.5,1,1,20,5\ngrouser,0,0,10,-1,-40,1,20,50\ngrouser,0,5,10,-0.5,-17,1,20,20\n"
    (tmp_path / "smooth_wheel_trials.csv").write_text(header + "smooth,0,0.2,1,1,20,5\n")
    missing.write_text(speeds + good)
    assert len(load_cmu_trials(tmp_path)) == 4  # the smooth file's row and the three
    for bad, match in (("grouser,0,,10,-0.5,-17,1,20,20", r"column 'rim_speed' is empty in braking data row 4 "),
                       ("grouser,0,5,,-0.5,-17,1,20,20", r"column 'carriage_speed' is empty in braking data row 4 "),
                       ("grouser,0,5,10,-1,-40,1,20,50", r"data row 4 has slip -1 with column 'rim_speed' 0.005 m/s"),
                       ("grouser,0,0,10,-0.5,-17,1,20,20", r"data row 4 has slip -0.5 with column 'rim_speed' 0 m/s")):
        missing.write_text(speeds + good + bad + "\n")
        with pytest.raises(WheelsoilInputError, match=match):
            load_cmu_trials(tmp_path)
    missing.write_text(speeds.replace("carriage_speed_mm_s,", "").replace(",10,", ",") + "grouser,0,20,0.5,1,1,20,5\n")
    with pytest.raises(WheelsoilInputError, match="has the column 'rim_speed' but not 'carriage_speed'"):
        load_cmu_trials(tmp_path)


def test_sweep_summary_reads_as_simulated_data_and_a_partial_table_is_refused(tmp_path):
    import pandas as pd

    from wheelsoil.validation.measured import SIMULATED_RESPONSES, load_measurements

    row = {"slip_set": 0.3, "slip_angle_set": 10.0, "load_set": 500.0, "gravity": 9.81 / 6, "wheel_radius": 0.6,
           "wheel_width": 0.5, "grouser_count": 24, "grouser_height": 0.02}
    for k, src in enumerate(SIMULATED_RESPONSES.values()):
        row[f"{src}_mean"], row[f"{src}_std"] = 10.0 * (k + 1), 1.0 * (k + 1)
    path = tmp_path / "summary.csv"
    pd.DataFrame([row, {**row, "gravity": 9.81, "load_set": 3000.0}]).to_csv(path, index=False)
    data = load_measurements(tmp_path)  # the sweep folder
    assert list(data.group) == ["moon", "1g"] and list(data.load) == [500.0, 3000.0]
    assert data.responses["sinkage"][0] == row["tread_sinkage_mean"]  # the rut depth, without deflection
    assert data.std["torque"][1] == row["torque_std"]
    pd.DataFrame([{k: v for k, v in row.items() if k != "wheel_radius"}]).to_csv(path, index=False)
    with pytest.raises(WheelsoilInputError, match=r"not a wheelsoil sweep summary: columns \['wheel_radius'\]"):
        load_measurements(path)


def test_wheelsoil_csv_round_trip_keeps_every_condition(tmp_path):
    """save_measurements / load_generic: conditions (pass number included), wheel and responses come back."""
    from wheelsoil.validation.measured import load_generic, save_measurements
    from wheelsoil.validation.synthetic import conditions, synthetic_measurements

    data = synthetic_measurements({}, np.random.default_rng(0), cond=conditions(slips=(0.1, 0.3), slip_angles=(0.0, 10.0)))
    back = load_generic(save_measurements(data, tmp_path / "m.csv"))
    for key in ("slip", "slip_angle", "load", "gravity", "passes", "radius", "width", "grouser_height", "grouser_count"):
        np.testing.assert_allclose(getattr(back, key), getattr(data, key), rtol=1e-9, err_msg=key)
    assert set(np.unique(back.passes)) == {1.0, 2.0, 3.0}
    for q in ("drawbar_pull", "lateral_force", "sinkage", "torque"):
        np.testing.assert_allclose(back.responses[q], data.responses[q], rtol=1e-9, err_msg=q)


def test_residuals_are_summarised_by_kind_of_motion_and_angle(measured_dir):
    """An error that lives in one branch shows in that branch's row of the report and in no other."""
    from wheelsoil.validation.residuals import residuals_by_group

    data = load_cmu_trials(os.path.join(measured_dir, "cmu_3d_terramechanics"))
    kinds = data.kinds()
    braking = (kinds == "braking").astype(float)
    rng = np.random.default_rng(3)
    noise = rng.normal(0.0, 0.01, len(data))
    rows = residuals_by_group({"classical": {"drawbar_pull": braking + noise}, "final": {"drawbar_pull": noise}}, data)
    by = {(r["by"], r["group"]): r for r in rows}
    assert by[("motion", "braking")]["classical"]["bias"] == pytest.approx(1.0, abs=0.01)
    assert abs(by[("motion", "driving")]["classical"]["bias"]) < 0.01
    assert abs(by[("motion", "braking")]["final"]["bias"]) < 0.01
    assert sum(by[("motion", k)]["rows"] for k in ("driving", "braking", "dragged")) == len(data)
    assert by[("slip_angle", "90")]["rows"] == int(np.sum(data.slip_angle == 90.0))
    # a residual growing with slip inside the driving rows shows as that group's trend
    trend = np.where(kinds == "driving", data.slip, 0.0)
    rows = residuals_by_group({"final": {"drawbar_pull": trend}}, data)
    driving = next(r for r in rows if r["group"] == "driving")
    assert driving["final"]["slip_spearman"] == pytest.approx(1.0)

