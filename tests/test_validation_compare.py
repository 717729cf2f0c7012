"""DEM-FEM results as the model (validation/compare.py): measured and simulated tests paired condition by condition."""

import numpy as np
import pandas as pd
import pytest

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.validation.compare import compare, match_conditions
from wheelsoil.validation.measured import load_sweep_summary
from wheelsoil.validation.synthetic import conditions, synthetic_measurements


def _as_sweep_summary(m, path, *, offset=0.0, rows=None):
    """Write measurements in the layout of a wheelsoil sweep's summary.csv (the simulated side)."""
    rows = np.arange(len(m)) if rows is None else rows
    table = {"slip_set": m.slip[rows], "slip_angle_set": m.slip_angle[rows], "load_set": m.load[rows],
             "gravity": m.gravity[rows], "wheel_radius": m.radius[rows], "wheel_width": m.width[rows],
             "grouser_count": m.grouser_count[rows], "grouser_height": m.grouser_height[rows]}
    for q, src in (("drawbar_pull", "drawbar_pull"), ("lateral_force", "lateral_force"), ("sinkage", "tread_sinkage"),
                   ("torque", "torque")):
        table[f"{src}_mean"] = m.responses[q][rows] + (offset if q == "drawbar_pull" else 0.0)
        table[f"{src}_std"] = np.full(len(rows), 0.5)
    path.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(table).to_csv(path / "summary.csv", index=False)
    return load_sweep_summary(path)


def _cond(**kw):
    return conditions(slips=(0.1, 0.3, 0.5), slip_angles=(0.0, 15.0, 30.0), loads=(60.0, 120.0), gravities=(9.81,),
                      passes=(1,), **kw)


def test_pairs_follow_the_conditions_and_an_offset_is_measured_exactly(tmp_path):
    measured = synthetic_measurements({}, np.random.default_rng(0), cond=_cond())
    measured.std.update({q: np.full(len(measured), 0.3) for q in ("torque", "sinkage")})  # as a rig states them
    # the simulation ran every other condition, in reverse order, 7 N too high in drawbar pull
    rows = np.arange(len(measured))[::2][::-1]
    sim = _as_sweep_summary(measured, tmp_path / "sweep", offset=7.0, rows=rows)
    pairs, unmatched = match_conditions(measured, sim)
    assert len(pairs) == len(rows) and len(unmatched) == len(measured) - len(rows)
    np.testing.assert_array_equal(rows[pairs[:, 1]], pairs[:, 0])
    c = compare(measured, sim)
    assert c.responses["drawbar_pull"]["bias"] == pytest.approx(7.0, rel=1e-9)
    assert c.responses["drawbar_pull"]["rmse"] == pytest.approx(7.0, rel=1e-9)
    for q in ("lateral_force", "torque", "sinkage"):
        assert c.responses[q]["rmse"] == pytest.approx(0.0, abs=1e-9)
    assert c.responses["torque"]["within_2sigma"] == 1.0
    assert c.responses["drawbar_pull"]["within_2sigma"] is None  # no measured std given for it
    # normalised by the spread of every measured row, as the semi-empirical model is, not of the paired half only
    assert c.responses["drawbar_pull"]["spread"] == pytest.approx(np.std(measured.responses["drawbar_pull"]), rel=1e-12)
    assert c.responses["drawbar_pull"]["nbias"] == pytest.approx(7.0 / np.std(measured.responses["drawbar_pull"]))
    # a response measured without a standard deviation (the CMU trials' sinkage) is not judged within 2 sigma on the
    # simulation's fluctuation alone: it says so (None, "–" in the report)
    assert c.responses["sinkage"]["within_2sigma"] == 1.0
    measured.std["sinkage"] = np.full(len(measured), np.nan)
    c = compare(measured, sim)
    assert c.responses["sinkage"]["within_2sigma"] is None and c.responses["torque"]["within_2sigma"] == 1.0


def test_a_simulation_missing_a_mechanism_shows_a_systematic_trend(tmp_path):
    """The simulation is the classical model; the measurements carry a sidewall resistance that grows with the
    steering angle: the lateral-force residual must trend with the slip angle, and only there."""
    cond = _cond()
    measured = synthetic_measurements({"sidewall_scale": 3.0}, np.random.default_rng(1), cond=cond, noise=0.01,
                                      relative_noise=0.01)
    sim = _as_sweep_summary(synthetic_measurements({}, np.random.default_rng(2), cond=cond, noise=0.0,
                                                   relative_noise=0.0), tmp_path / "sweep")
    c = compare(measured, sim)
    top = c.systematic[0]
    assert (top["response"], top["condition"]) == ("lateral_force", "slip_angle")
    assert abs(top["spearman"]) > 0.8


