"""The steady-state detector on synthetic runs with known answers: windows of whole tread pitches, means and
standard errors against the truth, and refusals (drifting forces, a tread that still winds up, a tread slip
away from the commanded one) that name the quantity and the amount. Several seeds each."""

import math

import numpy as np
import pytest

from wheelsoil.coupling.steady import (
    detect_steady_state,
    pitch_boundaries,
    pitch_noise,
    pitch_noise_dof,
    t_quantile,
    varies,
    window_stats,
)

DT = 0.005  # sample interval [s]
OMEGA = 1.0  # tread spin [rad/s]
R = 0.6  # wheel radius [m]
PITCH = math.radians(15.0)  # grouser pitch
SLIP = 0.3


def synthetic_run(seed, *, t_end=4.0, tau=0.4, drift=0.0, slip_drift=0.0, slip_offset=0.0):
    """A run that settles with time constant tau onto a plateau, with a component at the grouser frequency and
    red noise; optional linear drift of the force and of the tread slip."""
    rng = np.random.default_rng(seed)
    t = np.arange(1, int(t_end / DT) + 1) * DT
    noise = np.zeros(t.size)
    for k in range(1, t.size):  # AR(1), correlation time ~ 25 ms
        noise[k] = 0.8 * noise[k - 1] + rng.normal(0.0, 30.0)
    grouser = 50.0 * np.sin(2 * np.pi * OMEGA * t / PITCH)
    force = 1000.0 * (1.0 - np.exp(-t / tau)) + grouser + noise + drift * t
    spin = np.full(t.size, OMEGA)
    slip = SLIP + slip_offset + slip_drift * (t - t_end / 2)
    speed = (1.0 - slip) * R * spin  # travel speed that gives this tread slip
    angle = np.cumsum(spin * DT)
    return t, {"drawbar_pull": force}, angle, speed


def detect(t, series, angle, speed, **kw):
    args = dict(tread_angle=angle, travel_speed=speed, radius=R, pitch=PITCH, start=0.0, min_pitches=4,
                tolerance=0.1, floors={"drawbar_pull": 150.0}, slip_target=SLIP, slip_tolerance=0.03,
                sample_interval=DT)
    args.update(kw)
    return detect_steady_state(t, series, **args)


def test_pitch_boundaries_span_whole_pitches():
    t = np.arange(1, 801) * DT
    angle = OMEGA * t
    bounds = pitch_boundaries(angle, len(t), PITCH, 1)
    turned = [angle[b0 - 1] - angle[b1 - 1] for b0, b1 in zip(bounds[:-1], bounds[1:])]
    assert np.allclose(turned, PITCH, atol=OMEGA * DT)  # each within one sample of a pitch


@pytest.mark.parametrize("seed", [1, 2, 3, 4, 5])
def test_a_settling_run_is_steady_after_its_transient_and_the_mean_is_within_its_error(seed):
    t, series, angle, speed = synthetic_run(seed)
    state = detect(t, series, angle, speed)
    assert state.steady, state.reasons
    assert state.window[0] >= 1.0  # the transient (tau = 0.4 s) is out of the window
    # whole pitches: the window spans a whole number of pitches of the tread angle
    turned = angle[state.k1 - 1] - angle[state.k0 - 1]
    assert turned / PITCH == pytest.approx(state.pitches, abs=0.05)
    st = state.stats["drawbar_pull"]
    truth = 1000.0 * np.mean(1.0 - np.exp(-t[state.k0:state.k1] / 0.4))
    assert abs(st["mean"] - truth) < 4.0 * st["sem"] + 1.0, (st, truth)
    assert state.tread_slip == pytest.approx(SLIP, abs=1e-9)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_drifting_force_is_not_steady_and_the_reason_names_it(seed):
    t, series, angle, speed = synthetic_run(seed, drift=400.0)  # +400 N/s: +30 % over a second, as the issue saw
    state = detect(t, series, angle, speed)
    assert not state.steady
    assert any(r.startswith("drawbar_pull drifts by +") for r in state.reasons), state.reasons


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_tread_still_winding_up_is_not_steady(seed):
    t, series, angle, speed = synthetic_run(seed, slip_drift=0.05)  # tread slip rising 0.05 per second
    state = detect(t, series, angle, speed)
    assert not state.steady
    assert any("still winding up" in r for r in state.reasons), state.reasons


