"""Replicas: the sweep over seeds, and the statistics that say whether a run's own error bars hold, checked on
synthetic campaigns with known spread (honest error bars: inflation about 1, coverage about 95 %; error bars three
times too small: inflation about 3, coverage far below)."""

import math
from dataclasses import replace

import numpy as np
import pytest

from wheelsoil.cases.replicas import (QUANTITIES, check_seeds, make_replicas, replica_statistics, report_markdown,
                                     ReplicaSpread)
from wheelsoil.cases.schema import load_case
from wheelsoil.coupling.run_summary import QuantityStats, RunSummary
from wheelsoil.errors import WheelsoilInputError


def _campaign(rng, n, sigma, stated, steady=True):
    """n replica summaries: every quantity's mean drawn from N(truth, sigma), its stated sem ``stated`` and its
    ci95 the normal 1.96 x sem."""
    out = []
    for seed in range(n):
        quantities = {q: QuantityStats(100.0 + rng.normal(0.0, sigma), math.nan, sem=stated, ci95=1.96 * stated)
                      for q in QUANTITIES}
        out.append((seed, RunSummary(steady=steady, window=(0.0, 1.0), samples=10, pitches=4, pitch_deg=45.0,
                                     period_pitches=1, reasons=(), commanded_slip=0.3, commanded_slip_angle=0.0,
                                     **quantities)))
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("stated, inflation, coverage", [(2.0, (0.9, 1.1), (0.93, 0.97)),
                                                         (2.0 / 3.0, (2.7, 3.3), (0.0, 0.6))])
def test_inflation_and_coverage_on_synthetic_campaigns(seed, stated, inflation, coverage):
    rng = np.random.default_rng(seed)
    factors, covered, runs, inside = [], 0, 0, 0
    for _ in range(300):
        stats = replica_statistics(_campaign(rng, 5, 2.0, stated))
        r = stats["quantities"]["drawbar_pull"]
        factors.append(r["inflation"])
        covered += r["covered"]
        runs += r["coverage_runs"]
        lo, hi = r["inflation_interval"]
        inside += lo <= 2.0 / stated <= hi
    # the mean of s / sigma over n = 5 is c4 = 0.940; the interval holds the true factor 95 % of the time
    assert inflation[0] <= np.mean(factors) / 0.940 <= inflation[1]
    assert coverage[0] <= covered / runs <= coverage[1]
    assert 0.92 <= inside / 300 <= 0.98


def test_runs_not_steady_or_not_finished_are_left_out_and_said(tmp_path):
    rng = np.random.default_rng(0)
    summaries = _campaign(rng, 3, 1.0, 1.0) + [(7, _campaign(rng, 1, 1.0, 1.0, steady=False)[0][1]), (8, None)]
    stats = replica_statistics(summaries)
    assert stats["steady"] == [0, 1, 2] and stats["finished"] == [0, 1, 2, 7]
    assert stats["quantities"]["torque"]["n"] == 3
    text = report_markdown("mini", stats)
    assert "not steady, left out: 7" in text and "| torque [N m] |" in text
    one = replica_statistics(summaries[:1])
    assert "fewer than two steady replicas" in report_markdown("mini", one)


def test_replicas_are_the_case_at_other_seeds(tmp_path):
    base = load_case("mini-1g-steer")
    sweep = make_replicas(base, [0, 1, 2], tmp_path)
    assert [c.case.case.seed for c in sweep.cases] == [0, 1, 2]
    assert len({c.folder for c in sweep.cases}) == 3
    for c in sweep.cases:
        assert c.case.model_copy(update={"case": base.case}).test == base.test and c.case.soil == base.soil


@pytest.mark.parametrize("seeds", [[0], [1, 1], [-1, 2], ["a", 2], [0.5, 1]])
def test_bad_seeds_are_refused(seeds):
    with pytest.raises(WheelsoilInputError, match="--seeds"):
        check_seeds(seeds)
    assert math.isfinite(check_seeds([0, 3])[1])


@pytest.mark.parametrize("seeds", [["0"], ["0", "x"]])
def test_the_command_refuses_bad_seeds_before_any_work(seeds, tmp_path, capsys):
    from wheelsoil.cases.cli import EXIT_INPUT, main

    assert main(["replicate", "mini-1g-steer", "--out", str(tmp_path / "r"), "--seeds", *seeds]) == EXIT_INPUT
    err = capsys.readouterr().err
    assert "--seeds" in err and "Traceback" not in err
    assert not (tmp_path / "r").exists()


