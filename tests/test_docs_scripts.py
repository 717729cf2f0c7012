"""The scripts under docs/ that regenerate the studies (issue 38 item 7): each loads, and every wheelsoil name it
imports -- at the top or inside a function, where most import the engine -- exists, so a moved or renamed name
breaks a test here instead of the next campaign. (Running them is hours of DEM each; their commands are in docs/.)"""

import ast
import importlib
import importlib.util
import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
SCRIPTS = sorted(DOCS.glob("*.py"))


def test_the_docs_have_their_scripts():
    assert len(SCRIPTS) >= 10


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_a_docs_script_loads_and_its_wheelsoil_imports_exist(script, monkeypatch):
    monkeypatch.syspath_prepend(str(DOCS))  # the scripts import their siblings, as when run from the repository root
    _load(script.stem)
    for node in ast.walk(ast.parse(script.read_text(), filename=str(script))):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("wheelsoil"):
            target = importlib.import_module(node.module)
            for alias in node.names:
                assert hasattr(target, alias.name) or importlib.util.find_spec(f"{node.module}.{alias.name}"), \
                    f"{script.name} line {node.lineno}: {node.module} has no {alias.name}"
    sys.modules.pop(f"docs_{script.stem}", None)


def _load(name: str):
    spec = importlib.util.spec_from_file_location(f"docs_{name}", DOCS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # a script's dataclasses look their module up while they are made
    spec.loader.exec_module(module)
    return module


def test_the_twin_queue_links_a_finished_run_as_a_bin_checks_reference(tmp_path):
    """The CMU twin's queue (docs/cmu_twin_queue.py) gives a convergence study the sweep's finished run of the same
    case as its reference, and nothing unfinished or already there."""
    from wheelsoil.cases.run import RESULT_NAME
    from wheelsoil.cases.schema import load_case

    queue = _load("cmu_twin_queue")
    case = DOCS / "cmu-twin" / "bin-check" / "cmu-90-driving.toml"
    digest = load_case(case).case_hash()
    runs, out = tmp_path / "runs", tmp_path / "runs" / "bin-check"
    run = runs / "some-sweep" / "cases" / digest
    run.mkdir(parents=True)
    assert queue.link_reference(runs, out, str(case)) is None  # not finished: nothing to link
    (run / RESULT_NAME).write_bytes(b"")
    assert queue.link_reference(runs, out, str(case)) == run
    assert (out / "cases" / digest).resolve() == run.resolve()
    assert queue.link_reference(runs, out, str(case)) is None  # linked before: kept as it is
    other = runs / "some-sweep" / "cases" / "0123456789abcdef"
    other.mkdir()
    (other / RESULT_NAME).write_bytes(b"")
    assert sorted(p.name for p in (out / "cases").iterdir()) == [digest]  # only the case's own hash


def test_the_twin_runs_table_pairs_each_run_with_its_trial(tmp_path, measured_dir):
    """docs/cmu_twin_runs.py reads finished runs as typed results, pairs each with the measured trial of its wheel,
    steering angle, slip and load, and gives the residual in the trial's standard deviations; a run not steady is
    marked as giving no number; a slip ramp gives a record per stage, at the stage's slip."""
    from result_files import summary, write_result

    from wheelsoil.cases.schema import load_case
    from wheelsoil.validation.measured import load_cmu_trials

    table = _load("cmu_twin_runs")
    data = load_cmu_trials(Path(measured_dir) / "cmu_3d_terramechanics")
    k = int(np.flatnonzero((data.grouser_height > 0) & (data.slip_angle == 45.0)
                           & (np.abs(data.travel_slip - 0.5) <= 0.05))[0])
    rig = [f"test.slip={data.travel_slip[k]}", "test.slip_angle=45.0", f"test.load={data.load[k]}",
           "test.drive_time=20.0", "case.seed=1"]
    dp = data.responses["drawbar_pull"][k] + 2 * data.std["drawbar_pull"][k]
    run = lambda slip, steady: summary(  # noqa: E731
        slip, steady=steady, window=(2.0, 9.0), tread_slip=(0.5, 0.0), vertical_force=(20.0, 0.0),
        drawbar_pull=(dp, 0.25), lateral_force=(-1.0, 0.25), tread_sinkage=(0.03, 0.25))
    for name, steady in (("a1", True), ("b2", False)):
        write_result(tmp_path / "cmu-some-sweep" / "cases" / name, load_case("cmu-grouser", rig), [run(0.5, steady)])
    ramp = load_case("cmu-grouser", rig + ["protocol.stages=[{slip = 0.9}]"])
    write_result(tmp_path / "cmu-some-sweep" / "cases" / "c3", ramp, [run(data.travel_slip[k], True), run(0.9, True)])
    records = table.finished_runs(tmp_path)
    table.pair_with_trials(records, data)
    assert [(r["case_hash"], r.get("stage")) for r in records] == [("a1", None), ("b2", None), ("c3", 0), ("c3", 1)]
    assert [r["slip"] for r in records[2:]] == [data.travel_slip[k], 0.9]
    assert records[0]["trial"] is not None and records[0]["drawbar_pull"] == {"mean": dp, "ci95": 0.5}
    from wheelsoil.coupling.run_summary import RunSummary

    kept = RunSummary.from_dict(records[0]["summary"])  # the whole summary comes back from the record
    assert kept.steady and kept.quantity("drawbar_pull").mean == dp and kept.window == (2.0, 9.0)
    lines = table.markdown(records)
    assert " / +2.0 | " in lines[2] and "yes (2.00–9.00 s)" in lines[2]  # drawbar pull two trial stds high
    # the sinkage beside the trial's as a difference in mm (the trials give one value each, no std)
    trial_sinkage = 1e3 * data.responses["sinkage"][k]
    assert f" / {trial_sinkage:.1f} / {30.0 - trial_sinkage:+.1f} mm | " in lines[2]
    assert "**no**" in lines[3]
    assert " / +2.0 | " in lines[4] and ", +0.900, " in lines[5]
    assert all(np.isnan(r["drum_fill"]) and not r["side_walls"] for r in records)  # stand-ins keep no frame
    assert all(line.endswith(" | – | 1 s / 1.00 s |") for line in lines[2:])


def test_the_twin_runs_recorded_earlier_are_kept_when_their_files_are_gone(tmp_path):
    """docs/cmu_twin_runs.py on a fresh runs folder: a run recorded earlier whose files are not there keeps its record
    (marked) and its summary rows; a run found again replaces its earlier record and rows; a case's stages stay
    together."""
    table = _load("cmu_twin_runs")
    earlier = [{"sweep": "cmu-a", "case_hash": "aa", "slip": 0.5, "x": 1},
               {"sweep": "cmu-a", "case_hash": "cc", "slip": 0.5, "x": 2}]
    found = [{"sweep": "cmu-a", "case_hash": "cc", "slip": 0.5, "x": 3},
             {"sweep": "cmu-b", "case_hash": "bb", "slip": 0.5, "stage": 1, "x": 5},
             {"sweep": "cmu-b", "case_hash": "bb", "slip": 0.3, "stage": 0, "x": 4}]
    merged = table.merge_records(found, earlier)
    assert [(r["case_hash"], r["x"], r.get("recorded")) for r in merged] == [
        ("aa", 1, "earlier"), ("cc", 3, None), ("bb", 4, None), ("bb", 5, None)]

    old, new = tmp_path / "old.csv", tmp_path / "new.csv"
    old.write_text("case,case_hash,steady,extra\na,aa,True,7\nc,cc,False,8\nd,dd,True,9\nd,dd,True,10\n")
    new.write_text("case,case_hash,steady\nc,cc,True\nb,bb,True\n")
    rows = table.merge_summary(new, old)
    assert [(r["case_hash"], r["steady"], r["extra"]) for r in rows] == [
        ("aa", "True", "7"), ("bb", "True", ""), ("cc", "True", ""), ("dd", "True", "9"), ("dd", "True", "10")]
    assert table.merge_summary(None, old) == table.merge_summary(tmp_path / "absent.csv", old)
    table.write_summary_rows(tmp_path / "out" / "summary.csv", rows)
    assert table.merge_summary(tmp_path / "out" / "summary.csv", tmp_path / "absent.csv") == rows


def test_the_twin_queue_skips_a_case_recorded_in_the_repository(tmp_path, monkeypatch):
    """docs/cmu_twin_queue.py does not run again a case whose hash the repository's copy of its sweep's summary holds
    (its files gone with an earlier machine), and runs the others."""
    queue = _load("cmu_twin_queue")
    recorded = tmp_path / "recorded"
    assert queue.recorded_cases(recorded, "cmu-trials-subset") == set()
    (recorded / "cmu-trials-subset").mkdir(parents=True)
    (recorded / "cmu-trials-subset" / "summary.csv").write_text("case,case_hash\na,0123\na,0123\nb,4567\n")
    assert queue.recorded_cases(recorded, "cmu-trials-subset") == {"0123", "4567"}

    from wheelsoil.cases import sweep as sweeps

    runs, started = tmp_path / "runs", []
    monkeypatch.setattr(sweeps, "run_sweep", lambda s, workers: started.append(s.cases[0].folder.name) or "done")
    monkeypatch.setattr(sweeps, "write_summary", lambda s: None)
    cases = sweeps.load_sweep("cmu-trials-subset", runs / "cmu-trials-subset").cases
    at = [c for c in cases if c.values.get("wheel.preset") == "cmu-k10-grouser"
          and float(c.values["test.slip_angle"]) in (45.0, 90.0) and abs(float(c.values["test.slip"]) - 0.5) < 0.05]
    assert len(at) == 2
    (recorded / "cmu-trials-subset" / "summary.csv").write_text(f"case,case_hash\na,{at[0].folder.name}\n")
    for c in at:
        queue.run_sweep_case(runs, "cmu-trials-subset", "cmu-k10-grouser", float(c.values["test.slip_angle"]), 0.5,
                             None, recorded=recorded)
    assert started == [at[1].folder.name]  # the recorded one skipped, the other run


def test_the_twin_queue_tells_a_longer_drive_from_the_first_run_of_the_same_trial(tmp_path, monkeypatch):
    """A sweep with a longer drive of one trial (cmu_sweep.LONGER_DRIVES) holds two cases of it: a queue entry without
    a drive matches both and runs neither (said in the log); with a drive it runs that one only."""
    queue = _load("cmu_twin_queue")
    from wheelsoil.cases import sweep as sweeps

    runs, started = tmp_path / "runs", []
    monkeypatch.setattr(sweeps, "run_sweep", lambda s, workers: started.append(s.cases[0].folder.name) or "done")
    monkeypatch.setattr(sweeps, "write_summary", lambda s: None)
    cases = sweeps.load_sweep("cmu-candidate-closed-wheel", runs / "cmu-candidate-closed-wheel").cases
    at75 = {float(c.values["test.drive_time"]): c.folder.name for c in cases
            if float(c.values["test.slip_angle"]) == 75.0}
    assert sorted(at75) == [20.0, 30.0]
    queue.run_sweep_case(runs, "cmu-candidate-closed-wheel", "cmu-k10-grouser", 75.0, 0.5, None)
    assert started == []
    for drive in (30.0, 20.0):
        queue.run_sweep_case(runs, "cmu-candidate-closed-wheel", "cmu-k10-grouser", 75.0, 0.5, None, drive)
    assert started == [at75[30.0], at75[20.0]]


def test_the_drum_fill_counts_the_grains_inside_an_open_wheel():
    """docs/cmu_twin_runs.py's drum fill: the grains whose centres lie inside the tread and between the side planes of
    a wheel yawed by the steering angle, their solid volume over the drum's (at 90 deg the axle lies along the bin)."""
    table = _load("cmu_twin_runs")
    hub, r = np.array([0.1, 0.1, 0.08]), 0.003
    along_axle = {0.0: np.array([0.0, 1.0, 0.0]), 90.0: np.array([1.0, 0.0, 0.0])}
    for angle, axle in along_axle.items():
        positions = hub + np.array([0.01 * axle + [0, 0, -0.03],   # in the drum
                                    0.03 * axle + [0, 0, -0.03],   # beyond a side plane
                                    [0.0, 0.0, -0.06],             # below the tread
                                    -0.02 * axle])                 # in the drum, beside the hub
        fill = table.drum_fill(positions, np.full(4, r), hub, angle, radius=0.058, width=0.05, tread_thickness=0.002)
        assert fill == pytest.approx(2 * (4 / 3 * np.pi * r ** 3) / (np.pi * 0.056 ** 2 * 0.05), rel=1e-12), angle


def test_a_calibration_candidate_reruns_only_its_plates_in_another_box(tmp_path, monkeypatch, measured_dir):
    """docs/soillab_calibration.py --box --reuse: a candidate keeps the density, repose and shear box of its earlier
    file and presses its plates, and nothing else, in the box given, on the bed of that density (the DEM replaced
    here by a power-law plate)."""
    from types import SimpleNamespace

    from wheelsoil import soillab
    from wheelsoil.parameters import soil_lab
    from wheelsoil.soillab.measured import LoadCurve

    calibration = _load("soillab_calibration")
    earlier = tmp_path / "earlier" / "candidates"
    earlier.mkdir(parents=True)
    old = {"friction": 0.5, "rolling_friction": 0.1, "pour_friction_factor": 1.0, "rolling_model": "epsd",
           "density": 2345.0, "packing_fraction": 0.567, "bulk_density": 1329.6, "repose_deg": 27.0,
           "shear": {"peak_friction_angle_deg": 40.0}, "plates": {"0.1": "stale"}, "objective": 9.9}
    (earlier / "mu0.5_mur0.1_epsd.json").write_text(json.dumps(old))
    assert calibration.reused_row([tmp_path / "nowhere", tmp_path / "earlier"], "mu0.3_mur0.1_epsd") is None
    reused = calibration.reused_row([tmp_path / "earlier"], "mu0.5_mur0.1_epsd")
    assert "plates" not in reused and "objective" not in reused and reused["density"] == 2345.0

    pressed = []

    def plate_test(bed, plate, cache_dir=None, checkpoint=None):
        pressed.append((bed, plate.diameter, checkpoint))
        z = np.linspace(0.0, 0.03, 61)
        area = np.pi * plate.diameter ** 2 / 4
        curve = LoadCurve("plate", plate.diameter, "fake", z, area * 2e6 * z ** 1.2, area=area)
        return SimpleNamespace(curve=curve, wall_seconds=1.0, top_offset=0.0, inertial_number=1e-4,
                               bulk_density=1330.0)

    def refuse(*args, **kwargs):
        raise AssertionError("a reused candidate runs no bed preparation, repose or shear box")

    monkeypatch.setattr(soillab, "plate_test", plate_test)
    for name in ("repose_test", "shear_test"):
        monkeypatch.setattr(soillab, name, refuse)
    monkeypatch.setattr("wheelsoil.granular.bed.prepare_bed", refuse)
    box = {"length": 0.6, "width": 0.6, "depth": 0.12}
    row = calibration.candidate(0.5, 0.1, None, shear=True, law="epsd", box=box, reused=reused,
                                checkpoints=tmp_path / "ck")
    assert [d for _, d, _ in pressed] == list(soil_lab.PLATE_DIAMETERS)
    for bed, d, checkpoint in pressed:
        assert (bed.length, bed.width, bed.depth) == (0.6, 0.6, 0.12) and bed.material.density == 2345.0
        assert checkpoint.parent == tmp_path / "ck" and f"{1e3 * d:g}" in checkpoint.name
    assert row["repose_deg"] == 27.0 and row["shear"] == old["shear"] and row["plate_box_m"] == [0.6, 0.6, 0.12]
    assert np.isfinite(row["objective"]) and row["objective"] != old["objective"]


def test_seed004_like_reads_changes_in_the_seeds_terms(tmp_path):
    """docs/seed004_like.py on synthetic runs whose drawbar pull falls by a known 40 % from 5 to 20 deg at every
    slip, and is 80 % lower at 1/6 g: it gives those averages, leaves out slips whose runs are not steady and reports
    nothing below four slips."""
    from result_files import summary, write_result

    from wheelsoil.cases.schema import load_case

    table = _load("seed004_like")
    cases = tmp_path / "cases"
    k = 0
    for gravity, load in (table.EARTH_3000, table.MOON_500):
        for angle in (5.0, 20.0):
            for slip in table.SLIPS:
                dp = 1000.0 * slip * (0.6 if angle == 20.0 else 1.0) * (0.2 if gravity == "moon" else 1.0)
                steady = not (gravity == "moon" and slip >= 0.4)  # three moon slips are not steady
                case = load_case("smoke-1g-steer", [f"soil.gravity={gravity}", f"test.load={load}",
                                                    f"test.slip_angle={angle}", f"test.slip={slip}"])
                stage = summary(slip, steady=steady, drawbar_pull=(dp, 5.0), lateral_force=(-dp, 5.0),
                                sinkage=(0.05, 1e-3))
                write_result(cases / f"c{k}", case, [stage])
                k += 1
    runs = table.read_runs(tmp_path)
    factors = {"earth": dict.fromkeys(table.QUANTITIES, 2.0), "moon": dict.fromkeys(table.QUANTITIES, 1.0)}
    steer = table.averaged(runs, factors, (*table.EARTH_3000, 5.0), (*table.EARTH_3000, 20.0), "drawbar_pull",
                           difference=False)
    assert steer["value"] == pytest.approx(-40.0) and steer["slips"] == list(table.SLIPS)
    # the error: each slip's change from sems of 5 N widened twice, averaged over six slips
    one = [100 * np.hypot(10 / (1000 * s), 600 * s * 10 / (1000 * s) ** 2) for s in table.SLIPS]
    assert steer["error"] == pytest.approx(np.sqrt(np.sum(np.square(one))) / 6)
    lateral = table.averaged(runs, factors, (*table.EARTH_3000, 5.0), (*table.EARTH_3000, 20.0), "lateral_force",
                             difference=False)
    assert lateral["value"] == pytest.approx(-40.0)  # by magnitude
    gravity = table.averaged(runs, factors, (*table.EARTH_3000, 20.0), (*table.MOON_500, 20.0), "drawbar_pull",
                             difference=True)
    assert np.isnan(gravity["value"]) and gravity["slips"] == [0.1, 0.2, 0.3]
    assert table.verdict(-36.9, steer) in ("agrees", "the same way") and table.verdict(80.0, gravity).startswith("not")
    assert table.verdict(+30.0, {"value": -40.0, "error": 1.0, "slips": []}) == "disagrees"


def test_the_box_check_reads_its_rule_from_the_runs(tmp_path):
    """docs/soillab_box_check.py: a doubling that moves the plate's pressure by 5 % passes, one by 20 % fails, and a
    box not yet run is said to be missing."""
    check = _load("soillab_box_check")

    def box(name, scale, packing=0.52):
        (tmp_path / name).mkdir()
        rows = [{"diameter_m": 0.1, "sinkage_m": z, "simulated_Pa": 1e6 * z * scale}
                for z in (0.005, 0.01, 0.015, 0.02)]
        rows.append({"diameter_m": 0.06, "sinkage_m": 0.01, "simulated_Pa": 1.0})  # another plate: not read
        (tmp_path / name / "plate.json").write_text(json.dumps({"pressure": rows,
                                                                "runs": [{"packing_fraction": packing}]}))

    box("lab", 1.0)
    box("wide", 1 / 0.95)  # the wide box's pressure 5 % above: passes
    box("deep", 1.25)      # 20 % of the deep box's: fails
    assert check.main(["--boxes", str(tmp_path)]) == 0
    verdicts = json.loads((tmp_path / "check.json").read_text())["doublings"]
    assert [v["verdict"] for v in verdicts][:2] == ["passes", "fails (20% against 10%)"]
    assert verdicts[0]["changes"] == pytest.approx([0.05] * 3)
    assert verdicts[2]["verdict"] == verdicts[3]["verdict"] == "not run yet"
    assert json.loads((tmp_path / "check.json").read_text())["depth_or_density"]["verdict"] == "not run yet"
    # depth or density: the lab's box poured denser carries the deep box's pressure (within 4 %), 20 % above the lab's
    (tmp_path / "density").mkdir()
    box("density/plate", 1.2)
    check.main(["--boxes", str(tmp_path)])
    density = json.loads((tmp_path / "check.json").read_text())["depth_or_density"]
    assert density["verdict"] == "the density explains the depth doubling"
    assert density["from_deep"] == pytest.approx([(1.2 - 1.25) / 1.2] * 3)
    box("density/lab-like", 1.05)  # within 10 % of the lab box's: the depth stiffens the deep box
    assert check.depth_or_density(check.pressures(tmp_path / "lab"), check.pressures(tmp_path / "deep"),
                                  check.pressures(tmp_path / "density" / "lab-like"))["verdict"].startswith("the depth")
    box("density/between", 1.12)  # 10.7 % from both: both
    assert check.depth_or_density(check.pressures(tmp_path / "lab"), check.pressures(tmp_path / "deep"),
                                  check.pressures(tmp_path / "density" / "between"))["verdict"].startswith("both")
    # the depth doubling at equal packing: the deep box poured looser carries 8 % more than the lab's box (passes) and
    # 14 % less than the deep box poured loose; its packing is reported beside
    assert json.loads((tmp_path / "check.json").read_text())["depth_at_equal_packing"]["verdict"] == "not run yet"
    (tmp_path / "depth").mkdir()
    box("depth/plate", 1 / 0.92, packing=0.515)
    check.main(["--boxes", str(tmp_path)])
    equal = json.loads((tmp_path / "check.json").read_text())["depth_at_equal_packing"]
    assert equal["verdict"] == "passes" and equal["changes"] == pytest.approx([0.08] * 3)
    assert equal["from_deep"] == pytest.approx([(1 / 0.92 - 1.25) * 0.92] * 3)
    assert equal["packing"] == {"box": 0.52, "deep": 0.52, "looser_deep": 0.515}
    assert "Verdict on the lab box's depth doubling at equal packing: passes." in (tmp_path / "check.md").read_text()
    assert json.loads((tmp_path / "check.json").read_text())["wide_depth_at_equal_packing"]["verdict"] == "not run yet"
    # the wide box's seeds: both doublings judged against the three seeds' mean, once every seed has run
    box("wider", 1.15 / 0.95)  # 15 % above seed 0 (fails against it)
    (tmp_path / "depth-wide").mkdir()
    box("depth-wide/plate", 1 / 0.95 * 1.02)
    box("wide-seed1", 1 / 0.95 * 1.2)
    assert json.loads((tmp_path / "check.json").read_text())["wide_three_seeds"]["mean_Pa"] is None
    check.main(["--boxes", str(tmp_path)])
    assert json.loads((tmp_path / "check.json").read_text())["wide_three_seeds"]["doublings"][0]["verdict"] == \
        "not run yet"
    box("wide-seed2", 1 / 0.95 * 1.25)  # the mean 1.15 times seed 0's: the wider box equal to it, the deep one 13 % below
    check.main(["--boxes", str(tmp_path)])
    wide = json.loads((tmp_path / "check.json").read_text())["wide_three_seeds"]
    assert wide["mean_Pa"][0] == pytest.approx(1e6 * 0.01 * 1.15 / 0.95)
    assert wide["relative_spread"] == pytest.approx([np.std([1.0, 1.2, 1.25], ddof=1) / 1.15] * 3)
    assert [d["verdict"] for d in wide["doublings"]] == ["passes", "fails (13% against 10%)"]
    assert wide["doublings"][1]["changes"] == pytest.approx([(1.02 - 1.15) / 1.02] * 3)


def test_the_force_balance_table_averages_each_term_over_the_steady_window(tmp_path):
    """docs/force_balance_table.py: every term's mean over the summary's window (samples after its start, to its end)
    and the largest residual over every sample, read from a result's own files."""
    from result_files import summary, write_result

    from wheelsoil.cases.schema import load_case

    table = _load("force_balance_table")
    # the stand-in series run 0, 0.25, ..., 1 s in every column; a window (0.25, 0.75] holds the samples at 0.5, 0.75
    write_result(tmp_path / "run", load_case("mini-1g-steer"), [summary(0.3, window=(0.25, 0.75))])
    row = table.balance(tmp_path / "run")
    assert row["vertical_force_applied"] == pytest.approx(0.625) and row["weight"] == pytest.approx(0.625)
    assert row["largest_residual"] == 1.0 and row["steady"] and row["load"] == 80.0


def test_the_background_status_reads_the_queue_log_and_the_campaign_list(tmp_path):
    """The status screen names the twin queue's last start and end from its log, each checkpoint's simulated time,
    and every campaign the runner script lists with its target number of draws."""
    import h5py

    status = _load("background_status")
    (tmp_path / "cmu_queue.log").write_text("08:00:00 start sweep-a 1111\n09:00:00 end sweep-a 1111: ok in 3600 s\n"
                                            "09:00:01 start sweep-b 2222\nsome traceback line\n")
    case = tmp_path / "sweep-b" / "cases" / "2222"
    case.mkdir(parents=True)
    with h5py.File(case / ".checkpoint.h5", "w") as h5:
        h5.attrs["t"] = 3.25
    lines = status.twin_lines(tmp_path)
    assert lines[1].startswith("  09:00:00 end sweep-a") and lines[2].startswith("  09:00:01 start sweep-b")
    assert "sweep-b/2222: t = 3.25 s simulated" in lines[3]
    import re

    script = status.CAMPAIGN_SCRIPT.read_text()
    listed = [re.match(r"  ([\w-]+)-(\d+): \d+ of (\d+) draws", ln) for ln in status.campaign_lines()[1:]]
    assert listed and all(m and (f'"{m[1]} {m[3]} {m[2]}"' in script or f'"{m[1]} {m[3]} {m[2]} ' in script)
                          for m in listed)
    assert len(listed) == len(re.findall(r'"[\w-]+ \d+ \d+[^"]*"', script))  # every campaign of the script


def test_the_background_status_counts_a_sweeps_cases(tmp_path):
    """Each of issue 35's sweeps: its case folders with a summary (finished) and without one, or none started."""
    status = _load("background_status")
    cases = tmp_path / status.SWEEPS[0] / "cases"
    for k, done in enumerate((True, False, True)):
        (cases / f"case{k}").mkdir(parents=True)
        if done:
            (cases / f"case{k}" / "summary.json").write_text("{}")
    lines = status.sweep_lines(tmp_path)
    assert lines[1] == f"  {status.SWEEPS[0]}: 2 finished, 1 started without a summary"
    assert lines[2] == f"  {status.SWEEPS[1]}: no case started"


def test_the_choice_checks_summary_reads_every_check_by_its_rule(tmp_path, monkeypatch, measured_dir):
    """docs/soillab_choice_checks.py on synthetic results of run.sh's steps: the calibration's choice by its rule,
    the repose's mean and spread with seed 0 against the calibration's, the shear box's verdict at 10 % (one stress
    changed by 12 %), each seed's objective as the calibration scores it, and the scale's line through the scale
    runs and the x1 replicas (exactly linear in the mean diameter with a symmetric spread at x1: the line's own
    intercept)."""
    from wheelsoil.parameters import cmu_sand
    from wheelsoil.soillab.objective import score

    checks = _load("soillab_choice_checks")
    calibration = _load("soillab_calibration")
    monkeypatch.syspath_prepend(str(DOCS))
    sinkages = [0.005, 0.01, 0.015, 0.02, 0.025]
    measured = {"0.06": [3e3, 7e3, 12e3, 18e3, 26e3], "0.1": [5e3, 13e3, 23e3, 35e3, float("nan")]}

    def plates(factor):
        return {d: {"sinkage_m": sinkages, "simulated_Pa": [factor * m if m == m else 40e3 for m in mea],
                    "measured_Pa": mea, "measured_sd_Pa": [0.1 * m for m in mea]} for d, mea in measured.items()}

    cands = tmp_path / "calibration" / "candidates"
    cands.mkdir(parents=True)
    for k, (mu, mu_r, pour, _, law) in enumerate(calibration.DESIGNS["epsd-box"]):
        chosen = (mu, mu_r) == (0.52, 0.5)
        row = {"friction": mu, "rolling_friction": mu_r, "pour_friction_factor": pour, "rolling_model": law,
               "density": cmu_sand.PARTICLE_MATERIAL.density if chosen else 2400.0 + k,
               "repose_deg": 28.0 if chosen else 25.0 + 0.1 * k, "plates": plates(1.2 if chosen else 1.5 + 0.1 * k)}
        (cands / f"{calibration.candidate_name(mu, mu_r, pour, law)}.json").write_text(json.dumps(row))
    out = tmp_path / "checks"

    def write(path, data):
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(data))

    write(out / "repose" / "repose.json", {"angles_deg": [28.5, 29.5, 30.5]})
    stresses = [5e3, 10e3, 20e3]
    write(out / "shear-20mms" / "shear.json", {"runs": [{"imposed_normal_Pa": s, "peak_Pa": s} for s in stresses],
                                               "peak": {"friction_angle_deg": 45.0}})
    write(out / "shear-10mms" / "shear.json", {"runs": [{"imposed_normal_Pa": s, "peak_Pa": s * f}
                                                        for s, f in zip(stresses, (1.05, 0.97, 1.12))],
                                               "peak": {"friction_angle_deg": 46.0}})
    wide = {}
    p0, slope = 10e3, 1e6  # the 100 mm plate's pressure at every scale sinkage: p0 + slope * d, +-1 % at x1
    for seed, spread in ((1, 1.01), (2, 0.99)):
        write(out / f"plate-seed{seed}" / "plate.json", {"pressure": [
            {"diameter_m": 0.06, "sinkage_m": z, "simulated_Pa": 1.1 * seed * m} for z, m in zip(sinkages,
                                                                                               measured["0.06"])]})
        wide[seed] = tmp_path / f"wide-seed{seed}"
        write(wide[seed] / "plate.json", {"pressure": [
            {"diameter_m": 0.1, "sinkage_m": z, "simulated_Pa": spread * (p0 + slope * 0.008)} for z in sinkages]})
    for scale, d in ((1.0, 0.008), (0.8, 0.0064), (0.64, 0.00512)):
        write(out / "scale" / "runs" / f"scale{scale:g}_seed0.json",
              {"scale": scale, "seed": 0, "mean_diameter_m": d, "pressure_Pa": [p0 + slope * d] * 4})
    monkeypatch.setattr(checks, "CALIBRATION", tmp_path / "calibration")
    monkeypatch.setattr(checks, "WIDE_BOX_SEEDS", wide)
    monkeypatch.setattr(checks, "CMU_SAND_WHEELS", tmp_path / "no-wheels")

    assert checks.main(["--out", str(out)]) == 0
    report = json.loads((out / "summary.json").read_text())
    assert report["choice"]["cmu_sand"] and report["choice"]["friction"] == 0.52
    rep = report["repose"]
    assert rep["mean_deg"] == pytest.approx(29.5) and rep["sd_deg"] == pytest.approx(1.0)
    assert rep["seed0_change_deg"] == pytest.approx(0.5)
    shear = report["shear_speed"]
    assert shear["change"] == pytest.approx([0.05, -0.03, 0.12]) and shear["quasi_static"] is False
    per_seed = report["plates"]["per_seed"]
    assert sorted(per_seed) == ["0", "1", "2"]
    for seed, angle in zip("012", (28.5, 29.5, 30.5)):
        pressures = per_seed[seed]["pressure_Pa"]
        expected = score({"plates": {d: {"simulated_Pa": pressures[d], "measured_Pa": measured[d]} for d in measured},
                          "repose_deg": angle})
        assert per_seed[seed]["objective"] == pytest.approx(expected["objective"], rel=1e-12)
    assert per_seed["1"]["pressure_Pa"]["0.06"] == pytest.approx([1.1 * m for m in measured["0.06"]])
    objectives = [per_seed[s]["objective"] for s in "012"]
    assert report["plates"]["objective_sd"] == pytest.approx(np.std(objectives, ddof=1))
    assert report["runner_up"]["gap"] > 0
    assert [w["seeds"] for w in report["wheels"].values()] == [[], []]
    extrapolation = report["scale"]["extrapolation"]
    assert [e["points"] for e in extrapolation] == [5] * 4
    assert all(e["p0_Pa"] == pytest.approx(p0, rel=1e-9) for e in extrapolation)
    for e in extrapolation:  # the line's error at each size run: slope d / p0 (x0.8: the twin's particles)
        assert sorted(e["by_scale"]) == ["0.64", "0.8", "1"]
        for x, d in (("1", 0.008), ("0.8", 0.0064), ("0.64", 0.00512)):
            assert e["by_scale"][x]["scale_error"] == pytest.approx(slope * d / p0, rel=1e-9)
        assert e["by_scale"]["0.64"]["converged"] is False  # +51 %: not within 10 %
        assert e["p0_quadratic_Pa"] == pytest.approx(p0, rel=1e-6)
    text = (out / "summary.md").read_text()
    # the 5 mm row: p0 10 kPa, the lab's particles 18 kPa, +80 % at x1 and +64 % at x0.8, the quadratic's p0 10 kPa
    assert re.search(r"\| 5 \| 5 \| 10\.0 ± [\d.]+ \| 18\.0 \| \+80 ± \d+ % \| no \| \+64 ± \d+ % \| no \| 10\.0 \|", text)
    assert "Not quasi-static" in text and "not run yet" in text


