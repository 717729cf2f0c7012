"""Leave-one-condition-out cross-validation (``wheelsoil validate DATA --cv CONDITION``): a mechanism hidden in
every level is found on the rest and gains on the held-out level; a fold's final model is the classical one
unless something was accepted; the report lists found, partial and unexplained per fold."""

from types import SimpleNamespace

import numpy as np
import pytest

from wheelsoil.validation.crossval import carry_verdicts, cross_validate, write_cross_validation
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
    folds_table, _, carry_table = md.partition("## Does each finding carry to the level held out?")
    assert folds_table.count("\n| ") == 1 + len(folds)  # header and one row per fold (the separator starts with "|-")
    carried = [v for v in carry_verdicts(cv) if v["mechanism"] == "slip_sinkage"]
    assert carried and carried[0]["not_carried"] == [] and "| slip_sinkage |" in carry_table


def test_a_cross_validation_resumes_from_its_finished_folds(tmp_path, monkeypatch):
    """Finished folds are kept and reused; a different seed recomputes them. The workflow is replaced by the
    classical model at its starting soil (the bookkeeping is under test, not the selection)."""
    from types import SimpleNamespace

    from wheelsoil.validation import crossval
    from wheelsoil.validation.terramechanics import SoilParameters

    calls = []

    def classical_only(data, *, responses, heldout, **kw):
        calls.append(int(heldout.sum()))
        fit = SimpleNamespace(soil=SoilParameters())
        return SimpleNamespace(baseline=fit, final=fit, responses=tuple(responses), scales={q: 1.0 for q in responses},
                               found=[], partial=[], ambiguities=[], unexplained=[])

    monkeypatch.setattr(crossval, "discover", classical_only)
    rng = np.random.default_rng(7)
    data = synthetic_measurements({}, rng, cond=conditions(gravities=(9.81,), loads=(60.0,)))
    run = lambda seed: cross_validate(data, "slip_angle", responses=("drawbar_pull",), seed=seed,  # noqa: E731
                                      bootstrap=50, resume_dir=tmp_path)
    first = run(1)
    assert len(calls) == len(first["folds"]) == len(list(tmp_path.glob("fold-*.json"))) == 4
    calls.clear()
    assert run(1) == first and calls == []
    (tmp_path / "fold-1.json").unlink()  # a fold lost: only it runs again, to the same numbers
    assert run(1) == first and calls == [5]
    calls.clear()
    run(2)
    assert len(calls) == 4  # another seed matches no saved fold
    calls.clear()
    monkeypatch.setattr(crossval, "rule_digest", lambda: "another rule")
    run(2)
    assert len(calls) == 4  # folds saved under another selection rule are computed again


def test_the_rule_digest_follows_the_rivals_and_margins(monkeypatch):
    """The selection rule's digest changes with a margin and with the conditions the rivals drift along."""
    from wheelsoil.validation import selection, terramechanics

    before = selection.rule_digest()
    assert selection.rule_digest() == before
    monkeypatch.setattr(selection, "RIVAL_MARGIN", selection.RIVAL_MARGIN + 1.0)
    assert selection.rule_digest() != before
    monkeypatch.undo()
    fewer = {k: v for k, v in terramechanics.DRIFT_MEASURES.items() if k != "signed_slip"}
    monkeypatch.setattr(selection, "DRIFT_MEASURES", fewer)
    assert selection.rule_digest() != before


def _fold(level, gain, gain_std, found=(), partial=()):
    return {"level": level, "rows": 27, "found": list(found), "partial": list(partial), "ambiguities": [],
            "unexplained": [], "classical_nrmse": 1.0, "final_nrmse": 1.0 - gain, "gain": gain, "gain_std": gain_std}


def test_a_finding_that_does_not_carry_to_a_held_out_level_is_reported_as_not_carrying(tmp_path):
    """Per mechanism in any fold's final model: the levels where its fold's held-out gain exceeds two bootstrap
    standard deviations (carried) and where it does not; named in fewer folds than there are, it is not a stable
    finding. Hand-built folds, so every branch is met: one mechanism carried everywhere, one nowhere, one in part."""
    cv = {"condition": "slip_angle", "selection_rule": "x", "found_in": {"a": 4, "c": 1},
          "folds": [_fold(0.0, 0.30, 0.05, found=["a"], partial=["b"]),
                    _fold(30.0, 0.10, 0.06, found=["a"], partial=["b"]),  # 0.10 < 2 x 0.06: not carried
                    _fold(60.0, 0.21, 0.10, found=["a", "c"]),  # 0.21 > 2 x 0.10: carried
                    _fold(90.0, 0.50, 0.02, found=["a"], partial=["c"])]}
    v = {x["mechanism"]: x for x in carry_verdicts(cv)}
    assert v["a"]["carried"] == [0.0, 60.0, 90.0] and v["a"]["not_carried"] == [30.0]
    assert v["a"]["verdict"] == "carries to some levels held out, not to others"
    assert v["b"]["partial"] == [0.0, 30.0] and v["b"]["named"] == [] and v["b"]["not_carried"] == [30.0]
    assert v["c"]["named"] == [60.0] and v["c"]["partial"] == [90.0] and v["c"]["not_carried"] == []
    assert v["c"]["verdict"] == ("carries to every level held out where it is in the model; named in 1 of 4 folds "
                                 "only: not a stable finding")
    only_30 = {**cv, "folds": [f for f in cv["folds"] if f["level"] == 30.0]}
    assert carry_verdicts(only_30)[0]["verdict"] == "does not carry: no held-out gain where it is in the model"
    md = write_cross_validation(cv, SimpleNamespace(name="hand-built folds"), tmp_path).read_text()
    assert "| a | 0, 30, 60, 90 | – | 0, 60, 90 | 30 | carries to some levels held out, not to others |" in md
    assert "| c | 60 | 90 | 60, 90 | – |" in md