def test_the_command_refuses_a_bad_widening_file_before_any_work(tmp_path, capsys):
    from wheelsoil.cases.cli import EXIT_INPUT, main

    bad = tmp_path / "bad.json"
    bad.write_text("not json")
    assert main(["replicate", "mini-1g-steer", "--out", str(tmp_path / "r"), "--seeds", "0", "1",
                 "--widen-by", str(bad)]) == EXIT_INPUT
    err = capsys.readouterr().err
    assert "--widen-by" in err and "not a replicas.json" in err and "Traceback" not in err
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_factors_set_on_one_replica_set_restore_coverage_on_another(seed, tmp_path):
    """Error bars three times too small: the factor one campaign of 5 replicas measures, applied to fresh ones,
    brings their coverage near the claimed 95 %; the spread between beds is recovered beside the stated error."""
    import json

    rng = np.random.default_rng(100 + seed)
    covered, widened, runs, factors, between = 0, 0, 0, [], []
    for _ in range(200):
        first = replica_statistics(_campaign(rng, 5, 2.0, 2.0 / 3.0))
        path = tmp_path / "replicas.json"
        path.write_text(json.dumps(first))
        widening = ReplicaSpread.read(path)
        factors.append(widening.factors["drawbar_pull"])
        r = replica_statistics(_campaign(rng, 5, 2.0, 2.0 / 3.0), widening)["quantities"]["drawbar_pull"]
        covered += r["covered"]
        widened += r["covered_widened"]
        runs += r["coverage_runs"]
        between.append(r["excess_spread"] ** 2)
    assert covered / runs < 0.6
    # Student's t at 4 dof carries the factor's own scatter: the widened intervals hold about 95 % of the time (a
    # normal 1.96 f sem would hold 88 %: P(|T_4| < 1.96))
    assert 0.92 <= widened / runs <= 0.98, widened / runs
    assert 2.7 <= np.mean(factors) / 0.940 <= 3.3  # E[s] = c4 sigma, c4 = 0.940 for n = 5
    # E[s^2] - sem^2 = sigma^2 - sem^2 = 4 - 4/9
    assert np.mean(between) == pytest.approx(4.0 - 4.0 / 9.0, rel=0.1)


def test_replicas_mean_interval_and_report_columns(tmp_path):
    import json
    from scipy.stats import t as student_t

    rng = np.random.default_rng(5)
    stats = replica_statistics(_campaign(rng, 4, 1.0, 0.5), ReplicaSpread({q: 2.0 for q in QUANTITIES},
                                                                          {q: 0.0 for q in QUANTITIES},
                                                                          {q: 1.0 for q in QUANTITIES}, 5, "x"))
    r = stats["quantities"]["sinkage"]
    assert r["mean_ci95"] == pytest.approx(student_t.ppf(0.975, 3) * r["spread"] / 2.0)
    assert r["covered"] <= r["covered_widened"] <= r["coverage_runs"] == 4
    # a factor of 1 from many replicas (t near 1.96) never narrows a run's own wider interval
    unit = ReplicaSpread({q: 1.0 for q in QUANTITIES}, {q: 0.0 for q in QUANTITIES}, {q: 1.0 for q in QUANTITIES},
                         1000, "x")
    wide_own = [(seed, replace(summary, **{q: replace(summary.quantity(q), ci95=100.0) for q in QUANTITIES}))
                for seed, summary in _campaign(rng, 4, 1.0, 0.5)]
    assert replica_statistics(wide_own, unit)["quantities"]["torque"]["covered_widened"] == 4
    stats["widened_by"] = {"source": "other/replicas.json", "replicas": 5, "factors": {}}
    text = report_markdown("mini", stats)
    assert "coverage widened" in text and "5 replicas of other/replicas.json" in text and " 2.00 | " in text
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    with pytest.raises(WheelsoilInputError, match=r"--widen-by .*bad.json: not a replicas.json"):
        ReplicaSpread.read(bad)
    with pytest.raises(WheelsoilInputError, match="not a replicas.json"):
        ReplicaSpread.read(tmp_path / "missing.json")
    ok = tmp_path / "ok.json"
    quantities = {"drawbar_pull": {"inflation": 2.5, "excess_spread": 3.0, "spread": 4.0},
                  "torque": {"inflation": 0.4, "excess_spread": None}}
    ok.write_text(json.dumps({"steady": [0, 1, 2], "quantities": quantities}))
    widening = ReplicaSpread.read(ok)
    assert widening.factors["drawbar_pull"] == 2.5 and widening.factors["torque"] == 1.0
    assert widening.excess["drawbar_pull"] == 3.0 and widening.excess["torque"] == 0.0
    assert widening.spread["drawbar_pull"] == 4.0 and math.isnan(widening.spread["torque"])
    assert widening.factors["sinkage"] == 1.0 and widening.replicas == 3
    assert widening.half_width("drawbar_pull", 1.0) == pytest.approx(student_t.ppf(0.975, 2) * 2.5)
    one = tmp_path / "one.json"
    one.write_text(json.dumps({"steady": [0], "quantities": {}}))
    with pytest.raises(WheelsoilInputError, match="1 steady replicas; a spread needs at least two"):
        ReplicaSpread.read(one)


def test_a_steady_run_says_its_intervals_are_within_the_run():
    from wheelsoil.cases.commands.run import summary_lines

    rng = np.random.default_rng(0)
    steady = _campaign(rng, 1, 1.0, 1.0)[0][1]
    assert any("wheelsoil replicate" in line for line in summary_lines(steady))
    unsteady = _campaign(rng, 1, 1.0, 1.0, steady=False)[0][1]
    assert not any("wheelsoil replicate" in line for line in summary_lines(unsteady))