def test_the_calibration_figure_draws_the_stored_candidates_and_refuses_a_folder_without_plates(tmp_path,
                                                                                                   measured_dir):
    """docs/soillab_calibration.py figure on the stored EPSD grid (no DEM): the PNG is written; a --seed-plates folder
    without a plate.csv is refused before any drawing."""
    calibration = _load("soillab_calibration")
    png = tmp_path / "plates.png"
    folder = str(DOCS / "soillab" / "calibration-epsd")
    assert calibration.main(["figure", folder, "--design", "epsd", "--png", str(png)]) == 0
    assert png.stat().st_size > 10_000
    assert calibration.main(["figure", folder, "--design", "epsd", "--png", str(tmp_path / "no.png"),
                             "--seed-plates", str(tmp_path)]) == 1
    assert not (tmp_path / "no.png").exists()


def test_the_gravity_terms_name_a_step_only_beyond_two_standard_errors(tmp_path):
    gt = _load("gravity_terms")
    qs = list(gt.COEFFICIENTS)

    def condition(name, dp_values):
        return gt.Condition(name, [{q: (v if q == "drawbar_pull" else 0.1) for q in qs} for v in dp_values], "test")

    conditions = {"earth": condition("earth", [0.30, 0.32, 0.31]), "moon": condition("moon", [0.18, 0.19, 0.17]),
                  "froude": condition("froude", [0.285, 0.295]), "soil-stiffness": condition("soil-stiffness", [0.30]),
                  "similar": condition("similar", [0.31, 0.31]), "rigid-earth": condition("rigid-earth", [0.16]),
                  "rigid-moon": condition("rigid-moon", [0.15])}
    result = gt.analyse(conditions)
    # pooled over every condition with two runs or more: (2*1e-4 + 2*1e-4 + 5e-5 + 0) / (2 + 2 + 1 + 1)
    assert result["spreads"]["drawbar_pull"] == pytest.approx(np.sqrt((2e-4 + 2e-4 + 5e-5) / 6))
    steps = {s["term"]: s["drawbar_pull"] for s in result["steps"]}
    s = result["spreads"]["drawbar_pull"]
    inertia = steps["inertia (Froude number)"]
    assert inertia["change"] == pytest.approx(0.29 - 0.18)
    assert inertia["se"] == pytest.approx(s * np.sqrt(1 / 3 + 1 / 2)) and inertia["named"]
    assert not steps["grain stiffness"]["named"]  # 0.01 against 2 x 0.0106
    assert not steps["similarity check (must be 0)"]["named"]
    assert steps["all of them: 1/6 g at equal mass"]["named"]
    assert steps["1/6 g at equal mass, rigid wheel (the wheel's term removed)"]["change"] == pytest.approx(-0.01)
    assert result["steps"][0]["lateral_force"]["change"] == pytest.approx(0.0)
    # the diagnostic steps of a condition not run yet say nothing; once it has runs, they compare it both ways
    assert steps["diagnostic: the 1g case at the similar case's step"] == {"change": None, "se": None, "named": None}
    with_step = gt.analyse(dict(conditions, **{"earth-step": condition("earth-step", [0.33, 0.33])}))
    diag = {s["term"]: s["drawbar_pull"] for s in with_step["steps"]}
    assert diag["diagnostic: the 1g case at the similar case's step"]["change"] == pytest.approx(0.33 - 0.31)
    assert diag["diagnostic: the similarity check at the same step (must be 0)"]["change"] == pytest.approx(0.31 - 0.33)
    unsteady = ({"seed": 4, "window": [1.0, 2.0], "reasons": ["drawbar_pull drifts"], **{q: 0.25 for q in qs}},)
    empty = dict(conditions, froude=gt.Condition("froude", [], "test", unsteady))
    assert gt.analyse(empty)["steps"][0]["drawbar_pull"] == {"change": None, "se": None, "named": None}
    text = gt.markdown(gt.analyse(empty))
    assert "| froude | 0 |" in text and "| froude | 4 | 1.00–2.00 | +0.2500" in text and "drawbar_pull drifts" in text
    gt.figure(gt.analyse(empty), tmp_path / "terms.png")
    assert (tmp_path / "terms.png").stat().st_size > 10_000