@pytest.mark.parametrize("offset", [-0.08, 0.05])
def test_a_tread_slip_away_from_the_commanded_slip_is_not_steady(offset):
    t, series, angle, speed = synthetic_run(7, slip_offset=offset)
    state = detect(t, series, angle, speed)
    assert not state.steady
    assert state.tread_slip == pytest.approx(SLIP + offset, abs=1e-9)
    assert any("differs from the commanded" in r for r in state.reasons), state.reasons


def test_too_short_a_drive_says_so():
    t, series, angle, speed = synthetic_run(1, t_end=0.2)
    state = detect(t, series, angle, speed)
    assert not state.steady and "has not yet turned" in state.reasons[0]


def test_windows_are_whole_periods_when_spokes_and_grousers_differ():
    t, series, angle, speed = synthetic_run(3)
    state = detect(t, series, angle, speed, period_pitches=2)
    assert state.steady and state.pitches % 2 == 0


@pytest.mark.parametrize("m", [4, 8])
def test_the_drift_standard_error_matches_the_scatter_of_drifts_over_many_seeds(m):
    """Pitch means on a line with white noise sigma: the drift's standard error from one window agrees (on
    average over 400 draws) with the standard deviation of the drift across draws, sigma (m - 1) /
    sqrt(sum (x - xbar)^2), within 10 %; the drift itself is unbiased within three of its standard errors."""
    from wheelsoil.coupling.steady import window_stats

    sigma, slope = 5.0, 2.0
    x = np.arange(m, dtype=float)
    bounds = list(range(m, -1, -1))  # one sample per pitch
    rng = np.random.default_rng(1000 + m)
    drifts, sems = [], []
    for _ in range(400):
        st = window_stats(100.0 + slope * x + rng.normal(0.0, sigma, m), bounds)
        drifts.append(st["drift"])
        sems.append(st["drift_sem"])
    exact = sigma * (m - 1) / math.sqrt(((x - x.mean()) ** 2).sum())
    assert np.std(drifts) == pytest.approx(exact, rel=0.1)
    assert np.sqrt(np.mean(np.square(sems))) == pytest.approx(exact, rel=0.1)
    assert abs(np.mean(drifts) - slope * (m - 1)) < 3 * exact / math.sqrt(400)


@pytest.mark.parametrize("seed", [11, 12, 13, 14])
def test_a_drift_within_its_noise_beyond_the_tolerance_is_refused_and_says_so(seed):
    """A flat but very noisy force (pitch means scattered by 40 % of the mean) over a short window: the
    detector cannot tell it from a drifting one, so the window is not steady whenever its drift exceeds the
    tolerance, and the reason says when the drift is within its own noise (a longer window would tell)
    instead of implying a trend; a drift within the tolerance gives no drift reason."""
    t, series, angle, speed = synthetic_run(seed, t_end=1.6, tau=0.01)
    rng = np.random.default_rng(seed)
    pitch_of = np.floor(angle / PITCH).astype(int)
    series["drawbar_pull"] = series["drawbar_pull"] + rng.normal(0.0, 400.0, pitch_of.max() + 1)[pitch_of]
    state = detect(t, series, angle, speed)
    st = state.stats["drawbar_pull"]
    assert math.isfinite(st["drift_sem"]) and st["drift_sem"] > 0
    reasons = [r for r in state.reasons if r.startswith("drawbar_pull drifts")]
    if abs(st["drift"]) > 0.1 * max(abs(st["mean"]), 150.0):
        assert not state.steady and len(reasons) == 1
        assert ("within its own noise" in reasons[0]) == (abs(st["drift"]) < 2 * st["drift_sem"])
    else:
        assert reasons == []


