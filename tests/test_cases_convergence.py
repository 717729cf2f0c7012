"""The convergence study: its levels are the case keys they claim, its arithmetic is the change between
neighbouring levels with the combined standard error, its verdict is the coarsest level from which every
pair is within the threshold."""

import math

import pytest

from wheelsoil.cases import build
from wheelsoil.cases import convergence as cv
from wheelsoil.cases import convergence_report as cr
from wheelsoil.cases.schema import load_case
from wheelsoil.errors import WheelsoilInputError


@pytest.fixture(scope="module")
def mini():
    return load_case("mini-1g-steer")


def test_levels_change_only_their_keys(mini, tmp_path):
    study = cv.make_study(mini, tmp_path, {"particle_size": (1, 0.8, 0.64), "depth": (1, 2), "mesh": (1, 0.5),
                                           "time_step": (1, 0.5)}, particle_step="own")
    ref = study.reference.case
    ps = study.levels["particle_size"][2].case
    assert ps.soil.diameter_min == pytest.approx(0.64 * ref.soil.diameter_min)
    assert ps.soil.diameter_max == pytest.approx(0.64 * ref.soil.diameter_max)
    assert ps.soil.depth == ref.soil.depth and ps.wheel == ref.wheel
    # refined levels may drive twice as long (they stop once steady); nothing else of the test changes
    assert ps.test == ref.test.model_copy(update={"drive_time": 2 * ref.test.drive_time})
    longer = cv.make_study(mini, tmp_path, {"depth": (1, 2)}, level_drive_time=10.0)
    assert longer.levels["depth"][1].case.test.drive_time == 10.0 and longer.reference.case == ref
    with pytest.raises(WheelsoilInputError, match="at least the case's test.drive_time"):
        cv.make_study(mini, tmp_path, {"depth": (1, 2)}, level_drive_time=0.5 * ref.test.drive_time)
    assert study.levels["depth"][1].case.soil.depth == pytest.approx(2 * ref.soil.depth)
    assert study.levels["mesh"][1].case.wheel.element_size == pytest.approx(0.5 * ref.wheel.element_size)
    # the reference is one case shared by every factor; the time-step level waits for the reference's step
    assert len({lv.folder for lv in study.cases()}) == len(study.cases()) == 1 + 2 + 1 + 1
    assert study.levels["time_step"][1].case is None
    again = cv.make_study(mini, tmp_path, {"time_step": (1, 0.5)}, reference_time_step=2e-5)
    assert again.levels["time_step"][1].case.soil.time_step == pytest.approx(1e-5)
    assert build.bed_spec(again.levels["time_step"][1].case) == build.bed_spec(again.reference.case)  # the same bed


def test_the_bin_length_is_a_factor_on_request_only(tmp_path):
    """A ploughing wheel's check (the CMU twin at 90 deg): the length doubles the periodic bin along the travel, every
    other key as it is, and the wheel keeps its start, so the whole added length lies ahead of it."""
    from wheelsoil.coupling.patch_geometry import PatchGeometry

    case = load_case("cmu-grouser", ["test.slip_angle=90"])
    study = cv.make_study(case, tmp_path, {"length": (1, 2)})
    ref, longer = study.reference.case, study.levels["length"][1].case
    assert longer.soil.length == pytest.approx(2 * ref.soil.length)
    assert longer.soil.model_copy(update={"length": ref.soil.length}) == ref.soil
    assert longer.wheel == ref.wheel and longer.test.model_copy(update={"drive_time": ref.test.drive_time}) == ref.test
    reach, shift, dmax = 0.063, 0.2 * 0.058, ref.soil.diameter_max
    start = [PatchGeometry.for_wheel(c.soil.length, reach, shift, dmax).check(None) for c in (ref, longer)]
    assert start[0] == pytest.approx(start[1])
    assert "length" not in cv.make_study(case, tmp_path / "default").levels