def test_no_matching_condition_is_refused_with_both_sides_named(tmp_path):
    measured = synthetic_measurements({}, np.random.default_rng(0), cond=_cond())
    sim = _as_sweep_summary(measured, tmp_path / "sweep")
    sim.radius = sim.radius * 4.0
    with pytest.raises(WheelsoilInputError, match=r"no measured condition .* it ran \[\(0\.6"):
        compare(measured, sim)


def test_cli_model_sweep_report(tmp_path):
    from wheelsoil.cases.cli import EXIT_OK, main
    from wheelsoil.validation.measured import save_measurements

    measured = synthetic_measurements({}, np.random.default_rng(0), cond=_cond())
    csv = save_measurements(measured, tmp_path / "measured.csv")
    _as_sweep_summary(measured, tmp_path / "sweep", offset=3.0)
    out = tmp_path / "rep"
    assert main(["validate", str(csv), "--model", str(tmp_path / "sweep"), "--report", str(out)]) == EXIT_OK
    text = (out / "report.md").read_text()
    assert "18 measured conditions have a simulated run" in text and "| drawbar_pull | 18 | +3 N |" in text
    assert (out / "measured_vs_simulated.png").stat().st_size > 1000


def test_a_run_with_the_rigs_slip_pairs_with_the_trial_at_the_same_heading_slip(tmp_path):
    """A case run with ``test.slip_speed = "travel"`` (the CMU rig's slip) is read along the heading, as the CMU
    loader reads the rig's rows; heading-convention runs are kept as they are."""
    from wheelsoil.slip import heading_slip_from_travel

    path = tmp_path / "sweep"
    path.mkdir()
    table = {"slip_set": [0.5, 0.5, -0.5], "slip_angle_set": [60.0, 60.0, 30.0], "slip_speed": ["travel", "heading",
                                                                                               "travel"],
             "load_set": [25.0] * 3, "gravity": [9.81] * 3, "wheel_radius": [0.058] * 3, "wheel_width": [0.05] * 3,
             "grouser_count": [0] * 3, "grouser_height": [0.0] * 3}
    for src in ("drawbar_pull", "lateral_force", "tread_sinkage", "torque"):
        table[f"{src}_mean"], table[f"{src}_std"] = [1.0] * 3, [0.1] * 3
    pd.DataFrame(table).to_csv(path / "summary.csv", index=False)
    sim = load_sweep_summary(path)
    np.testing.assert_allclose(sim.slip, [0.75, 0.5, heading_slip_from_travel(-0.5, 30.0)])


def test_the_report_splits_the_residual_by_steering_angle(tmp_path):
    """An offset only at 30 deg shows in the 30 deg row of the report's table and in no other angle's."""
    from wheelsoil.validation.compare import write_comparison_report

    measured = synthetic_measurements({}, np.random.default_rng(1), cond=_cond())
    sim = _as_sweep_summary(measured, tmp_path / "sweep")
    sim.responses["drawbar_pull"] = sim.responses["drawbar_pull"] + np.where(sim.slip_angle == 30.0, 5.0, 0.0)
    f = write_comparison_report(compare(measured, sim), measured, sim, tmp_path / "report")
    rows = {(g["group"], g["response"]): g["simulation"] for g in f["residuals_by_group"]}
    spread = f["responses"]["drawbar_pull"]["spread"]
    assert rows[("30", "drawbar_pull")]["bias"] == pytest.approx(5.0 / spread, rel=1e-9)
    assert rows[("0", "drawbar_pull")]["bias"] == pytest.approx(0.0, abs=1e-12)
    # kinds by the slip against the travel speed: at 30 deg a heading slip of 0.1 turns slower than it travels
    driving = measured.kinds() == "driving"
    share = np.mean(measured.slip_angle[driving] == 30.0)
    assert rows[("driving", "drawbar_pull")]["bias"] == pytest.approx(5.0 / spread * share, rel=1e-9)
    assert "| 30° | drawbar_pull |" in (tmp_path / "report" / "report.md").read_text()


def test_a_run_without_a_steady_state_is_left_out_and_named(tmp_path):
    """A run whose steady detector found no steady window reports no number: the sweep loader drops it and says so;
    a sweep with no steady run is refused."""
    measured = synthetic_measurements({}, np.random.default_rng(0), cond=_cond())
    sim = _as_sweep_summary(measured, tmp_path / "sweep")
    table = pd.read_csv(tmp_path / "sweep" / "summary.csv")
    table["case"] = [f"case-{k}" for k in range(len(table))]
    table["steady"] = [k != 3 for k in range(len(table))]
    table.to_csv(tmp_path / "sweep" / "summary.csv", index=False)
    kept = load_sweep_summary(tmp_path / "sweep")
    assert len(kept) == len(sim) - 1 and "1 not steady, left out: case-3" in kept.notes
    np.testing.assert_array_equal(kept.slip, np.delete(sim.slip, 3))
    table.drop(columns="case").to_csv(tmp_path / "sweep" / "summary.csv", index=False)  # no names: rows are named
    assert "left out: row 3" in load_sweep_summary(tmp_path / "sweep").notes
    table["steady"] = False
    table.to_csv(tmp_path / "sweep" / "summary.csv", index=False)
    with pytest.raises(WheelsoilInputError, match="none of its 18 runs reached a steady state"):
        load_sweep_summary(tmp_path / "sweep")