@pytest.mark.parametrize("seed", [21, 22, 23])
def test_drift_confidence_holds_the_drift_plus_its_standard_errors_to_the_tolerance(seed):
    """With drift_confidence k the drift estimate plus k of its standard errors (and likewise the change between
    the halves) must lie within the tolerance: the noisy flat force of the test above is refused exactly when
    |drift| + k drift_sem or |step| + k step_sem exceeds 10 % of max(|mean|, floor), with the margin named; k = 0
    is the default detector, verdict for verdict."""
    t, series, angle, speed = synthetic_run(seed, t_end=3.0, tau=0.01)
    rng = np.random.default_rng(seed)
    pitch_of = np.floor(angle / PITCH).astype(int)
    series["drawbar_pull"] = series["drawbar_pull"] + rng.normal(0.0, 60.0, pitch_of.max() + 1)[pitch_of]
    default = detect(t, series, angle, speed)
    assert detect(t, series, angle, speed, drift_confidence=0.0).steady == default.steady
    for k in (0.5, 1.0, 3.0):
        state = detect(t, series, angle, speed, drift_confidence=k)
        st = state.stats["drawbar_pull"]
        allowed = 0.1 * max(abs(st["mean"]), 150.0)
        refused = (abs(st["drift"]) + k * st["drift_sem"] > allowed or abs(st["step"]) + k * st["step_sem"] > allowed)
        named = [r for r in state.reasons if r.startswith("drawbar_pull") and f"plus {k:g} standard errors" in r]
        assert bool(named) == refused
        if refused:
            assert not state.steady
    # a large enough margin refuses every window of this noise
    assert not detect(t, series, angle, speed, drift_confidence=10.0).steady


def test_pitch_noise_recovers_the_scatter_of_pitch_means_and_sees_a_trend_only_through_its_step():
    """Mean square successive difference (von Neumann 1941): over 400 draws of 12 independent pitch means with
    sigma = 5, the mean of sigma_hat^2 is sigma^2 within 10 %; on a line rising by one sigma per pitch it is
    sigma^2 + step^2 / 2, where the window's own standard deviation would be inflated by the whole rise."""
    from wheelsoil.coupling.steady import pitch_noise

    rng = np.random.default_rng(77)
    sigma, m = 5.0, 12
    flat = [pitch_noise(rng.normal(0.0, sigma, m)) ** 2 for _ in range(400)]
    assert np.mean(flat) == pytest.approx(sigma**2, rel=0.1)
    line = sigma * np.arange(m)
    rising = [pitch_noise(line + rng.normal(0.0, sigma, m)) ** 2 for _ in range(400)]
    assert np.mean(rising) == pytest.approx(sigma**2 + sigma**2 / 2, rel=0.1)
    assert pitch_noise(np.array([1.0])) == math.inf


def zero_quantity(seed, t, angle, sigma=40.0, rate=0.0):
    """A force that is zero on average: independent pitch means scattered by sigma [N] (no floor or tolerance of
    +-15 N can hold it), optionally trending at ``rate`` [N/s]. The pitches are counted back from the last sample,
    as the detector counts them, so that its pitch means are independent (pitch means that straddle two
    pitches are correlated, and the successive differences then see less than the whole scatter)."""
    rng = np.random.default_rng(seed)
    pitch_of = np.floor((angle[-1] - angle) / PITCH).astype(int)
    return rng.normal(0.0, sigma, pitch_of.max() + 1)[pitch_of] + rate * t