def test_particle_levels_share_the_finest_levels_dem_step(mini, tmp_path):
    """By default every particle-size level, the reference's size included (a case of its own), runs at the
    reference's DEM step times the finest scale, so the series changes the particles and not the step; the
    levels wait for the reference's step like the time-step levels."""
    levels = {"particle_size": (1, 0.8, 0.64), "depth": (1, 2)}
    waiting = cv.make_study(mini, tmp_path, levels)
    assert all(lv.case is None for lv in waiting.levels["particle_size"])
    assert waiting.reference.case.soil.time_step is None and waiting.reference is waiting.levels["depth"][0]
    study = cv.make_study(mini, tmp_path, levels, reference_time_step=2e-5)
    ps = study.levels["particle_size"]
    assert [lv.case.soil.time_step for lv in ps] == [pytest.approx(0.64 * 2e-5)] * 3
    assert ps[0].case.soil.diameter_min == mini.soil.diameter_min and ps[0].folder != study.reference.folder
    assert ps[2].case.soil.diameter_min == pytest.approx(0.64 * mini.soil.diameter_min)
    assert build.bed_spec(ps[0].case) == build.bed_spec(study.reference.case)  # the reference's bed, a finer step
    assert len(study.cases()) == 1 + 3 + 1
    # the plan: each particle level's cost at the common step, 1 / 0.64 steps per simulated second
    rows = {(r["factor"], r["scale"]): r for r in cv.plan(study)}
    assert rows["particle_size", 1.0]["relative_soil_cost"] == pytest.approx(1 / 0.64, rel=1e-3)
    assert rows["particle_size", 0.64]["relative_soil_cost"] == pytest.approx(0.64 ** -3 / 0.64, rel=1e-2)
    # a case without time-step or depth factor: the reference runs on its own
    alone = cv.make_study(mini, tmp_path, {"particle_size": (1, 0.5)}, reference_time_step=2e-5)
    assert alone.reference.factor == "reference" and alone.reference.case.soil.time_step is None
    with pytest.raises(WheelsoilInputError, match="particle_step = 'shared'"):
        cv.make_study(mini, tmp_path, levels, particle_step="shared")


@pytest.mark.parametrize("levels, message", [
    ({"particle_size": (0.8, 1.0)}, "reference 1 first"),
    ({"depth": (1,)}, "at least one more level"),
    ({"width": (1, -2)}, "distinct numbers > 0"),
    ({"grain": (1, 2)}, "not one of"),
])
def test_bad_levels_are_refused(mini, tmp_path, levels, message):
    with pytest.raises(WheelsoilInputError, match=message):
        cv.make_study(mini, tmp_path, levels)


def test_a_level_the_machine_cannot_hold_is_refused_before_the_reference_runs(tmp_path, capsys):
    """A particle level waits for the reference's DEM step (the common step), but its bed is checked against the
    machine's memory at once: 15 million spheres are refused before any run, by the command too, naming the level."""
    from wheelsoil.cases.cli import EXIT_INPUT, main
    from wheelsoil.cases.schema import load_case

    with pytest.raises(WheelsoilInputError, match=r"particle_size x 0.1 .* spheres while it is prepared"):
        cv.make_study(load_case("smoke-1g-steer"), tmp_path, {"particle_size": (1, 0.1)})
    out = tmp_path / "c"
    assert main(["convergence", "smoke-1g-steer", "--factors", "particle_size", "--particle-size-levels", "1,0.1",
                 "--out", str(out)]) == EXIT_INPUT
    err = " ".join(capsys.readouterr().err.split())
    assert "particle_size x 0.1" in err and "GiB" in err and "Traceback" not in err
    assert not (out / "cases").exists()


def test_parse_levels():
    assert cv.parse_levels("1, 0.8,0.64", "particle_size") == (1.0, 0.8, 0.64)
    assert cv.parse_levels(None, "depth") == cv.DEFAULT_LEVELS["depth"]
    with pytest.raises(WheelsoilInputError, match="numbers separated by commas"):
        cv.parse_levels("1,fine", "mesh")


