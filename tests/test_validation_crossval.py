"""Leave-one-condition-out cross-validation (``wheelsoil validate DATA --cv CONDITION``): a mechanism hidden in
every level is found on the rest and gains on the held-out level; a fold's final model is the classical one
unless something was accepted; the report lists found, partial and unexplained per fold."""

import numpy as np
import pytest

from wheelsoil.validation.crossval import cross_validate, write_cross_validation
from wheelsoil.validation.discovery import RESPONSES
from wheelsoil.validation.synthetic import conditions, draw_hidden_effect, synthetic_measurements


@pytest.mark.slow
@pytest.mark.parametrize("seed", [51, 52])
def test_a_hidden_mechanism_carries_to_every_held_out_steering_angle(seed, tmp_path):
    rng = np.random.default_rng(seed)
    _, hidden = draw_hidden_effect(rng, ["slip_sinkage"])
    data = synthetic_measurements(hidden, rng, cond=conditions(gravities=(9.81,), loads=(60.0, 120.0)))
    cv = cross_validate(data, "slip_angle", responses=RESPONSES, seed=seed, bootstrap=200)
    folds = cv["folds"]
    assert [f["level"] for f in folds] == [0.0, 10.0, 20.0, 30.0]
    assert set(cv["found_in"]) <= {"slip_sinkage"}, cv["found_in"]
    assert cv["found_in"].get("slip_sinkage", 0) >= 3, (cv["found_in"], hidden)
    for f in folds:
        if f["found"] or f["partial"]:
            assert f["gain"] > 2 * f["gain_std"], f  # n1 in 0.3-0.8 moves sinkage and drawbar pull strongly
        else:
            assert f["final_nrmse"] == f["classical_nrmse"]
    md = write_cross_validation(cv, data, tmp_path, command="wheelsoil validate synthetic --cv slip_angle").read_text()
    assert "| held-out slip_angle | rows | found on the rest | unexplained on the rest |" in md
    assert md.count("\n| ") == 1 + len(folds)  # header and one row per fold (the separator starts with "|-")
