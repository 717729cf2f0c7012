"""A change of the twin judged on held-out trials (validation/candidate_test.py): the errors are the RMS normalised
residuals computed exactly, only held-out trials that both runs reached count, and the verdict compares the gain with
the replicas' run-to-run spread."""

from dataclasses import replace

import numpy as np
import pytest

from wheelsoil.validation.calibration import response_scales
from wheelsoil.validation.candidate_test import concat_runs, judge_candidate, replica_spread
from wheelsoil.validation.measured import Measurements
from wheelsoil.validation.synthetic import conditions, synthetic_measurements

Q = ("drawbar_pull", "lateral_force")


@pytest.fixture(scope="module")
def data():
    cond = conditions(slips=(0.1, 0.3, 0.5), slip_angles=(0.0, 30.0, 60.0), loads=(20.0,), gravities=(9.81,),
                      passes=(1,))
    return synthetic_measurements({}, np.random.default_rng(3), cond=cond)


def _run(data, rows, offsets: dict):
    """The measured rows ``rows`` as a simulation, each response shifted by ``offsets[q]`` times its spread."""
    sim = data.select(np.asarray(rows))
    scales = response_scales(data, Q)
    return replace(sim, responses={q: v + offsets.get(q, 0.0) * scales.get(q, 0.0) for q, v in sim.responses.items()},
                   std={})


def _replicas(data, sd_in_spreads: float):
    """Three runs of one condition whose drawbar pull and lateral force scatter by ``sd_in_spreads`` spreads."""
    scales = response_scales(data, Q)
    reps = data.select(np.array([0, 0, 0]))
    dev = np.array([-1.0, 0.0, 1.0]) * sd_in_spreads  # std (ddof 1) of -1, 0, 1 is 1
    return replace(reps, responses={**reps.responses, **{q: reps.responses[q] + dev * scales[q] for q in Q}})


def test_the_errors_are_the_rms_normalised_residuals_of_the_held_out_trials(data):
    held = data.slip_angle > 0
    rows = np.arange(len(data))
    baseline = _run(data, rows, {"drawbar_pull": 3.0})
    # the candidate is off by one spread where held out, and far off on the trials that chose it (not judged)
    cand = _run(data, rows, {"drawbar_pull": 1.0})
    cand.responses["drawbar_pull"][~held] += 50.0 * response_scales(data, Q)["drawbar_pull"]
    v = judge_candidate(data, baseline, cand, held, replicas=_replicas(data, 0.1))
    assert v.judged_trials == int(held.sum())
    assert v.baseline_error == pytest.approx(np.sqrt(9.0 / 2.0), rel=1e-9)  # mean over both responses
    assert v.candidate_error == pytest.approx(np.sqrt(1.0 / 2.0), rel=1e-9)
    assert v.replica_spread == pytest.approx(0.1, rel=1e-9)
    assert v.verdict == "accepted" and v.gain_percent == pytest.approx(100 * (1 - 1 / 3), rel=1e-9)
    # a gain inside the run-to-run spread is not accepted; with one replica it is provisional
    assert judge_candidate(data, baseline, cand, held, replicas=_replicas(data, 2.0)).verdict == "not accepted"
    one = judge_candidate(data, baseline, cand, held, replicas=data.select(np.array([0])))
    assert one.verdict.startswith("provisional") and one.replica_spread is None


def test_only_trials_that_both_ran_are_judged(data):
    held = data.slip_angle > 0
    rows = np.arange(len(data))
    some = np.flatnonzero(held)[:2]
    baseline = _run(data, rows, {"lateral_force": 2.0})
    cand = _run(data, some, {"lateral_force": -1.0})
    v = judge_candidate(data, baseline, cand, held, replicas=_replicas(data, 0.5))
    assert v.judged_trials == 2 and v.baseline_error == pytest.approx(np.sqrt(2.0), rel=1e-9)
    assert v.candidate_error == pytest.approx(np.sqrt(0.5), rel=1e-9)
    none = judge_candidate(data, baseline, _run(data, np.flatnonzero(~held), {}), held)
    assert none.judged_trials == 0 and none.verdict.startswith("not judged")


def test_the_replica_spread_pools_the_responses():
    cond = conditions(slips=(0.3,), slip_angles=(0.0,), loads=(20.0,), gravities=(9.81,), passes=(1,))
    d = synthetic_measurements({}, np.random.default_rng(0), cond=cond)
    reps = d.select(np.array([0, 0]))
    reps = replace(reps, responses={**reps.responses, "drawbar_pull": np.array([1.0, 3.0]),
                                    "lateral_force": np.array([5.0, 5.0])})
    # drawbar pull: std (ddof 1) 1.414 over a scale of 2; lateral force none
    assert replica_spread(reps, {"drawbar_pull": 2.0, "lateral_force": 1.0}, Q) == pytest.approx(
        np.sqrt(0.5 * (np.sqrt(2.0) / 2.0) ** 2), rel=1e-12)
    assert replica_spread(d, {"drawbar_pull": 2.0, "lateral_force": 1.0}, Q) is None


def test_concat_runs_puts_the_parts_rows_one_after_another(data):
    a = data.slip_angle == 0.0
    runs = replace(data, std={"drawbar_pull": np.arange(len(data), dtype=float)})
    joined = concat_runs("both", [runs.select(a), runs.select(~a)])
    order = runs.select(np.r_[np.flatnonzero(a), np.flatnonzero(~a)])
    assert joined.name == "both" and len(joined) == len(data)
    for key in Measurements.ROW_FIELDS + ("passes", "travel_slip"):
        np.testing.assert_array_equal(getattr(joined, key), getattr(order, key), err_msg=key)
    for q in data.responses:
        np.testing.assert_array_equal(joined.responses[q], order.responses[q])
    np.testing.assert_array_equal(joined.std["drawbar_pull"], order.std["drawbar_pull"])