def test_a_quantity_zero_within_its_noise_is_steady_when_it_does_not_trend():
    """The lateral force of a straight run: zero on average, pitch means scattered by 40 N, allowance +-15 N
    (10 % of a 150 N floor). Over 100 draws the detector's default calls at least 75 % steady, flagged zero
    within noise (expected about 85 %: each of |mean|, drift and halves exceeds 2 standard errors in about 5 %
    of draws), nearly all of them flagged; with the tolerance alone (zero_within=0) at most 40 % (the drift over
    ~10 pitches has a standard error of about 40 N against the 15 N allowed)."""
    steady_default, steady_tolerance, flagged = 0, 0, 0
    for seed in range(100):
        t, series, angle, speed = synthetic_run(500 + seed)
        series["lateral_force"] = zero_quantity(500 + seed, t, angle)
        floors = {"drawbar_pull": 150.0, "lateral_force": 150.0}
        state = detect(t, series, angle, speed, floors=floors)
        steady_default += state.steady
        flagged += state.steady and state.stats["lateral_force"]["zero_within_noise"]
        steady_tolerance += detect(t, series, angle, speed, floors=floors, zero_within=0.0).steady
    assert steady_default >= 75 and flagged >= 70  # a few pass the tolerance itself, by chance
    assert steady_tolerance <= 40


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_zero_quantity_that_trends_is_not_steady_and_the_reason_names_it(seed):
    """The same zero force trending at 150 N/s (about ten of its drift's standard errors over the window)."""
    t, series, angle, speed = synthetic_run(seed)
    series["lateral_force"] = zero_quantity(seed, t, angle, rate=150.0) - 150.0 * t[-1] / 2
    state = detect(t, series, angle, speed, floors={"drawbar_pull": 150.0, "lateral_force": 150.0})
    assert not state.steady
    assert any(r.startswith("lateral_force") for r in state.reasons), state.reasons


def test_a_run_is_steady_only_at_the_required_number_of_steady_checks_in_a_row():
    """confirm_steady: with two required, a first steady verdict is reported not steady (and says why), an
    unsteady verdict resets the count, and the second steady verdict in a row is reported steady unchanged."""
    from dataclasses import replace

    from wheelsoil.coupling.steady import confirm_steady

    t, series, angle, speed = synthetic_run(1)
    good = detect(t, series, angle, speed)
    assert good.steady
    bad = replace(good, steady=False, reasons=["drawbar_pull drifts"])
    verdicts, count = [], 0
    for state in (good, bad, good, good, good):
        out, count = confirm_steady(state, count, 2)
        verdicts.append((out.steady, count))
    assert verdicts == [(False, 1), (False, 0), (False, 1), (True, 2), (True, 3)]
    first, _ = confirm_steady(good, 0, 2)
    assert "1 check(s) in a row" in first.reasons[0] and first.stats is good.stats
    assert confirm_steady(good, 0, 1)[0] is good  # one check: the verdict as it is


def test_mser_searches_only_the_first_half_so_a_stationary_run_keeps_a_long_window():
    """Six stationary quantities over 24 pitches: searched to the end, the latest MSER truncation cuts most such
    runs to a window of a few pitches (the last means happen to lie close together); searched over the first
    half (MSER's own rule), every window keeps at least half the pitches. 40 draws, each asserted."""
    short_before = 0
    for seed in range(40):
        t, series, angle, speed = synthetic_run(900 + seed, t_end=6.5, tau=0.01)
        for q in range(5):
            series[f"q{q}"] = 100.0 + zero_quantity(900 + 10 * seed + q, t, angle, sigma=5.0)
        floors = {name: 150.0 for name in series}
        kw = dict(floors=floors, slip_target=None, zero_within=0.0, tolerance=1.0)
        n_pitches = len(pitch_boundaries(angle, len(t), PITCH, 1)) - 1
        state = detect(t, series, angle, speed, **kw)
        assert state.pitches >= n_pitches // 2, (seed, state.pitches, n_pitches)
        short_before += detect(t, series, angle, speed, truncation_search=1.0, **kw).pitches < n_pitches // 2
    assert short_before >= 20  # the rule the first half replaces: about 84 % of such runs cut short


def test_a_transient_longer_than_half_the_run_is_not_called_steady():
    """A force still settling (time constant 2 s over a 4 s run): MSER may not cut it out of the window beyond
    the first half, so the window holds the rise and its drift fails the tolerance."""
    for seed in (1, 2, 3):
        t, series, angle, speed = synthetic_run(seed, tau=2.0)
        state = detect(t, series, angle, speed)
        assert not state.steady
        assert any(r.startswith("drawbar_pull") for r in state.reasons), state.reasons


#: A pattern repeating every 4 pitches, like the mini run's drawbar pull (pitch means about +3, +6, -3, -5 N on
#: 11 N: 8 grousers and 6 spokes repeat together every 180 deg), scaled by 10.
PATTERN = np.array([30.0, 60.0, -35.0, -55.0])