def test_a_run_that_twins_no_measured_condition_is_refused_unless_allowed(tmp_path, capsys):
    """validate --model: a run at a load no trial has (a typo in a twin's sweep) is refused before any report,
    named with its conditions; a second run of a measured condition (a replica) is not an orphan;
    --allow-unpaired-runs leaves the orphan out."""
    from wheelsoil.cases.cli import EXIT_OK, main
    from wheelsoil.validation.compare import unpaired_runs
    from wheelsoil.validation.measured import save_measurements

    measured = synthetic_measurements({}, np.random.default_rng(0), cond=_cond())
    csv = save_measurements(measured, tmp_path / "measured.csv")
    rows = np.r_[np.arange(len(measured)), 0]  # every condition, the first twice
    sim = _as_sweep_summary(measured, tmp_path / "sweep", rows=rows)
    assert unpaired_runs(measured, sim).size == 0
    table = pd.read_csv(tmp_path / "sweep" / "summary.csv")
    table.loc[3, "load_set"] = 97.0  # no trial at 97 N
    table.to_csv(tmp_path / "sweep" / "summary.csv", index=False)
    out = tmp_path / "rep"
    assert main(["validate", str(csv), "--model", str(tmp_path / "sweep"), "--report", str(out)]) != EXIT_OK
    err = capsys.readouterr().err
    assert "1 of the 19 runs" in err and "run 3:" in err and "load 97 N" in err and not (out / "report.md").exists()
    assert main(["validate", str(csv), "--model", str(tmp_path / "sweep"), "--report", str(out),
                 "--allow-unpaired-runs"]) == EXIT_OK
    assert (out / "report.md").is_file()


def test_at_90_degrees_a_run_pairs_only_with_the_trial_at_its_travel_slip(measured_dir):
    """At 90 deg the heading slip is +-1 at every rim speed, so a twin run of the CMU grousered wheel driving at travel
    slip 0.5 must pair with the trial at 0.5 and not with one at free rolling whose load happens to be within 1 %."""
    from pathlib import Path

    from wheelsoil.validation.compare import match_conditions
    from wheelsoil.validation.measured import load_cmu_trials

    data = load_cmu_trials(Path(measured_dir) / "cmu_3d_terramechanics")
    at90 = np.flatnonzero((data.grouser_height > 0) & (data.slip_angle == 90.0))
    assert len(np.unique(data.slip[at90])) <= 3  # the heading slip cannot tell the trials apart
    k = int(at90[np.argmin(np.abs(data.travel_slip[at90] - 0.5))])
    sim = data.select(np.arange(len(data)) == k)
    for other in at90[np.abs(data.travel_slip[at90] - 0.5) > 0.05]:  # the other 90 deg trials, at this run's load
        probe = data.select(np.arange(len(data)) == other)
        probe.load = sim.load.copy()
        pairs, _ = match_conditions(probe, sim)
        assert len(pairs) == 0, f"trial at travel slip {data.travel_slip[other]:.3f} paired with the run at 0.5"
    pairs, _ = match_conditions(data, sim)
    assert k in pairs[:, 0] and np.all(np.abs(data.travel_slip[pairs[:, 0]] - data.travel_slip[k]) <= 0.01)


def test_several_sweeps_are_one_model(tmp_path):
    """``--model A B``: the runs of two sweeps taken together compare as one sweep holding both would (the pairs and
    every statistic); 'semi-empirical' among sweep folders is refused, naming it."""
    from wheelsoil.validation.workflow import simulated_runs

    measured = synthetic_measurements({}, np.random.default_rng(4), cond=_cond())
    rows = np.arange(len(measured))
    whole = compare(measured, _as_sweep_summary(measured, tmp_path / "all", offset=3.0, rows=rows))
    _as_sweep_summary(measured, tmp_path / "a", offset=3.0, rows=rows[::2])
    _as_sweep_summary(measured, tmp_path / "b", offset=3.0, rows=rows[1::2])
    both = simulated_runs([tmp_path / "a", tmp_path / "b"])
    assert len(both) == len(measured) and both.name == "a + b"
    split = compare(measured, both)
    assert len(split.pairs) == len(whole.pairs)
    for q, v in whole.responses.items():
        assert split.responses[q]["bias"] == pytest.approx(v["bias"], abs=1e-12)
        assert split.responses[q]["rmse"] == pytest.approx(v["rmse"], abs=1e-12)
    with pytest.raises(WheelsoilInputError, match="'semi-empirical' is a model of its own"):
        simulated_runs([tmp_path / "a", "semi-empirical"])



