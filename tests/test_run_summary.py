"""The typed run summary (issue 38 item 4): what the testbed returns, the writer stores and every reader reads back
by attribute; the stored layout round-trips, unknown quantities are refused by name, and results written before a
field existed still read."""

import json
import math

import pytest

from wheelsoil.coupling.run_summary import SUMMARY_QUANTITIES, QuantityStats, RunSummary


def _summary(**changes):
    quantities = {q: QuantityStats(float(k), 0.1 * k, sem=0.01 * k, ci95=0.02 * k, dof=7.0, drift=0.001 * k,
                                   drift_sem=0.002, units="N", zero_within_noise=(k % 2 == 0) if k < 5 else None)
                  for k, q in enumerate(SUMMARY_QUANTITIES)}
    base = dict(steady=True, window=(1.25, 4.5), samples=130, pitches=16, pitch_deg=22.5, period_pitches=2,
                reasons=(), commanded_slip=0.5, commanded_slip_angle=45.0)
    return RunSummary(**{**base, **quantities, **changes})


def test_the_stored_layout_round_trips_through_json():
    s = _summary(steady=False, reasons=("drawbar_pull drifts",))
    stored = json.loads(json.dumps(s.to_dict()))
    assert stored["window"] == [1.25, 4.5] and stored["reasons"] == ["drawbar_pull drifts"]
    assert stored["torque"]["mean"] == 3.0 and "zero_within_noise" not in stored["tread_slip"]
    assert RunSummary.from_dict(stored) == s


def test_quantities_are_read_by_attribute_and_an_unknown_one_is_named():
    s = _summary()
    assert s.drawbar_pull.mean == s.mean("drawbar_pull") == 0.0 and s.quantity("tread_slip").sem == pytest.approx(0.1)
    assert list(s.quantities()) == list(SUMMARY_QUANTITIES)
    with pytest.raises(KeyError, match="no quantity 'drawbar'.*drawbar_pull"):
        s.quantity("drawbar")


def test_a_result_written_before_a_field_existed_still_reads():
    """An older summary: no period_pitches, no tread slip angle, no drift_sem."""
    old = {"steady": True, "window": [0.5, 2.0], "samples": 40, "pitches": 6, "pitch_deg": 30.0,
           "drawbar_pull": {"mean": 9.0, "std": 3.0, "sem": 0.4, "ci95": 0.9, "dof": 5.0, "drift": 0.1, "units": "N"}}
    s = RunSummary.from_dict(old)
    assert s.period_pitches == 1 and s.reasons == () and s.drawbar_pull.sem == 0.4
    assert math.isnan(s.drawbar_pull.drift_sem) and math.isnan(s.tread_slip_angle.mean)
