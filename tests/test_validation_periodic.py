"""Periodic components: detection against white and red noise, recovery of a sinusoid, and hidden frequency
laws (grouser passing, spoke stiffness, seed 002's slip-dependent density wave, or nothing) across runs."""

import numpy as np
import pytest

from wheelsoil.cases import build
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.validation.periodic import SIGNIFICANCE, Run, dominant_component, explain_frequencies

T = np.arange(0.0, 4.0, 0.005)  # a 4 s steady window sampled like the testbed (5 ms)


def test_white_noise_is_rarely_called_periodic():
    """Fisher's g test at p < 1e-3: over 300 white-noise records about 0.3 false detections are expected;
    more than 3 would mean the test is miscalibrated (Poisson tail below 0.5 %)."""
    rng = np.random.default_rng(0)
    hits = sum(dominant_component(T, rng.standard_normal(T.size)).p_value < SIGNIFICANCE for _ in range(300))
    assert hits <= 3


def _ar1(rng, n, phi):
    """AR(1) red noise x_k = phi x_(k-1) + e_k with unit innovations, started stationary."""
    e = rng.standard_normal(n)
    x = np.empty(n)
    x[0] = e[0] / np.sqrt(1.0 - phi * phi)
    for k in range(1, n):
        x[k] = phi * x[k - 1] + e[k]
    return x


def test_red_noise_fools_the_white_test_but_not_the_red_one():
    """Granular force series are red. On AR(1) noise with phi = 0.9 the white-noise test calls nearly every
    record periodic; the red-noise test keeps its level (p < 1e-3: about 0.3 false detections in 300
    records expected, more than 3 would be miscalibration)."""
    rng = np.random.default_rng(2)
    records = [_ar1(rng, T.size, 0.9) for _ in range(300)]
    white = sum(dominant_component(T, y).p_value < SIGNIFICANCE for y in records)
    red = [dominant_component(T, y, noise="red") for y in records]
    assert white > 250
    assert sum(c.p_value < SIGNIFICANCE for c in red) <= 3
    assert np.median([c.ar1 for c in red]) == pytest.approx(0.9, abs=0.03)


def test_sinusoid_in_red_noise_is_found_by_the_red_test():
    rng = np.random.default_rng(3)
    found = [dominant_component(T, _ar1(rng, T.size, 0.9) + 2.0 * np.sin(2 * np.pi * 7.3 * T + rng.uniform(0, 6)),
                                noise="red") for _ in range(20)]
    assert all(c.significant for c in found)
    assert all(c.frequency == pytest.approx(7.3, rel=0.01) for c in found)


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
            elif law == "natural_mode":
                f = params["a_hz"]
            y = 100.0 * slip + 5.0 * T + rng.normal(0.0, 1.0, T.size)  # drawbar pull with noise of 1 N
            if law is not None:
                y = y + amplitude * np.sin(2 * np.pi * f * T + rng.uniform(0, 2 * np.pi))
            runs.append(Run(omega, slip, dominant_component(T, y)))
    return runs


@pytest.mark.parametrize("seed", range(10))
def test_hidden_frequency_law_is_named(seed):
    rng = np.random.default_rng(seed)
    law = [None, "grouser_passing", "spoke_stiffness", "slip_density_wave", "natural_mode"][seed % 5]
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
    with pytest.raises(WheelsoilInputError, match="noise = 'pink'; choose 'white' or 'red'"):
        dominant_component(T, T, noise="pink")


class _FakeResult:
    """The parts of a result file runs_from_results reads: the case, run info and series."""

    def __init__(self, case, t, y, t_spin_up):
        self.case, self.path = case, f"{case.name}.h5"
        self.wheel = build.wheel_geometry(case)
        self.info = {"t_spin_up": t_spin_up}
        self.series = {"t": t, "torque": y}


def test_runs_from_results_take_the_drive_and_name_grouser_passing_in_red_noise(tmp_path):
    from wheelsoil.cases.schema import load_case
    from wheelsoil.validation.periodic import runs_from_results, wheel_counts

    rng = np.random.default_rng(4)
    results = []
    for omega in (1.0, 2.0, 3.0):
        for slip in (0.2, 0.5):
            case = load_case("smoke-1g-steer", [f"test.angular_velocity={omega}", f"test.slip={slip}"])
            grousers, _ = wheel_counts(build.wheel_geometry(case))
            t = np.arange(0.005, 3.0, 0.005)
            drive = 0.5  # the lowering and settling before it ring at another frequency, which must be cut
            y = 400.0 + 10.0 * _ar1(rng, t.size, 0.9)
            y += np.where(t < drive, 300.0 * np.sin(2 * np.pi * 1.3 * t), 0.0)
            y += np.where(t >= drive, 30.0 * np.sin(2 * np.pi * grousers * omega / (2 * np.pi) * t), 0.0)
            results.append(_FakeResult(case, t, y, drive - case.test.spin_up_time))
    runs = runs_from_results(results, "torque")
    assert all(r.record_seconds == pytest.approx(3.0 - 0.5, abs=0.01) for r in runs)
    assert all(r.component.significant for r in runs)
    found = explain_frequencies(runs, grousers=24, spokes=12)
    assert found["found"] == "grouser_passing", found
    with pytest.raises(WheelsoilInputError, match="has no series 'drawbar_pull'"):
        runs_from_results(results, "drawbar_pull")
    # the report takes the results the caller read (validation does not read result files itself)
    from wheelsoil.validation.periodic import periodic_report

    out = periodic_report(results, "torque", source="six fake runs", report=tmp_path)
    assert out["configurations"]["flexible wheel, 1g, W = 3000 N"]["found"] == "grouser_passing"
    assert "in six fake runs" in (tmp_path / "periodic.md").read_text()
    with pytest.raises(WheelsoilInputError, match="no finished runs"):
        periodic_report([], source="an empty folder")