def test_an_error_of_one_wheel_shows_in_its_row_and_as_a_trend_with_the_wheel(tmp_path):
    """Both wheels paired (the CMU rig's grousered and smooth wheels): an offset of the grousered wheel's drawbar pull
    alone is that wheel's bias in the by-wheel table, none of the smooth one's, and a residual trend with the grouser
    height (issue 34: trends with slip, steering angle and wheel)."""
    from wheelsoil.validation.compare import write_comparison_report
    from wheelsoil.validation.synthetic import synthetic_two_wheel_measurements

    measured = synthetic_two_wheel_measurements({}, np.random.default_rng(2), cond=_cond())
    sim = _as_sweep_summary(measured, tmp_path / "sweep")
    grousered = sim.grouser_height > 0
    sim.responses["drawbar_pull"] = sim.responses["drawbar_pull"] + np.where(grousered, 6.0, 0.0)
    c = compare(measured, sim)
    trend = next(t for t in c.trends if t["response"] == "drawbar_pull" and t["condition"] == "grouser_height")
    assert trend["spearman"] > 0.85 and trend["p_value"] < 1e-6  # ranks: every grousered residual above the smooth
    f = write_comparison_report(c, measured, sim, tmp_path / "report")
    rows = {(g["by"], g["group"], g["response"]): g["simulation"] for g in f["residuals_by_group"]}
    spread = f["responses"]["drawbar_pull"]["spread"]
    height = f"{1e3 * measured.grouser_height.max():g} mm grousers"
    assert rows[("wheel", height, "drawbar_pull")]["bias"] == pytest.approx(6.0 / spread, rel=1e-9)
    assert rows[("wheel", "smooth", "drawbar_pull")]["bias"] == pytest.approx(0.0, abs=1e-12)
    assert f"| {height} | drawbar_pull |" in (tmp_path / "report" / "report.md").read_text()
    # one wheel: no wheel rows
    one = compare(measured.select(~(measured.grouser_height > 0)), sim)
    assert not any(t["condition"] == "grouser_height" for t in one.trends)


def test_the_rigs_repeats_stand_beside_the_simulations_replicas(tmp_path):
    """Three repeats of one test at their own loads (as the CMU rig's), each twinned by its own run, and a fourth
    trial at another slip: the repeats' table holds the standard deviation (ddof 1) of the measured means and of the
    simulated ones over those three, and nothing for the single trial; without repeats the report says the
    run-to-run spread is not measured."""
    from dataclasses import replace as dc_replace

    from wheelsoil.validation.compare import repeat_spreads, write_comparison_report

    base = synthetic_measurements({}, np.random.default_rng(1), cond=_cond())
    first = 0
    other = int(np.flatnonzero((base.slip != base.slip[first]) & (base.slip_angle == base.slip_angle[first]))[0])
    m = base.select(np.array([first, first, first, other]))  # three repeats of one test, and a test at another slip
    m = dc_replace(m, load=np.array([60.0, 61.5, 58.7, 60.0]), name="rig")
    m.responses["drawbar_pull"] = np.array([2.0, 3.0, 4.5, 9.0])
    sim = _as_sweep_summary(m, tmp_path / "sweep")
    sim.responses["drawbar_pull"] = np.array([8.0, 8.5, 10.0, 12.0])
    c = compare(m, sim)
    groups = repeat_spreads(c, m, sim)
    assert len(groups) == 1 and groups[0]["repeats"] == 3
    dp = groups[0]["spreads"]["drawbar_pull"]
    assert dp["measured"] == pytest.approx(np.std([2.0, 3.0, 4.5], ddof=1), rel=1e-12)
    assert dp["simulated"] == pytest.approx(np.std([8.0, 8.5, 10.0], ddof=1), rel=1e-12)
    findings = write_comparison_report(c, m, sim, tmp_path / "report")
    assert findings["repeats"] == groups
    assert "| 3 | drawbar_pull |" in (tmp_path / "report" / "report.md").read_text()
    single = m.select(np.array([0, 3]))
    c1 = compare(single, sim)
    assert repeat_spreads(c1, single, sim) == []
    write_comparison_report(c1, single, sim, tmp_path / "one")
    assert "run-to-run spread is not measured here" in (tmp_path / "one" / "report.md").read_text()
