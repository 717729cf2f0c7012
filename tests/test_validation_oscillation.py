"""Amplitude mechanisms of periodic effects (validation/oscillation.py): verified against closed forms, then
found when hidden in synthetic drawbar-pull series, and not found where nothing (or no mechanism) is hidden."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import quad

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.validation import oscillation as osc
from wheelsoil.validation import synthetic as syn
from wheelsoil.validation.terramechanics import RigidWheel, effective_radius, predict

WHEEL = syn.SMOOTH_WHEEL


def _cond(slip=(0.1, 0.3, 0.5), load=(50.0, 100.0, 150.0)):
    n = len(slip)
    return {"slip": np.array(slip), "slip_angle": np.zeros(n), "load": np.array(load), "gravity": np.full(n, 9.81)}


def test_density_wave_matches_its_closed_form_when_the_shear_is_fully_mobilised():
    """With a vanishing shear modulus, tau = c + sigma tan(phi) over the whole contact, so the extra pressure
    A = l_c d gamma k'_a (seed 002 eqs. 19, 24) adds exactly (r b A times the integrals of eq. 17's terms):
    dT = r^2 b A tan(phi) (theta_f - theta_r), dF_z = r b A (tan(phi)(cos theta_r - cos theta_f) + sin theta_f
    - sin theta_r), dDP = r b A (tan(phi)(sin theta_f - sin theta_r) - (cos theta_r - cos theta_f))."""
    soil = replace(syn.TRUE_SOIL, shear_modulus_x=1e-9, shear_modulus_y=1e-9, c3=0.2)
    cond = _cond()
    k_a = 110.0
    steady = predict(soil, WHEEL, **cond)
    r, b = effective_radius(soil, WHEEL), WHEEL.width
    tf, tr = steady["theta_f"], steady["theta_r"]
    a = r * (tf - tr) * osc.DENSITY_VARIATION * soil.density * 9.81 * k_a
    tan_phi = np.tan(np.radians(soil.friction_angle))
    expected = {
        "torque": r * r * b * a * tan_phi * (tf - tr),
        "vertical_force": r * b * a * (tan_phi * (np.cos(tr) - np.cos(tf)) + np.sin(tf) - np.sin(tr)),
        "drawbar_pull": r * b * a * (tan_phi * (np.sin(tf) - np.sin(tr)) - (np.cos(tr) - np.cos(tf))),
    }
    for q, value in expected.items():
        got = osc.density_wave_amplitudes(soil, WHEEL, cond, k_a, q)
        np.testing.assert_allclose(got, np.abs(value), rtol=1e-6, err_msg=q)
    # linear in the amplitude factor (the integrals are linear in sigma)
    np.testing.assert_allclose(osc.density_wave_amplitudes(soil, WHEEL, cond, 2 * k_a),
                               2 * osc.density_wave_amplitudes(soil, WHEEL, cond, k_a), rtol=1e-12)


def test_spoke_radius_follows_seed000_eq19():
    """R = R_max W, W = 1 - (R_max - R_min)/(2 R_max)(1 + tanh(cos(nu theta))), with R_max = R_bar + dR/2:
    the mean over a period is R_bar, the extremes R_bar -+ (dR/2) tanh(1), and the rim is a floor."""
    mean, swing = 1.6, 0.8
    phase = np.linspace(0.0, 2 * np.pi, 4001)[:-1]
    s = osc.spoke_radius_scales(mean, swing, phase)
    r_max = mean + swing / 2
    np.testing.assert_allclose(s, r_max * (1 - (r_max - (r_max - swing)) / (2 * r_max) * (1 + np.tanh(np.cos(phase)))),
                               rtol=1e-14)
    assert s.mean() == pytest.approx(mean, rel=1e-12)
    assert s.min() == pytest.approx(mean - swing / 2 * np.tanh(1.0), rel=1e-12)
    assert s.max() == pytest.approx(mean + swing / 2 * np.tanh(1.0), rel=1e-12)
    assert osc.spoke_radius_scales(1.1, 1.0, phase).min() == 1.0


def test_small_spoke_swing_gives_the_linearised_first_harmonic():
    """For a small swing, R/r = R_bar - (dR/2) tanh(cos(phase)), so the first harmonic of a response X is
    |dX/ds| (dR/2) h1 with h1 = (1/pi) int tanh(cos p) cos p dp (checked against a central difference)."""
    soil = replace(syn.TRUE_SOIL, radius_scale=1.5)
    cond = _cond()
    swing = 2e-3
    h1 = quad(lambda p: np.tanh(np.cos(p)) * np.cos(p), 0.0, 2 * np.pi)[0] / np.pi
    ds = 1e-4
    up = predict(replace(soil, radius_scale=1.5 + ds), WHEEL, **cond)["drawbar_pull"]
    down = predict(replace(soil, radius_scale=1.5 - ds), WHEEL, **cond)["drawbar_pull"]
    expected = np.abs((up - down) / (2 * ds)) * swing / 2 * h1
    got = osc.spoke_radius_amplitudes(soil, WHEEL, cond, swing, samples=24)
    np.testing.assert_allclose(got, expected, rtol=2e-3)


def _findings(hidden, seed):
    rng = np.random.default_rng(seed)
    params = {k: float(rng.uniform(*b)) for k, b in syn.HIDDEN_OSCILLATIONS.get(hidden, {}).items()}
    records = syn.synthetic_oscillation_series(hidden, params, rng)
    soil = replace(syn.TRUE_SOIL, radius_scale=1.5) if hidden == "spoke_radius" else syn.TRUE_SOIL
    return params, records, soil, osc.oscillation_findings(records, soil, WHEEL, spokes=syn.SYNTHETIC_SPOKES)


@pytest.mark.parametrize("hidden,seed", [("density_wave", 21), ("density_wave", 22), ("spoke_radius", 23),
                                         ("spoke_radius", 24), (None, 25), (None, 26)])
def test_hidden_periodic_mechanism_is_named_and_measured(hidden, seed):
    """The pipeline is given drawbar-pull series (red noise, lag-1 correlation 0.9) and the steady model, not the
    mechanism. It must name the frequency law and the amplitude mechanism, recover the parameter within 10 %
    and show a held-out gain (one load held out at a time) of more than two standard errors; with nothing
    hidden it must find nothing."""
    params, records, soil, out = _findings(hidden, seed)
    law = {"density_wave": "slip_density_wave", "spoke_radius": "spoke_stiffness", None: None}[hidden]
    assert out["frequency"]["found"] == law
    assert out["found"] == hidden
    if hidden is None:
        assert out["amplitude"] is None
        return
    model = out["amplitude"]["models"][hidden]
    truth = params["k_a"] if hidden == "density_wave" else params["radius_swing"]
    assert model["value"] == pytest.approx(truth, rel=0.10)
    assert model["gain"] > 2 * model["gain_se"] > 0
    # the amplitudes alone (no frequency law given) name the same mechanism
    runs = [osc.AmplitudeRun(r.slip, r.slip_angle, r.load, r.gravity, c.amplitude, r.group)
            for r, c in zip(records, out["components"]) if c.significant]
    assert osc.explain_amplitudes(runs, soil, WHEEL, spokes=syn.SYNTHETIC_SPOKES)["found"] == hidden


def test_an_oscillation_of_constant_amplitude_names_no_mechanism():
    """A sinusoid at a slip-law frequency but of the same amplitude in every run: the frequency law is named,
    but no amplitude mechanism may be (the density wave's amplitude must grow with the contact length)."""
    rng = np.random.default_rng(31)
    records = syn.synthetic_oscillation_series(None, {}, rng)
    for r in records:
        r.y = r.y + 2.0 * np.sin((35.0 - 35.0 * r.slip) * r.t + rng.uniform(0.0, 2 * np.pi))
    out = osc.oscillation_findings(records, syn.TRUE_SOIL, WHEEL, spokes=syn.SYNTHETIC_SPOKES)
    assert out["frequency"]["found"] == "slip_density_wave"
    assert out["amplitude"] is not None and out["found"] is None
    assert out["amplitude"]["models"]["constant"]["bic"] < out["amplitude"]["models"]["density_wave"]["bic"]


def test_amplitude_input_is_checked():
    runs = [osc.AmplitudeRun(0.2, 0.0, 50.0, 9.81, 1.0)] * 3
    with pytest.raises(WheelsoilInputError, match="at least 4"):
        osc.explain_amplitudes(runs, syn.TRUE_SOIL, RigidWheel(0.15, 0.12))
    with pytest.raises(WheelsoilInputError, match="unknown amplitude model"):
        osc._fit("magic", syn.TRUE_SOIL, WHEEL, _cond(), np.ones(3), "drawbar_pull")


def test_cli_synthetic_periodic_report(tmp_path):
    from wheelsoil.cases.cli import EXIT_OK, main

    out = tmp_path / "rep"
    assert main(["validate", "synthetic-periodic", "--hidden", "density_wave", "--seed", "2", "--report", str(out)]) == EXIT_OK
    text = (out / "report.md").read_text()
    assert "Found: **slip_density_wave**" in text and "Found: **density_wave**" in text
    assert (out / "amplitudes.png").stat().st_size > 1000 and (out / "findings.json").is_file()