def _values(scale, steady=True):
    """Synthetic results: every quantity q(s) = q_inf (1 + 0.2 s^2) with standard error 1 % of the value; the
    change from s to s' is then 0.2 (s'^2 - s^2) / (1 + 0.2 s'^2) of the finer value."""
    base = {"drawbar_pull": 500.0, "lateral_force": 200.0, "vertical_force": 3000.0, "torque": 600.0,
            "sinkage": 0.08, "tread_slip": 0.3}
    out = {"steady": steady, "wall_seconds": 1.0, "particles": 1, "dem_time_step": 1e-5}
    for q, v in base.items():
        m = v * (1 + 0.2 * scale**2)
        out[q] = (m, 0.01 * m)
    return out


def test_changes_and_verdict(mini, tmp_path, monkeypatch):
    study = cv.make_study(mini, tmp_path, {"particle_size": (1, 0.8, 0.64), "depth": (1, 2)})
    steady = {0.64: False}
    monkeypatch.setattr(cr, "_level_values",
                        lambda lv: _values(lv.scale if lv.factor == "particle_size" else 0.1,
                                           steady=steady.get(lv.scale, True)))
    rows = cr.comparison_rows(study)
    r = next(r for r in rows if r["factor"] == "particle_size" and r["coarse_scale"] == 1.0
             and r["quantity"] == "drawbar_pull")
    coarse, fine = 500 * 1.2, 500 * (1 + 0.2 * 0.64)
    assert r["change"] == pytest.approx(fine - coarse)
    assert r["relative_change"] == pytest.approx((fine - coarse) / fine)
    assert r["change_sem"] == pytest.approx(math.hypot(0.01 * coarse, 0.01 * fine))
    # 1 -> 0.8: -6.4 % (converged); 0.8 -> 0.64 not steady, so not converged: no coarsest level
    assert r["converged"]
    verdict = cr.coarsest_converged(study, rows)
    assert verdict["particle_size"] is None
    assert verdict["depth"] == 1.0
    steady.clear()
    assert cr.coarsest_converged(study, cr.comparison_rows(study))["particle_size"] == 1.0
    tight = cv.make_study(mini, tmp_path, {"particle_size": (1, 0.8, 0.64)}, threshold=0.05)
    # 1 -> 0.8 changes 6.4 %, 0.8 -> 0.64 4.4 %: converged within 5 % only from 0.8 on
    assert cr.coarsest_converged(tight, cr.comparison_rows(tight))["particle_size"] == 0.8
    paths = cr.write_report(tight)
    text = (tmp_path / "convergence.md").read_text()
    # neighbouring levels within 5 % is not convergence: extrapolated, the reference is 0.2 / 1.2 off (see below)
    assert "particle_size: **not converged**: extrapolated to scale 0" in text and all(p.is_file() for p in paths)
    assert "(neighbouring levels change by less than 5 % from scale 0.8 on)" in text
    # a level that is not steady makes the verdict undecided, not "not converged"
    steady[0.64] = False
    cr.write_report(study)
    text = (tmp_path / "convergence.md").read_text()
    assert "particle_size: **undecided**: the level(s) at scale 0.64 did not reach a steady state" in text
    assert "depth: converged within 10 % from scale 1 on" in text


def test_plan_estimates_particles_and_soil_cost(mini, tmp_path):
    """Particles scale as the bin volume over the mean sphere volume, the soil's cost per simulated second as
    particles x steps (the stable step is proportional to the particle size): x 0.8 in size is 1/0.8^4."""
    study = cv.make_study(mini, tmp_path, {"particle_size": (1, 0.8), "width": (1, 2)}, reference_time_step=2e-5)
    rows = {(r["factor"], r["scale"]): r for r in cv.plan(study)}
    spec = build.bed_spec(mini)
    assert rows["particle_size", 1.0]["particles"] == round(0.6 * 0.6 * 0.25 * 0.05 / spec.mean_particle_volume)
    assert rows["particle_size", 0.8]["relative_soil_cost"] == pytest.approx(0.8**-4, rel=1e-3)  # whole particles
    assert rows["width", 2.0]["relative_soil_cost"] == pytest.approx(2.0)
    assert rows["width", 2.0]["drive_time"] == 2 * mini.test.drive_time


