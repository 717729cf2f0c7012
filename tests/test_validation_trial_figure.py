"""The trials' figure: panels framed on the measured points, models that leave the frame said so."""

from pathlib import Path

import numpy as np
import pytest

from wheelsoil.validation.measured import load_cmu_file
from wheelsoil.validation.trial_figure import ModelPoints, frame_limits, plot_trials


def test_the_frame_holds_the_measured_points_and_the_runs_not_a_runaway_model(measured_dir, tmp_path):
    """On the CMU grouser trials, the frame of each response spans the measured means with their std and a run's
    points, 10 % beyond, whatever a model line does (here one 10 times the measured drawbar pull); the figure is
    written."""
    data = load_cmu_file(Path(measured_dir) / "cmu_3d_terramechanics" / "grouser_wheel_trials.csv")
    runs = ModelPoints(rows=np.array([0, 5]), responses={"drawbar_pull": np.array([55.0, -60.0]),
                                                         "lateral_force": np.array([0.0, 0.0])},
                       std={"drawbar_pull": np.array([2.0, 2.0])})
    lo, hi = frame_limits(data, "drawbar_pull", {"twin": runs})
    y, s = data.responses["drawbar_pull"], data.std["drawbar_pull"]
    top, bottom = max(np.nanmax(y + s), 57.0), min(np.nanmin(y - s), -62.0)
    assert (lo, hi) == pytest.approx((bottom - 0.1 * (top - bottom), top + 0.1 * (top - bottom)), rel=1e-12)
    runaway = {q: 10.0 * data.responses[q] for q in ("drawbar_pull", "lateral_force")}
    path = plot_trials(data, {"runaway": runaway}, tmp_path / "trials.png", points={"twin": runs})
    assert path.stat().st_size > 10_000
