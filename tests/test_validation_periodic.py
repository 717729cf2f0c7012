"""Periodic components: detection against white noise, recovery of a sinusoid, and hidden frequency laws
(grouser passing, spoke stiffness, seed 002's slip-dependent density wave, or nothing) across runs."""

import numpy as np
import pytest

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.validation.periodic import SIGNIFICANCE, Run, dominant_component, explain_frequencies

T = np.arange(0.0, 4.0, 0.005)  # a 4 s steady window sampled like the testbed (5 ms)


def test_white_noise_is_rarely_called_periodic():
    """Fisher's g test at p < 1e-3: over 300 white-noise records about 0.3 false detections are expected;
    more than 3 would mean the test is miscalibrated (Poisson tail below 0.5 %)."""
    rng = np.random.default_rng(0)
    hits = sum(dominant_component(T, rng.standard_normal(T.size)).p_value < SIGNIFICANCE for _ in range(300))
    assert hits <= 3


def test_sinusoid_on_a_trend_is_recovered():
    rng = np.random.default_rng(1)
    y = 50.0 + 20.0 * T + 4.0 * np.sin(2 * np.pi * 5.3 * T + 1.0) + 2.0 * rng.standard_normal(T.size)
    c = dominant_component(T, y)
    assert c.significant
    assert c.frequency == pytest.approx(5.3, rel=0.005)
    assert c.amplitude == pytest.approx(4.0, rel=0.1)


def _runs(rng, law, params, *, grousers, spokes, amplitude):
    runs = []
    for omega in (1.0, 2.0):
        for slip in (0.1, 0.3, 0.5, 0.7):
            if law == "grouser_passing":
                f = grousers * omega / (2 * np.pi)
            elif law == "spoke_stiffness":
                f = spokes * omega / (2 * np.pi)
            elif law == "slip_density_wave":
                f = params["a_hz"] + params["b_hz"] * slip
            y = 100.0 * slip + 5.0 * T + rng.normal(0.0, 1.0, T.size)  # drawbar pull with noise of 1 N
            if law is not None:
                y = y + amplitude * np.sin(2 * np.pi * f * T + rng.uniform(0, 2 * np.pi))
            runs.append(Run(omega, slip, dominant_component(T, y)))
    return runs


@pytest.mark.parametrize("seed", range(8))
def test_hidden_frequency_law_is_named(seed):
    rng = np.random.default_rng(seed)
    law = [None, "grouser_passing", "spoke_stiffness", "slip_density_wave"][seed % 4]
    grousers, spokes = int(rng.integers(10, 21)), int(rng.integers(4, 9))
    params = {"a_hz": float(rng.uniform(4.0, 7.0)), "b_hz": float(rng.uniform(-5.0, -2.0))}
    amplitude = float(rng.uniform(0.5, 2.0))  # 0.5-2 N against 1 N of noise
    runs = _runs(rng, law, params, grousers=grousers, spokes=spokes, amplitude=amplitude)
    found = explain_frequencies(runs, grousers=grousers, spokes=spokes)
    assert found["found"] == law, (law, found)
    if law is not None:
        # the amplitude's standard error in white noise of 1 N is sqrt(2 / N) N; allow four of them
        tol = 4.0 * np.sqrt(2.0 / T.size)
        assert all(r.component.amplitude == pytest.approx(amplitude, abs=tol) for r in runs)
    if law == "slip_density_wave":
        fit = found["laws"][law]["parameters"]
        assert fit["a_hz"] == pytest.approx(params["a_hz"], abs=0.05)
        assert fit["b_hz"] == pytest.approx(params["b_hz"], abs=0.1)


def test_bad_series_are_refused():
    with pytest.raises(WheelsoilInputError, match="at least 16 samples"):
        dominant_component(T[:5], T[:5])
    with pytest.raises(WheelsoilInputError, match="uniformly sampled"):
        dominant_component(T ** 2, T)