def test_time_step_levels_join_the_first_sweep_once_the_reference_has_run(mini, tmp_path, monkeypatch):
    study = cv.make_study(mini, tmp_path, {"time_step": (1, 0.5)})
    assert not cv.resolve_time_step_levels(study) and study.levels["time_step"][1].case is None
    ref = study.reference.folder
    ref.mkdir(parents=True)
    (ref / cv.RESULT_NAME).write_bytes(b"")
    monkeypatch.setattr(cv, "load_result", lambda path: type("R", (), {"info": {"dem_time_step": 4e-5}})())
    assert cv.resolve_time_step_levels(study)
    assert study.levels["time_step"][1].case.soil.time_step == pytest.approx(2e-5)


def test_unrun_levels_are_reported_as_such(mini, tmp_path):
    study = cv.make_study(mini, tmp_path, {"width": (1, 2)})
    rows = cr.comparison_rows(study)
    assert rows and not any(r["finished"] for r in rows)
    assert cr.coarsest_converged(study, rows) == {"width": None}
    cr.write_report(study)
    assert "not run" in (tmp_path / "convergence.md").read_text()


@pytest.mark.parametrize("slope, converged", [(0.25, False), (0.02, True)])
def test_a_linear_series_extrapolates_to_its_intercept_and_the_verdict_follows_it(mini, tmp_path, monkeypatch,
                                                                                 slope, converged):
    """q(s) = q0 (1 + slope s), 1 % errors: the extrapolated value is q0, the reference's error slope q0 with the
    propagated standard error; converged only when that error plus two standard errors is within 10 %."""
    base = {"drawbar_pull": 500.0, "lateral_force": -200.0, "vertical_force": 3000.0, "torque": 600.0,
            "sinkage": 0.08, "tread_slip": 0.3}

    def values(lv):
        out = {"steady": True, "wall_seconds": 1.0, "particles": 1, "dem_time_step": 1e-5}
        for q, v in base.items():
            m = v * (1 + slope * lv.scale)
            out[q] = (m, 0.01 * abs(m))
        return out

    study = cv.make_study(mini, tmp_path, {"particle_size": (1, 0.8, 0.64), "depth": (1, 2)})
    monkeypatch.setattr(cr, "_level_values", values)
    rows = {r["quantity"]: r for r in cr.extrapolation_rows(study)}
    assert set(rows) == set(cv.QUANTITIES) and all(r["factor"] == "particle_size" for r in rows.values())
    r = rows["drawbar_pull"]
    assert r["value"] == pytest.approx(500.0, rel=1e-9)
    assert r["reference_error"] == pytest.approx(slope * 500.0, rel=1e-9)
    assert r["birge"] == 1.0 and r["dof"] == 1 and r["reference_error_se"] > 0
    assert all(x["converged"] is converged for x in rows.values())
    cr.write_report(study)
    text = (tmp_path / "convergence.md").read_text()
    assert "## Extrapolated to zero scale" in text
    assert ("particle_size: converged: extrapolated" in text) is converged
    assert ("particle_size: **not converged**: extrapolated" in text) is not converged