def test_a_constant_frequency_at_one_wheel_speed_is_not_named():
    """At one wheel speed a natural mode and every counting law predict a constant: nothing may be named,
    and the note says to vary the speed."""
    rng = np.random.default_rng(6)
    runs = []
    for slip in (0.1, 0.3, 0.5, 0.7):
        y = 100.0 * slip + rng.normal(0.0, 1.0, T.size) + 2.0 * np.sin(2 * np.pi * 4.4 * T + rng.uniform(0, 6))
        runs.append(Run(1.0, slip, dominant_component(T, y)))
    found = explain_frequencies(runs, grousers=24, spokes=12)
    assert found["found"] is None
    assert "vary the wheel speed" in found["note"] and "4.4" in found["note"]


def test_a_fitted_law_needs_spare_runs():
    """Three significant runs lie on some line: the two-parameter slip law is not named from them; with
    SPARE_RUNS more runs than parameters, a line the frequencies follow is."""
    from wheelsoil.validation.periodic import SPARE_RUNS, Component, Run, explain_frequencies

    def runs(slips):
        return [Run(1.0, s, Component(frequency=10.0 - 5.0 * s, amplitude=1.0, phase=0.0, p_value=1e-9, explained=0.5))
                for s in slips]

    assert explain_frequencies(runs([0.1, 0.4, 0.7]), grousers=24)["found"] is None
    slips = np.linspace(0.1, 0.7, 2 + SPARE_RUNS)
    assert explain_frequencies(runs(slips), grousers=24)["found"] == "slip_density_wave"


def test_cli_periodic_report_of_a_folder_without_runs_is_an_input_error(tmp_path, capsys):
    from wheelsoil.cases.cli import EXIT_INPUT, main

    (tmp_path / "cases").mkdir()
    assert main(["validate", str(tmp_path), "--periodic", "torque"]) == EXIT_INPUT
    err = capsys.readouterr().err
    assert "holds no finished runs" in err and "Traceback" not in err


def _component(f):
    from wheelsoil.validation.periodic import Component

    return Component(frequency=f, amplitude=1.0, phase=0.0, p_value=1e-9, explained=0.5)


def test_a_slip_law_of_the_wrong_sign_is_not_seed_002s():
    """Seed 002 eq. 25: the density wave's frequency falls with slip. Frequencies that rise with slip along a
    line are not named as that law."""
    runs = [Run(w, s, _component(4.0 + 3.0 * s)) for w in (1.0, 2.0) for s in (0.1, 0.3, 0.5, 0.7)]
    out = explain_frequencies(runs, grousers=24, spokes=12)
    assert out["found"] is None and out["laws"]["slip_density_wave"]["seed_002_sign"] is False
    assert "opposite of seed 002" in out["note"]


@pytest.mark.parametrize("count", [7, 12])
def test_wheel_speed_tied_to_slip_is_reported_as_a_confound(count):
    """Constant carriage speed (omega = v / (r (1 - i))): a count per turn rises with slip like a line would. With
    a count the wheel does not declare (7), nothing is named: the only line that fits has the wrong sign for seed
    002 and no declared count fits. With the declared spoke count (12), spoke stiffness is still named (a
    parameter-free law, and the wrong-sign slip law is no alternative), and the confound is reported."""
    v, r = 0.05, 0.15
    runs = [Run(v / (r * (1 - s)), s, _component(count * v / (r * (1 - s)) / (2 * np.pi)))
            for s in (0.05, 0.15, 0.25, 0.35, 0.45, 0.55)]
    out = explain_frequencies(runs, grousers=24, spokes=12)
    assert out["speed_slip_r2"] > 0.999 and "tied to the slip" in out["confound"]
    assert out["found"] == (None if count == 7 else "spoke_stiffness"), out
    if count == 7:
        assert "at 7 ± 0.00 per wheel turn" in out["unexplained"] and "12 spokes" in out["unexplained"]
    else:
        assert "unexplained" not in out


def test_an_undeclared_count_per_turn_is_reported_unexplained():
    """Nine peaks per turn on a wheel declaring 24 grousers and 12 spokes, at two wheel speeds: no law fits,
    and the report says what the oscillation is (a steady count per turn) instead of naming nothing silently.
    Frequencies that follow no count are described by their range."""
    runs = [Run(w, s, _component(9 * w / (2 * np.pi))) for w in (1.0, 2.0) for s in (0.1, 0.3, 0.5)]
    out = explain_frequencies(runs, grousers=24, spokes=12)
    assert out["found"] is None and "at 9 ± 0.00 per wheel turn" in out["unexplained"], out
    scattered = [Run(w, s, _component(f)) for w, s, f in [(1.0, 0.1, 1.3), (1.0, 0.5, 2.9), (2.0, 0.3, 1.1),
                                                           (2.0, 0.6, 4.2)]]
    out = explain_frequencies(scattered, grousers=24, spokes=12)
    assert out["found"] is None and "1.1-4.2 Hz" in out["unexplained"], out