def periodic_pattern(angle, levels):
    """Pitch means following ``levels`` around the period, pitches counted back from the last sample."""
    pitch_of = np.floor((angle[-1] - angle) / PITCH).astype(int)
    return np.asarray(levels)[pitch_of % len(levels)]


def test_periodic_trend_recovers_a_slope_under_a_pattern_that_repeats_every_period():
    """Noise-free pitch means: a line plus a pattern repeating every 4 pitches over 12 pitches. The analysis of
    covariance slope is the line's exactly (the plain least-squares line is not: the pattern's phases correlate
    with time in a window of whole periods), and with period 1 it equals the least-squares slope."""
    from wheelsoil.coupling.steady import periodic_trend

    x = np.arange(12, dtype=float)
    pattern = np.tile([5.0, 8.0, -3.0, -6.0], 3)
    slope, factor = periodic_trend(0.7 * x + pattern, 4)
    assert slope == pytest.approx(0.7, abs=1e-12)
    assert np.polyfit(x, 0.7 * x + pattern, 1)[0] != pytest.approx(0.7, abs=0.05)
    # S = sum over 4 phases of sum (x - xbar_p)^2, each phase 3 points 4 apart: 4 * 16 * 2 = 128
    assert factor == pytest.approx(1.0 / math.sqrt(128.0), rel=1e-12)
    y = np.random.default_rng(3).normal(size=12)
    assert periodic_trend(y, 1)[0] == pytest.approx(np.polyfit(x, y, 1)[0], rel=1e-10)


@pytest.mark.parametrize("seed", [21, 22, 23, 24])
def test_a_pattern_every_four_pitches_is_not_taken_for_noise_or_drift(seed):
    """A stationary force whose pitch means ride on a pattern repeating every 4 pitches (PATTERN, against white
    pitch-mean noise of 20 N): told the period, the detector's noise is the noise (within 40 %, one draw) and
    the run is steady over whole periods; told nothing, the noise takes in the pattern (over 1.5 x)."""
    t, series, angle, speed = synthetic_run(seed, t_end=6.0, tau=0.01)
    force = 1000.0 + zero_quantity(seed, t, angle, sigma=20.0) + periodic_pattern(angle, PATTERN)
    series = {"drawbar_pull": force}
    state = detect(t, series, angle, speed, period_pitches=4)
    assert state.steady, state.reasons
    assert state.pitches % 4 == 0 and state.pitches >= 8
    assert state.stats["drawbar_pull"]["noise"] == pytest.approx(20.0, rel=0.4)
    blind = detect(t, series, angle, speed)
    assert blind.stats["drawbar_pull"]["noise"] > 1.5 * 20.0


@pytest.mark.parametrize("n, lag", [(6, 1), (12, 2), (16, 4)])
def test_pitch_noise_dof_matches_the_variance_of_the_noise_estimate(n, lag):
    """nu = 2 sigma^4 / Var(sigma_hat^2) for pitch_noise of n independent normal means (von Neumann et al. 1941,
    generalised to L independent chains): the Monte Carlo variance over 20,000 series agrees within 8 %
    (its own sampling error is under 2 %), for three seeds each."""
    for seed in range(3):
        rng = np.random.default_rng(seed)
        q = np.array([pitch_noise(rng.normal(size=n), lag) ** 2 for _ in range(20_000)])
        assert q.mean() == pytest.approx(1.0, rel=0.03)  # unbiased
        assert 2.0 / q.var() == pytest.approx(pitch_noise_dof(n, lag), rel=0.08)


