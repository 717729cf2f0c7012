"""The slip conversion from the CMU rig's convention (slip against the carriage's whole speed) to wheelsoil's (against
its component along the heading): closed forms on both branches, the limits at 0 and 90 deg, and the measured rows'
own rim and carriage speeds."""

import csv
from pathlib import Path

import numpy as np
import pytest

from wheelsoil.slip import heading_slip_from_travel, longitudinal_slip, rim_speed_ratio


def test_driving_closed_form_and_limits():
    i = np.linspace(0.0, 0.95, 20)
    for beta in (0.0, 15.0, 45.0, 75.0):
        # r omega = V / (1 - i) and v_x = V cos(beta): i_h = 1 - (1 - i) cos(beta)
        np.testing.assert_allclose(heading_slip_from_travel(i, beta), 1.0 - (1.0 - i) * np.cos(np.radians(beta)),
                                   atol=1e-12)
    # at 0 deg the two conventions are one, braking included
    j = np.linspace(-1.0, 0.95, 40)
    np.testing.assert_allclose(heading_slip_from_travel(j, 0.0), j, atol=1e-12)
    # the example of the rig's data: 60 deg, rim at 20 mm/s, carriage at 10 mm/s
    assert heading_slip_from_travel(0.5, 60.0) == pytest.approx(0.75)
    # 90 deg: a turning wheel does not advance along its heading; a dragged one keeps -1, the limit along the angle
    assert np.all(heading_slip_from_travel([0.0, 0.3, -0.5], 90.0) == 1.0)
    assert heading_slip_from_travel(-1.0, 90.0) == -1.0
    assert heading_slip_from_travel(-1.0, 90.0 - 1e-9) == -1.0
    # a wheel spinning in place stays at 1 at any angle; the sign of the angle does not matter
    assert heading_slip_from_travel(1.0, 30.0) == 1.0
    assert heading_slip_from_travel(0.4, -30.0) == pytest.approx(heading_slip_from_travel(0.4, 30.0))


def test_braking_branch_and_continuity():
    # r omega = (1 + i) V; braking along the heading while r omega < V cos(beta): i_h = (1 + i) / cos(beta) - 1
    beta = 30.0
    c = np.cos(np.radians(beta))
    i = np.array([-1.0, -0.9, -0.5, -0.2])
    np.testing.assert_allclose(heading_slip_from_travel(i, beta), (1.0 + i) / c - 1.0, atol=1e-12)
    # above r omega = V cos(beta) the rig's braking row drives along the heading
    i = np.array([-0.1, -0.05])
    np.testing.assert_allclose(heading_slip_from_travel(i, beta), 1.0 - c / (1.0 + i), atol=1e-12)
    # continuous through the rig's i = 0 and through the heading's i_h = 0 (at i = cos(beta) - 1)
    for at in (0.0, c - 1.0):
        assert heading_slip_from_travel(at - 1e-9, beta) == pytest.approx(heading_slip_from_travel(at + 1e-9, beta),
                                                                            abs=1e-7)
    np.testing.assert_allclose(rim_speed_ratio([-1.0, -0.5, 0.0, 0.5, 0.75]), [0.0, 0.5, 1.0, 2.0, 4.0])
    np.testing.assert_allclose(longitudinal_slip(1.0, rim_speed_ratio([-0.7, 0.0, 0.6]), 1.0), [-0.7, 0.0, 0.6])


def test_measured_rows_rim_and_carriage_speeds(measured_dir):
    """Each CMU row's converted slip against the heading slip of its own rim and carriage speeds (v_x = V cos beta):
    equal to 0.02 where the row's recorded slip is the one its nominal speeds give (the 12 mm/s rows ran at 13)."""
    folder = Path(measured_dir) / "cmu_3d_terramechanics"
    checked = 0
    for wheel in ("smooth", "grouser"):
        with open(folder / f"{wheel}_wheel_trials.csv", newline="") as fh:
            for row in csv.DictReader(fh):
                v, rim = float(row["carriage_speed_mm_s"]), float(row["rim_speed_mm_s"])
                beta, slip = float(row["steering_angle_deg"]), float(row["slip"])
                if abs(longitudinal_slip(v, rim, 1.0) - slip) > 0.02:
                    continue
                direct = longitudinal_slip(v * np.cos(np.radians(beta)), rim, 1.0) if beta < 90 else (
                    1.0 if rim > 0 else -1.0)
                assert heading_slip_from_travel(slip, beta) == pytest.approx(direct, abs=0.02), row
                checked += 1
    assert checked > 250
