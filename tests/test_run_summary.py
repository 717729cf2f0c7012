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
    assert s.drawbar_pull.mean == s.mean("drawbar_pull") == 0.0 and s.quantity("tread_slip").sem == pytest.approx(
        0.01 * SUMMARY_QUANTITIES.index("tread_slip"))
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


def test_the_protocol_state_round_trips_through_a_checkpoint_and_refuses_unknown_keys(tmp_path):
    """The testbed's protocol state goes to a checkpoint file as plain scalars and comes back equal (inf times,
    the phase's name, the counters); a checkpoint from an older version, without the later keys, reads with their
    defaults; an unknown key or phase is refused."""
    import numpy as np

    from wheelsoil.cases.run import load_checkpoint, save_checkpoint
    from wheelsoil.coupling.protocol_state import ProtocolState

    state = ProtocolState(phase="drive", t_release=0.4, t_spin=0.5, t_windup=0.9, t_hold=1.2, t_average_from=1.5,
                          next_check=2.0, hub_angle=3.1, hub_spin=1.7, omega_filtered=1.6, tread_angle=3.0,
                          shift=0.02, windup_converged=True, steady_in_a_row=1)
    save_checkpoint(tmp_path / "c.h5", {"loop": state.to_dict(), "x": np.zeros(2)}, {"t": 2.0})
    back, _ = load_checkpoint(tmp_path / "c.h5")
    assert ProtocolState.from_dict(back["loop"]) == state
    assert ProtocolState.from_dict(ProtocolState().to_dict()) == ProtocolState()
    older = {k: v for k, v in state.to_dict().items() if k not in ("t_average_from", "steady_in_a_row", "tread_angle")}
    restored = ProtocolState.from_dict(older)
    assert restored.t_average_from == math.inf and restored.steady_in_a_row == 0 and restored.tread_angle is None
    with pytest.raises(ValueError, match="unknown keys"):
        ProtocolState.from_dict({**state.to_dict(), "loop_count": 3})
    with pytest.raises(ValueError, match="not one of"):
        ProtocolState(phase="coast")


def test_the_default_protocol_is_its_five_steps_and_skips_the_wind_up_of_a_rigid_wheel():
    """The protocol as data: lower, settle, spin-up, wind-up, drive; the wind-up applies to a flexible wheel with
    the controller only, so a rigid wheel goes from the spin-up straight to the drive, which begins at that moment."""
    from types import SimpleNamespace

    from wheelsoil.coupling.protocol import DEFAULT_PROTOCOL, advance, protocol_for
    from wheelsoil.coupling.protocol_state import PHASES, ProtocolState

    assert [s.name for s in DEFAULT_PROTOCOL] == ["lower", "settle", "spin-up", "wind-up", "drive"]
    assert {s.name for s in protocol_for(2)} == set(PHASES[1:-1])  # a further stage adds the ramp
    for rigid, windup, expected in ((True, "controller", "drive"), (False, "none", "drive"),
                                    (False, "controller", "wind-up")):
        spec = SimpleNamespace(rigid=rigid, windup=windup, spin_up_time=0.5, average_time=1.0)
        bench = SimpleNamespace(spec=spec, stage_spec=spec, pitch=0.5, batch_rate=2.0)
        state = ProtocolState(phase="spin-up", t_spin=1.0)
        assert not advance(DEFAULT_PROTOCOL, bench, state, {}, 1.2)  # the ramp goes on
        assert state.phase == "spin-up"
        assert not advance(DEFAULT_PROTOCOL, bench, state, {}, 1.5)
        assert state.phase == expected and state.t_windup == 1.5
        if expected == "drive":  # the hold: the first window a pitch later, checked average_time after that
            assert (state.t_hold, state.t_average_from, state.next_check) == (1.5, 1.75, 2.75)
