"""One CMU rig case run end to end (slow tier; issue 34): the grousered wheel at a measured trial's slip and load on
the calibrated sand, in a reduced bin and a short drive, so that it fits the CI budget. The full case
(``cmu-trials-subset``, 25 minutes on 2 cores) is run by its sweep; this test checks what every such run relies on:
the rig carries the trial's load, commands the lab's slip (driving i = 1 - v / (r omega), the carriage's whole
travel speed), moves its soil patch with the wheel, and the soil on the wheel pulls it forward at slip 0.5."""

import csv
from pathlib import Path

import numpy as np
import pytest

from wheelsoil.cases.build import specs
from wheelsoil.cases.run import run_case
from wheelsoil.cases.schema import load_case

#: the reduced bin (a fifth of the twin's soil) and drive; every other key is the preset's
REDUCED = ["soil.length=0.22", "soil.width=0.12", "soil.depth=0.05", "test.drive_time=0.4",
           "output.average_time=0.2", "test.stop_when_steady=false", "output.render=false",
           "output.frame_interval=0", "output.checkpoint_interval=0"]


def _trial(measured_dir, wheel="grouser", angle=0.0, slip=0.5):
    path = Path(measured_dir) / "cmu_3d_terramechanics" / f"{wheel}_wheel_trials.csv"
    with open(path, newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if float(r["steering_angle_deg"]) == angle
                and abs(float(r["slip"]) - slip) <= 0.05]
    return rows[0]


@pytest.mark.slow
def test_a_cmu_rig_case_carries_the_trials_load_at_the_labs_slip(measured_dir, bed_cache, tmp_path):
    trial = _trial(measured_dir)
    slip, load = float(trial["slip"]), float(trial["vertical_load_N"])
    case = load_case("cmu-grouser", REDUCED + [f"test.slip={slip}", f"test.load={load}"])
    outcome = run_case(case, tmp_path / "run", bed_cache=bed_cache)
    series = outcome.testbed_result.series
    t = series["t"]
    drive = t >= t[-1] - 0.3  # the last 0.3 s of the 0.4 s drive
    _, wheel, _ = specs(case)
    # the load: the soil carries W (the rig's vertical slide is free and damped), within 5 % over the drive
    assert series["vertical_force"][drive].mean() == pytest.approx(load, rel=0.05)
    # the lab's slip: the hub's spin against the carriage's whole travel speed, i = 1 - v / (r omega)
    lab_slip = 1.0 - series["slip_speed"][drive] / (wheel.radius * series["omega"][drive])
    assert lab_slip.mean() == pytest.approx(slip, abs=2e-3)
    assert series["tread_slip"][drive].mean() == pytest.approx(slip, abs=0.01)
    # the carriage travels at v = r omega (1 - i): the travel, the moving patch's shifts included, grows at that rate
    rate = np.polyfit(t[drive], series["travel"][drive], 1)[0]
    assert rate == pytest.approx(wheel.radius * case.test.angular_velocity * (1.0 - slip), rel=0.02)
    assert outcome.testbed_result.info["patch_shifts"] >= 1
    # the grousered wheel at slip 0.5 is pushed forward by the soil (the trial's drawbar pull is positive)
    assert series["drawbar_pull"][drive].mean() > 0.0