@pytest.mark.parametrize("n, m, lag", [(6, 4, 1), (12, 6, 1), (16, 8, 2)])
def test_the_95_percent_interval_covers_the_true_mean_where_two_standard_errors_do_not(n, m, lag):
    """Independent normal pitch means, the noise from all n of them, the window the last m: the reported ci95
    (Student's t at pitch_noise_dof) covers the true mean in 95 % of 4,000 series (93-98 % allowed: binomial
    error 0.35 %, and the chi-square match is slightly conservative for few pitches), where +-2 standard errors
    cover it in under 94 % (88 % at n = 6)."""
    for seed in range(3):
        rng = np.random.default_rng(100 + seed)
        covered_t = covered_2 = 0
        bounds = list(range(n, n - m - 1, -1))  # one sample per pitch, latest boundary first
        for _ in range(4000):
            b = rng.normal(size=n)
            st = window_stats(b, bounds, noise=pitch_noise(b, lag), period=lag, noise_dof=pitch_noise_dof(n, lag))
            covered_t += abs(st["mean"]) <= st["ci95"]
            covered_2 += abs(st["mean"]) <= 2.0 * st["sem"]
        assert 0.93 <= covered_t / 4000 <= 0.98
        assert covered_2 / 4000 < 0.94


def test_the_interval_widens_to_infinity_without_a_noise_estimate():
    assert pitch_noise_dof(1, 1) == 0.0 and t_quantile(0.0) == math.inf
    assert t_quantile(1e9) == pytest.approx(1.95996, abs=1e-4)


def test_a_quantity_constant_to_round_off_does_not_choose_the_window():
    """A rigid wheel's tread slip is the commanded one to the last digits, and MSER on such pitch means picks its
    truncation from round-off: a run's verdict then changed between the live testbed (full float64 rows) and
    its series.csv (10 digits). With the tread slip's travel speed perturbed at the 1e-15 level in three ways,
    the window is the same each time, and it is the window chosen by the force alone."""
    for seed in (21, 22, 23):
        t, series, angle, speed = synthetic_run(seed, tau=0.05)
        alone = detect(t, series, angle, speed, slip_target=None)
        windows = set()
        for k in range(3):
            wobble = 1.0 + 1e-15 * np.random.default_rng(100 * seed + k).standard_normal(t.size)
            state = detect(t, series, angle, speed * wobble)
            windows.add((state.k0, state.k1))
        assert windows == {(alone.k0, alone.k1)}
    assert not varies(np.full(8, 0.3) + 1e-16 * np.arange(8)) and varies(np.array([0.3, 0.3001]))
    assert not varies(np.zeros(5))


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("slip", [-0.5, -0.2])
def test_a_braking_run_reports_the_rigs_braking_slip(seed, slip):
    """Braking (the measured rigs' convention, i = r omega_t / v - 1): the carriage at v = r omega_0, the
    tread turning at (1 + i) omega_0; the window is whole pitches of the tread and its slip is the commanded."""
    t, series, _, _ = synthetic_run(seed)
    spin = np.full(t.size, (1.0 + slip) * OMEGA)
    speed = np.full(t.size, R * OMEGA)
    angle = np.cumsum(spin * DT)
    state = detect(t, series, angle, speed, slip_target=slip)
    assert state.steady, state.reasons
    assert state.tread_slip == pytest.approx(slip, abs=1e-9)
    assert (angle[state.k1 - 1] - angle[state.k0 - 1]) / PITCH == pytest.approx(state.pitches, abs=0.05)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_dragged_wheel_is_batched_by_its_travel_and_reports_slip_minus_one(seed):
    """A wheel dragged without turning (i = -1) has no tread pitches: the batches are the angles it would roll
    through along its travel (batch_angle = travel / r), and its slip is -1 exactly."""
    t, series, _, _ = synthetic_run(seed)
    speed = np.full(t.size, R * OMEGA)
    rolled = np.cumsum(speed * DT) / R
    still = np.zeros(t.size)
    state = detect(t, series, still, speed, batch_angle=rolled, slip_target=-1.0)
    assert state.steady, state.reasons
    assert state.tread_slip == -1.0
    assert (rolled[state.k1 - 1] - rolled[state.k0 - 1]) / PITCH == pytest.approx(state.pitches, abs=0.05)
    # the tread's own angle alone gives no pitch to batch by, and says so
    refused = detect(t, series, still, speed, slip_target=-1.0)
    assert not refused.steady and "has not yet turned" in refused.reasons[0]
