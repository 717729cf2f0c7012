"""``wheelsoil validate`` end to end: the real CMU steering data and synthetic data."""

import json
import os

import pytest

from wheelsoil.cases.cli import EXIT_INPUT, EXIT_OK, main
from wheelsoil.validation.discovery import RIVAL_MARGIN
from wheelsoil.validation.extensions import CATALOGUE_DRIFTS, DRIFT_FIELDS, EXTENSIONS
from wheelsoil.validation.workflow import validate
from wheelsoil.validation.selection import rule_digest


@pytest.mark.slow
def test_cmu_large_steering_angles_sidewall_helps_but_is_not_named(measured_dir, tmp_path):
    """On the driving rows (``--domain driving``), calibrated on the other steering angles, the classical model
    misses the lateral force at 60 deg. Schwanghart's sidewall resistance (seed 003 eq. 19) predicts the held-out
    angle better, beyond two bootstrap standard deviations, but it removes a small share of the systematic residual
    on the training angles: the model's error there follows the steering angle in forms no candidate holds. The
    honest verdict is "nothing named; these trends unexplained", with the baseline's parameters at their bounds
    flagged. (On every row, the default, the sidewall's held-out gain at 60 deg is gone, -0.08 +- 0.03, and nothing
    is named either: docs/validation/cmu-large-steering, too long a run for this tier.)"""
    findings = validate(os.path.join(measured_dir, "cmu_3d_terramechanics"), report=tmp_path, holdout="slip_angle=60",
                        domain="driving")
    sidewall = next(c for c in findings["steps"][0]["candidates"] if c["name"] == "sidewall")
    assert sidewall["gain"] > 2 * sidewall["gain_std"] > 0
    assert sidewall["gain"] == max(c["gain"] for c in findings["steps"][0]["candidates"])
    assert not sidewall["checks"]["signature"] and not sidewall["accepted"]
    assert findings["found"] == [] and findings["unexplained"]
    assert findings["baseline"]["at_bounds"]
    report = (tmp_path / "report.md").read_text()
    assert "found: nothing" in report and "unexplained: error in lateral force" in report
    for png in ("fits.png", "residuals.png", "candidates.png"):
        assert (tmp_path / png).stat().st_size > 0
    saved = json.loads((tmp_path / "findings.json").read_text())
    assert saved["n_heldout"] > 0
    assert saved["selection_rule"] == rule_digest()  # which rule made the findings


@pytest.mark.slow
def test_validate_command_on_synthetic_data_and_bad_input(tmp_path, capsys):
    out = tmp_path / "syn"
    assert main(["validate", "synthetic", "--hidden", "slip_sinkage", "--seed", "4", "--report", str(out)]) == EXIT_OK
    findings = json.loads((out / "findings.json").read_text())
    assert findings["found"] == ["slip_sinkage"]
    for s in findings["steps"]:  # booleans, not 0.0
        for c in s["candidates"]:
            assert all(type(c[k]) is bool for k in ("accepted", "named", "passes"))
            assert all(type(v) is bool for v in c["checks"].values())
    report = (out / "report.md").read_text()
    assert "Hidden: slip_sinkage" in report
    # named only after its generic rivals were fitted and fell short: every classical field drifting along every
    # condition the synthetic design varies (not only slip, the one slip_sinkage acts through), less the drifts that
    # are catalogue mechanisms themselves
    rivals = findings["steps"][0]["rivals"]
    varied = ("slip", "slip_angle", "gravity", "load", "passes")
    assert {r["name"] for r in rivals} == {f"{f} ~ {c}" for c in varied for f in DRIFT_FIELDS
                                           if (f, c) not in CATALOGUE_DRIFTS}
    assert {"cohesion ~ slip", "friction_angle ~ load", "kc_prime ~ passes", "a1 ~ slip_angle"} <= {
        r["name"] for r in rivals}
    assert all(r["bic_vs_accepted"] >= -RIVAL_MARGIN for r in rivals) and "Generic rivals" in report
    # one truth: the terminal, the report's verdict and the JSON name the same mechanisms
    terminal = capsys.readouterr().out
    verdict = report.split("## Verdict")[1].split("##")[0]
    for text in (terminal, verdict):
        assert "found: slip_sinkage" in text.replace("\n", " ")
        assert not any(f"found: {n}" in text for n in EXTENSIONS if n != "slip_sinkage")
    assert (out / "model.json").is_file()
    assert (out / "synthetic_data.csv").stat().st_size > 0
    assert main(["validate", "synthetic", "--hidden", "magic", "--report", str(out)]) == EXIT_INPUT
    assert "--hidden 'magic'" in capsys.readouterr().err
    assert main(["validate", str(tmp_path / "missing.csv"), "--report", str(out)]) == EXIT_INPUT
    assert main(["validate", "synthetic", "--holdout", "speed=3", "--report", str(out)]) == EXIT_INPUT


