"""Replicas: the sweep over seeds, and the statistics that say whether a run's own error bars hold, checked on
synthetic campaigns with known spread (honest error bars: inflation about 1, coverage about 95 %; error bars three
times too small: inflation about 3, coverage far below)."""

import math

import numpy as np
import pytest

from wheelsoil.cases.replicas import QUANTITIES, check_seeds, make_replicas, replica_statistics, report_markdown
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