def test_replicas_excess_spread_widens_every_levels_error(mini, tmp_path, monkeypatch):
    """The same linear series with 1 % errors (slope 0.02: converged on its own errors) is not converged once the
    replicas' excess spread (here 10 % of each value) is added in quadrature to every level: the errors, and so the
    extrapolation's, grow as the quadrature sum says; the means do not move."""
    from wheelsoil.cases.replicas import ReplicaSpread

    base = {"drawbar_pull": 500.0, "lateral_force": -200.0, "vertical_force": 3000.0, "torque": 600.0,
            "sinkage": 0.08, "tread_slip": 0.3}

    def values(lv):
        out = {"steady": True, "wall_seconds": 1.0, "particles": 1, "dem_time_step": 1e-5}
        for q, v in base.items():
            m = v * (1 + 0.02 * lv.scale)
            out[q] = (m, 0.01 * abs(m))
        return out

    study = cv.make_study(mini, tmp_path, {"particle_size": (1, 0.8, 0.64)})
    monkeypatch.setattr(cr, "_level_values", values)
    excess = {q: 0.1 * abs(v) for q, v in base.items()}
    plain = {r["quantity"]: r for r in cr.extrapolation_rows(study)}
    wide = {r["quantity"]: r for r in cr.extrapolation_rows(study, excess)}
    for q in base:
        assert wide[q]["value"] == pytest.approx(plain[q]["value"], rel=1e-9)
        assert plain[q]["converged"] and not wide[q]["converged"]
        assert wide[q]["value_se"] > 5 * plain[q]["value_se"]
    one = values(study.levels["particle_size"][0])
    widened = cr.with_excess(one, excess)
    assert widened["drawbar_pull"] == (one["drawbar_pull"][0], pytest.approx(math.hypot(0.01 * 510.0, 50.0)))
    assert cr.with_excess(one, None) is one and cr.with_excess(None, excess) is None
    rows = cr.comparison_rows(study, excess)
    r = next(r for r in rows if r["coarse_scale"] == 1.0 and r["quantity"] == "torque")
    assert r["change_sem"] == pytest.approx(math.hypot(math.hypot(0.01 * 612.0, 60.0), math.hypot(0.01 * 609.6, 60.0)))
    spread = ReplicaSpread({q: 1.0 for q in base}, excess, {q: 0.2 * abs(v) for q, v in base.items()}, 5,
                           "replicas.json")
    cr.write_report(study, spread)
    text = (tmp_path / "convergence.md").read_text()
    assert "excess spread that the 5 replicas of replicas.json measured added in quadrature" in text


def test_a_bad_replicas_file_is_refused_before_any_work(tmp_path, capsys):
    from wheelsoil.cases.cli import EXIT_INPUT, main

    bad = tmp_path / "replicas.json"
    bad.write_text("{}")
    assert main(["convergence", "mini-1g-steer", "--out", str(tmp_path / "c"), "--replicas", str(bad)]) == EXIT_INPUT
    err = capsys.readouterr().err
    assert "--replicas" in err and "not a replicas.json" in err and "Traceback" not in err
    assert not (tmp_path / "c").exists()


@pytest.mark.parametrize("with_replicas", [False, True])
def test_the_documented_scale_errors_are_what_the_stored_study_gives(with_replicas, capsys, monkeypatch):
    """docs/testbed-numbers.md's extrapolation tables (without and with the replicas' spread) are what
    docs/convergence_extrapolate.py prints from the stored study and the stored replicas: an example that is a test,
    so the tables cannot drift from their command."""
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("docs_convergence_extrapolate",
                                                  root / "docs" / "convergence_extrapolate.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    monkeypatch.chdir(root)
    argv = ["docs/convergence/smoke-1g-steer/convergence.json"]
    if with_replicas:
        argv += ["--replicas", "docs/replicas/smoke-1g-steer/replicas.json"]
    assert script.main(argv) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("| particle_size")
            or line.startswith("| time_step") or line.startswith("| mesh")]
    assert len(rows) == 18
    documented = (root / "docs" / "testbed-numbers.md").read_text()
    missing = [row for row in rows if row not in documented]
    assert not missing, missing


def test_the_documented_error_budget_is_what_the_stored_studies_give(capsys, monkeypatch):
    """docs/testbed-numbers.md's error budget is what docs/error_budget.py prints from the stored studies and replicas;
    and its combination is the root-sum-square it states."""
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("docs_error_budget", root / "docs" / "error_budget.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    monkeypatch.chdir(root)
    assert script.main([]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("| ")][1:]  # after the header
    assert len(rows) == len(cv.QUANTITIES)
    documented = (root / "docs" / "testbed-numbers.md").read_text()
    assert not [row for row in rows if row not in documented]
    # the combination, recomputed from the printed cells of the drawbar pull's row
    cells = [c.strip() for c in rows[0].strip("|").split("|")]
    pairs = [tuple(float(x) for x in c.split(" ± ")) for c in cells[3:8]]
    scale_error = math.sqrt(sum(e * e + u * u for e, u in pairs))
    assert float(cells[8]) == pytest.approx(scale_error, abs=0.6)
    assert float(cells[9]) == pytest.approx(math.hypot(scale_error, float(cells[2])), abs=0.6)
