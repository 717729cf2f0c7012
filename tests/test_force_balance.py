"""The force balance's arithmetic (coupling/force_balance.py) on a hand-made account: each column the vertical
component of its impulse over the interval, the residual the momentum's rate less their sum."""

import math

import numpy as np
import pytest

from wheelsoil.coupling.force_balance import BALANCE_UNITS, balance_row
from wheelsoil.flexwheel.structure import MomentumAccount


def test_the_columns_are_the_impulses_over_the_interval_and_the_residual_their_shortfall():
    account = MomentumAccount(contact=np.array([1.0, 2.0, 30.0]), damping=np.array([0.0, 0.0, -0.5]),
                              reaction=np.array([5.0, 0.0, 2.0]), duration=0.5)
    weight = np.array([0.0, 0.0, -20.0])
    # rig: 12 N down of which 2 N is the damper; momentum changed by exactly the impulses but 0.1 N s
    momentum_change = np.array([0.0, 0.0, (60.0 - 10.0 - 2.0 + 4.0 - 1.0 - 20.0) * 0.5 + 0.1])
    row = balance_row(account, momentum_change, np.array([0.0, 0.0, -12.0]), -2.0, weight)
    assert list(row) == list(BALANCE_UNITS)
    assert row["vertical_force_applied"] == 60.0 and row["structural_damping"] == -1.0
    assert row["slide_reaction"] == 4.0 and row["rig_load"] == -10.0 and row["slide_damper"] == -2.0
    assert row["weight"] == -20.0
    assert row["balance_residual"] == pytest.approx(0.2)  # 0.1 N s over 0.5 s
    empty = balance_row(MomentumAccount(np.zeros(3), np.zeros(3), np.zeros(3), 0.0), np.zeros(3), np.zeros(3), 0.0,
                        weight)
    assert all(math.isnan(v) for v in empty.values())  # no step taken: nothing to balance


def test_a_checkpoint_from_before_the_balance_continues_with_its_columns_unknown():
    """A run checkpointed before the balance was recorded (the CMU twin's queue resumes such runs) continues: the
    balance's columns are NaN for the samples it had; a checkpoint with another column is refused."""
    from wheelsoil.coupling.run_summary import SERIES_UNITS
    from wheelsoil.coupling.testbed import checkpoint_rows
    from wheelsoil.errors import WheelsoilInputError

    old = {k: np.arange(3.0) for k in SERIES_UNITS if k not in BALANCE_UNITS}
    rows = checkpoint_rows(old)
    assert set(rows) == set(SERIES_UNITS)
    assert all(np.isnan(rows[k]).all() and len(rows[k]) == 3 for k in BALANCE_UNITS)
    assert np.array_equal(rows["drawbar_pull"], np.arange(3.0))
    with pytest.raises(WheelsoilInputError, match="do not match"):
        checkpoint_rows({**old, "something_else": np.zeros(3)})


def test_the_run_summary_prints_the_balance_where_it_was_recorded():
    """``wheelsoil run``'s summary lines give the soil's force as the wheel integrated it and the residual; a result
    from before the balance was recorded prints no such line."""
    from result_files import summary

    from wheelsoil.cases.commands.run import summary_lines

    recorded = summary(0.3, vertical_force_applied=(497.4, 6.2), balance_residual=(-4.5e-13, 4e-14))
    line = [s for s in summary_lines(recorded) if "force balance" in s]
    assert len(line) == 1 and "497.4 N" in line[0] and "-4.5e-13 N" in line[0]
    assert not any("force balance" in s for s in summary_lines(summary(0.3)))