def test_a_rival_fitted_in_place_of_two_members_is_quoted_at_its_best():
    """A drift fitted in place of each member of a pair appears twice among the rivals; the verdict quotes the fit
    that withheld the name (the better), with the member it replaced."""
    from wheelsoil.validation.report import verdict_lines

    rival = dict(name="a1 ~ load", description="a1 varying linearly with load")
    findings = {"accepted": [], "partial": [], "unexplained": [],
                "baseline": {"unidentified": [], "at_bounds": {}},
                "steps": [{"ambiguity": ["sidewall + theta_m_slip", "a1 ~ load"],
                           "rivals": [dict(rival, replaces="theta_m_slip", bic_vs_accepted=-40.3),
                                      dict(rival, replaces="sidewall", bic_vs_accepted=461.5)]}]}
    line = next(v for v in verdict_lines(findings) if v.startswith("ambiguous"))
    assert "a1 ~ load in place of theta_m_slip" in line and "-40.3" in line and "461.5" not in line


def test_a_deferred_mechanism_is_said_and_each_verdict_quotes_its_own_rivals():
    """A step that deferred a mechanism (validation.discovery: a rival beat it, another was accepted first) says so,
    and the rivals fitted against each mechanism checked are quoted beside that mechanism only."""
    from wheelsoil.validation.report import verdict_lines

    drift = dict(name="kphi_prime ~ signed_slip", description="k'phi varying linearly with the signed slip",
                 replaces="theta_m_slip", against="theta_m_slip", bic_vs_accepted=-6.0, delta_bic=-80.0, rate=0.3)
    near = dict(drift, name="cohesion ~ load", description="cohesion varying with load", replaces="sidewall",
                against="sidewall", bic_vs_accepted=4.0)
    accepted = {"name": "sidewall", "parameters": {}, "step": 0, "delta_bic": -90.0, "gain": 0.1, "gain_std": 0.01,
                "explained": 0.8, "source": "Iagnemma"}
    findings = {"accepted": [accepted], "partial": [], "unexplained": [], "baseline": {"unidentified": [], "at_bounds": {}},
                "steps": [{"step": 0, "ambiguity": [], "deferred": [["theta_m_slip", "kphi_prime ~ signed_slip"]],
                           "rivals": [drift, near]},
                          {"step": 1, "ambiguity": ["theta_m_slip", "kphi_prime ~ signed_slip"], "deferred": [],
                           "rivals": [dict(drift, bic_vs_accepted=-3.0), dict(near, bic_vs_accepted=-9.0)]}]}
    lines = verdict_lines(findings)
    found = next(v for v in lines if v.startswith("found: sidewall"))
    assert "cohesion ~ load" not in found and "varying with load in place of sidewall" in next(
        v for v in lines if "generic drift fits about as well" in v)
    assert not any("signed slip in place of theta_m_slip" in v for v in lines if "about as well" in v)
    deferred = next(v for v in lines if v.startswith("deferred at step 1"))
    assert "theta_m_slip" in deferred and "kphi_prime ~ signed_slip" in deferred
    ambiguous = next(v for v in lines if v.startswith("ambiguous"))
    assert "kphi_prime ~ signed_slip in place of theta_m_slip" in ambiguous and "-3.0" in ambiguous
    assert "cohesion ~ load" not in ambiguous