def test_the_gravity_terms_do_not_run_again_a_case_recorded_in_the_repository(tmp_path, monkeypatch, capsys):
    """A fresh machine has none of the runs' files: ``run`` skips the cases runs.json records (same case hash) and
    runs the others (run_sweep replaced by a recorder here: no DEM)."""
    from wheelsoil.cases import sweep

    gt = _load("gravity_terms")
    variant = gt.VARIANTS[0]
    seed1, seed2 = gt.variant_runs(variant, tmp_path, [1, 2])
    record = tmp_path / "runs.json"
    record.write_text(json.dumps({variant.name: {"1": {"case_hash": seed1.folder.name},
                                                 "2": {"case_hash": "0" * 16}}}))  # seed 2's record: another case
    ran = []
    monkeypatch.setattr(sweep, "run_sweep", lambda s, workers=None: ran.append(s.cases[0].folder.name))
    assert gt.main(["run", "--runs", str(tmp_path), "--seeds", "1", "2", "--variants", variant.name,
                    "--recorded", str(record)]) == 0
    assert ran == [seed2.folder.name]
    assert f"{variant.name}, seed 1: recorded in {record} (its files are not here); skipped" in capsys.readouterr().out


def test_the_gravity_terms_keep_a_run_recorded_in_the_repository_when_its_files_are_gone(tmp_path):
    gt = _load("gravity_terms")
    variant = gt.VARIANTS[0]
    case = gt.variant_runs(variant, tmp_path, [1])[0]
    coefficients = {q: 0.2 for q in gt.COEFFICIENTS}
    rec = {"case_hash": case.folder.name, "steady": True, "window": [1.0, 3.0], "reasons": [], "means": {},
           "coefficients": coefficients}
    stale = dict(rec, case_hash="0" * 16)  # a record of another case on that seed (the variant changed): dropped
    kept = gt.variant_records(variant, tmp_path, [1, 2], {"1": rec, "2": stale})
    assert list(kept) == ["1"] and kept["1"]["recorded"] == "earlier"
    condition = gt.variant_condition(variant, dict(kept, **{"3": dict(rec, steady=False, reasons=["drift"])}))
    assert condition.runs == [coefficients] and condition.unsteady[0]["seed"] == 3
