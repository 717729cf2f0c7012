"""Steady-state detection over whole periods of the tread's rotation, and the averages it reports.

A driven wheel's forces ride on a periodic component -- a grouser (or spoke) entering the soil every
pitch of the tread's rotation -- and on granular noise. A window that holds a fraction of a period biases
the mean by where in the period it starts and ends; a window of whole periods does not. So every
window here spans a whole number of *pitches of the tread's own rotation* (the tread angle phi_t, not
the hub's, which leads it by the wind-up), and its statistics are taken over per-pitch means
(batch means: Flyvbjerg & Petersen 1989, J. Chem. Phys. 91, 461; a pitch is the natural batch of a
rolling wheel):

* mean of the samples in the window (each sample is already an average over its interval);
* ``noise``: the scatter of the pitch means about their local level, from their mean square successive
  difference over every pitch since the earliest window start (von Neumann 1941, Ann. Math. Stat. 12, 367:
  sigma^2 = sum_k (b_{k+1} - b_k)^2 / (2 (M - 1))). A slow transient or trend enters only through its
  squared change per pitch, so the whole drive informs the noise, not just the two or three degrees of
  freedom of a short window's own pitch means;
* ``sem``: the standard error of the window's mean, noise / sqrt(m) over its m pitches;
* ``ci95``: the half-width of the window mean's 95 % confidence interval, t(0.975, dof) sem, with Student's t at
  the noise estimate's degrees of freedom ``dof`` (:func:`pitch_noise_dof`: a run that stops at its first
  steady window has estimated its noise from five or six pitch means, and +-2 sem then covers the true mean in
  about 84 % of stationary synthetic runs, not 95 %; ``docs/steady-detector.md``);
* ``drift``: the change over the window of the least-squares line through the pitch means, and
  ``drift_sem`` its standard error, noise sqrt(12 (m - 1) / (m (m + 1))) (the slope's variance
  12 sigma^2 / (m (m^2 - 1)), times (m - 1)^2).

When the wheel's whole period is P > 1 pitches (8 grousers and 6 spokes repeat together every 180 deg: 4
grouser pitches), the pitch means carry a pattern that repeats every P pitches -- at mini scale it moves the
drawbar pull's pitch means by +-5 N about 11 N, more than their noise. Windows then span whole periods (at
least two), the noise comes from differences P pitches apart (the pattern cancels), the drift from the common
slope of one line per phase of the period (:func:`periodic_trend`; with P = 1 the least-squares line), the
halves are whole periods each, and MSER looks at the pitch means less their phase means.

Where the window starts -- how much of the run is start-up transient -- is chosen by the marginal standard
error rule on the pitch means (MSER: White 1997, Simulation 69, 323; White, Cobb & Spratt 2000; batch means
as in MSER-5): for each quantity the truncation d that minimises sum_{k>=d} (b_k - mean_d)^2 / (M - d)^2 over
the M pitch means b_k, and the window starts after the latest of them (every quantity past its transient).
The search covers the first half of the pitches only (MSER's own rule: Hoad, Robinson & Davies 2011, J. Oper.
Res. Soc. 62, 1117 -- a minimum in the second half says the run is too short, not where its transient ends).
Searched to the end, the criterion finds a late minimum in a stationary series whenever its last few means
happen to lie close together: for 20 independent normal pitch means, one quantity's truncation falls in the
second half in 26 % of series, and the latest of six quantities' in 84 % (to the shortest window of 3 pitches
in 53 %; 2,000 series, ``tests/test_steady.py`` checks the restricted search). A stationary run at mini scale
drove 8.6 s and was judged over its last 3 of 22 pitches, where no drift can be told from its noise. A
transient longer than half the run stays in the window, fails its drift test, and the run drives on until
it is the shorter half.

That window is **steady** when every quantity passes one of two tests, and the tread is where the rig wants it:

* *within the tolerance*: |drift| <= tolerance x max(|mean|, floor), and the means of the window's first and
  second halves differ by no more than that either. A drift beyond the tolerance fails even when it is within
  its own noise (the reason then says so): for a quantity with a value to hold, the detector does not call a
  window steady that it cannot tell from a drifting one;
* *zero within its noise*: |mean| < 2 sem, |drift| <= 2 drift_sem and the halves' difference within twice its
  standard error. A quantity whose value cannot be told from zero -- the lateral force of a straight run, whose
  expected value is zero by symmetry -- has no value for a relative tolerance to hold, and the floor (an
  absolute allowance) asks of its granular noise a precision no affordable window has: at smoke scale the
  lateral force's pitch means scatter by 30--45 N against an allowance of 15 N (``docs/steady-detector.md``).
  What can be asked of it is that it does not trend, and that is what this test asks; its mean is then reported
  with its standard error, not as a value.

The tread is where the rig wants it when the tread slip over the window -- from the tread's mean spin
omega_t = pitch-angle / pitch-time, :func:`.kinematics.longitudinal_slip` (1 - v_x / (r omega_t) driving,
r omega_t / v_x - 1 braking) -- lies within ``slip_tolerance`` of the commanded slip and does not
itself drift by more than ``slip_tolerance`` (the tread turns at the hub's rate: the wind-up has settled).
If it is not steady, :func:`detect_steady_state` says which quantity failed and by how much.

A running testbed asks once per pitch and stops at the second steady verdict in a row
(:func:`confirm_steady`). How often all this calls a stationary run unsteady, and a drifting one steady, is
measured by a campaign of synthetic runs with the smoke runs' noise (``docs/steady_campaign.py`` ->
``docs/steady-detector.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np
from scipy.stats import t as student_t

from .kinematics import longitudinal_slip


@dataclass
class SteadyState:
    """What the detector found.

    steady: a steady window was found.
    k0, k1: sample indices of the window, [k0, k1) (the averaged samples).
    window: (t_start, t_end) [s] of the window (t_start is the start of the first sample's interval).
    pitches: whole pitches of the tread's rotation in the window.
    stats: per quantity ``{"mean", "std", "sem", "dof", "ci95", "drift", ...}`` over the window.
    tread_slip, tread_slip_sem: the tread slip from the window's mean spin and its standard error.
    reasons: why the best candidate window is not steady (empty when steady).
    bounds: the sample indices of the window's pitch boundaries, latest first (for :func:`window_stats` of
        other series).
    """

    steady: bool
    k0: int
    k1: int
    window: tuple[float, float]
    pitches: int
    stats: dict = field(default_factory=dict)
    tread_slip: float = math.nan
    tread_slip_sem: float = math.nan
    reasons: list = field(default_factory=list)
    bounds: list = field(default_factory=list)


def pitch_boundaries(angle: np.ndarray, k_end: int, pitch: float, k_min: int) -> list[int]:
    """Sample indices b_0 = k_end > b_1 > ... (>= k_min) at which the tread angle is one more pitch
    behind its value at ``k_end`` (nearest sample): the windows [b_m, k_end) span m whole pitches.

    ``angle[k]`` is the tread angle at the end of sample k's interval, so a window of samples
    [b, k_end) covers the rotation from angle[b - 1] to angle[k_end - 1].
    """
    end_angle = angle[k_end - 1]
    out = [k_end]
    m = 1
    while True:
        target = end_angle - m * pitch
        # first sample whose interval ends beyond target: the window starts after the sample ending nearest it
        j = int(np.searchsorted(angle[:k_end], target))
        if j <= 0:
            break
        nearest = j if j < k_end and abs(angle[j] - target) < abs(angle[j - 1] - target) else j - 1
        b = nearest + 1
        if b < k_min or b >= out[-1]:
            break
        out.append(b)
        m += 1
    return out


def pitch_noise(batches: np.ndarray, lag: int = 1) -> float:
    """Scatter sigma of a series of pitch means about its local level, from the mean square successive
    difference (von Neumann 1941): sigma^2 = sum_k (b_{k+L} - b_k)^2 / (2 (M - L)) at lag L. Unbiased for
    independent pitch means; a linear trend adds its squared change over L pitches / 2. With L the wheel's period
    in pitches, a pattern that repeats every period (grousers and spokes entering at different pitches) cancels
    from every difference. ``inf`` with no pair L apart."""
    b = np.asarray(batches, float)
    lag = max(1, int(lag))
    if len(b) <= lag:
        return math.inf
    return float(math.sqrt(float(np.sum((b[lag:] - b[:-lag]) ** 2)) / (2.0 * (len(b) - lag))))


def pitch_noise_dof(n: int, lag: int = 1) -> float:
    """Degrees of freedom nu of :func:`pitch_noise`'s variance estimate from ``n`` independent normal pitch means
    at lag L, matched to a chi-square's (nu = 2 sigma^4 / Var(sigma_hat^2)). For L = 1 the mean square successive
    difference q of n values has Var(q) = sigma^4 (3n - 4) / (n - 1)^2 (von Neumann, Kent, Bellinson & Hart 1941,
    Ann. Math. Stat. 12, 153, eq. for the variance of delta^2 / 2), so nu = 2 (n - 1)^2 / (3n - 4), about two
    thirds of the n - 1 of the sample variance. At lag L the differences form L independent chains, one per phase;
    their variances add to sigma^4 (3n - 4L) / (n - L)^2, so nu = 2 (n - L)^2 / (3n - 4L). 0 with no pair L apart."""
    lag = max(1, int(lag))
    pairs = int(n) - lag
    if pairs <= 0:
        return 0.0
    return 2.0 * pairs * pairs / (3.0 * pairs - lag)


@lru_cache(maxsize=1024)
def t_quantile(dof: float, level: float = 0.95) -> float:
    """Two-sided Student-t quantile t((1 + level) / 2, dof); inf for dof <= 0 (no noise estimate). Cached: a
    run asks for the same few degrees of freedom at every check."""
    if not dof > 0:
        return math.inf
    return float(student_t.ppf(0.5 + 0.5 * level, dof))


#: Standard errors a zero-within-noise quantity's mean, drift and halves may lie within (about 95 % each).
ZERO_WITHIN = 2.0


def periodic_trend(means: np.ndarray, period: int = 1) -> tuple[float, float]:
    """Slope [per pitch] of a line through pitch means that ride on a pattern repeating every ``period`` pitches,
    and the factor f with standard error = sigma f for pitch means of scatter sigma: the common slope of lines
    with one level per phase of the period (analysis of covariance), a = sum_p sum (x - xbar_p) (b - bbar_p) /
    S, S = sum_p sum (x - xbar_p)^2, f = 1 / sqrt(S). With ``period`` 1 this is the least-squares line.
    ``(0, inf)`` when no phase has two means."""
    b = np.asarray(means, float)
    x = np.arange(len(b), dtype=float)
    num = den = 0.0
    for p in range(max(1, int(period))):
        xp, bp = x[p::period], b[p::period]
        if len(xp) > 1:
            num += float(((xp - xp.mean()) * (bp - bp.mean())).sum())
            den += float(((xp - xp.mean()) ** 2).sum())
    return (num / den, 1.0 / math.sqrt(den)) if den > 0 else (0.0, math.inf)


def window_stats(y: np.ndarray, bounds: list[int], noise: float | None = None, period: int = 1,
                 noise_dof: float | None = None) -> dict:
    """Mean, standard deviation, standard errors and drift of ``y`` over the window [bounds[-1], bounds[0])
    split at the pitch boundaries ``bounds`` (descending), with the pitch means' scatter ``noise`` (default:
    :func:`pitch_noise` of the window's own pitch means at lag ``period``). ``period``: the wheel's period in
    pitches; the window should span whole periods, so that a pattern repeating every period drops out of the
    mean, of the drift (:func:`periodic_trend`) and of the change between its halves (whole periods each).
    ``noise_dof``: the degrees of freedom of ``noise`` (default: those of the window's own pitch means when
    ``noise`` is not given, else infinite, a normal quantile); ``ci95`` is Student's t at them times ``sem``. See the module docstring for the formulas."""
    k0, k1 = bounds[-1], bounds[0]
    period = max(1, int(period))
    seg = y[k0:k1]
    means = np.array([y[b1:b0].mean() for b0, b1 in zip(bounds[:-1], bounds[1:])])[::-1]  # in time order
    m = len(means)
    sigma = pitch_noise(means, period) if noise is None else float(noise)
    if noise_dof is None:
        noise_dof = pitch_noise_dof(m, period) if noise is None else math.inf
    sem = sigma / math.sqrt(m) if m > 1 else math.inf
    drift, drift_sem, step, step_sem = 0.0, math.inf, 0.0, math.inf
    slope, factor = periodic_trend(means, period)
    if math.isfinite(factor):
        drift, drift_sem = slope * (m - 1), sigma * factor * (m - 1)
    half = (m // period // 2) * period  # the halves in whole periods (the first is the shorter one)
    if 0 < half < m:
        step = float(means[half:].mean() - means[:half].mean())
        step_sem = sigma * math.sqrt(1.0 / half + 1.0 / (m - half))
    return {"mean": float(seg.mean()), "std": float(seg.std()), "noise": sigma, "sem": sem,
            "dof": float(noise_dof), "ci95": t_quantile(noise_dof) * sem, "drift": drift,
            "drift_sem": drift_sem, "step": step, "step_sem": step_sem}


def deseasonalised(means: np.ndarray, period: int) -> np.ndarray:
    """Pitch means less the mean of their phase of the period (phases counted back from the last mean, as the
    windows are), plus the overall mean: the series MSER looks at when grousers and spokes make a pattern."""
    b = np.asarray(means, float)
    if period <= 1:
        return b
    phase = (len(b) - 1 - np.arange(len(b))) % period
    out = b.copy()
    for p in range(period):
        out[phase == p] -= b[phase == p].mean() - b.mean()
    return out


def _pitch_means(t, angle, v, series: dict, bounds) -> tuple:
    """Per pitch, in time order: its duration [s], the tread's turn [rad], the mean travel speed and each series'
    mean (``bounds``: :func:`pitch_boundaries`, latest first)."""
    pairs = list(zip(bounds[1:], bounds[:-1]))[::-1]  # (start, end) of each pitch, in time order
    durations = np.array([t[e - 1] - t[s - 1] for s, e in pairs])
    turned = np.array([angle[e - 1] - angle[s - 1] for s, e in pairs])
    speeds = np.array([v[s:e].mean() for s, e in pairs])
    batches = {name: np.array([np.asarray(y, float)[s:e].mean() for s, e in pairs]) for name, y in series.items()}
    return durations, turned, speeds, batches


def _margin(confidence: float, sem: float) -> float:
    """``confidence`` standard errors ``sem`` (none at all when ``confidence`` is 0, even where sem is infinite)."""
    return confidence * sem if confidence else 0.0


def _quantity_reasons(name: str, st: dict, tolerance: float, floors: dict, zero_within: float,
                      drift_confidence: float = 0.0) -> list[str]:
    """Why quantity ``name``'s window statistics ``st`` are not steady (empty: steady); sets its
    ``zero_within_noise``. A quantity zero within its noise has no value to hold: it is steady when it does not
    trend beyond its noise; any other must drift, and change between the window's halves, by less than the
    tolerance times the larger of its mean and its floor, with ``drift_confidence`` standard errors of each
    added to it (0: the estimate alone must lie within the tolerance; 1: the estimate plus one standard error,
    so a window too short to tell its drift from the tolerance is not called steady)."""
    allowed = tolerance * max(abs(st["mean"]), floors.get(name, 0.0))
    st["zero_within_noise"] = bool(abs(st["mean"]) < zero_within * st["sem"])
    if st["zero_within_noise"]:
        if abs(st["drift"]) > zero_within * st["drift_sem"] or abs(st["step"]) > zero_within * st["step_sem"]:
            return [f"{name} is zero within its noise ({st['mean']:+.3g} +- {st['sem']:.2g}) but trends: "
                    f"drift {st['drift']:+.4g} +- {st['drift_sem']:.2g}, change between the window's halves "
                    f"{st['step']:+.4g} +- {st['step_sem']:.2g} (allowed: {zero_within:g} standard errors)"]
        return []
    margin = f" plus {drift_confidence:g} standard errors" if drift_confidence else ""
    if abs(st["drift"]) + _margin(drift_confidence, st["drift_sem"]) > allowed:
        return [f"{name} drifts by {st['drift']:+.4g} +- {st['drift_sem']:.2g} over the window (allowed "
                f"+-{allowed:.3g}{margin})" + ("; within its own noise: a longer window would tell"
                                               if abs(st["drift"]) < 2.0 * st["drift_sem"] else "")]
    elif abs(st["step"]) + _margin(drift_confidence, st["step_sem"]) > allowed:
        return [f"{name} changes by {st['step']:+.4g} +- {st['step_sem']:.2g} between the window's halves (allowed "
                f"+-{allowed:.3g}{margin})"]
    return []


def _tread_slip_stats(slip: float, per_pitch: np.ndarray, noise: dict, dof: int, period_pitches: int) -> dict:
    """The window's tread slip ``slip`` with its standard error (from every pitch since the earliest start where the
    slip was a checked series, else from the window's ``per_pitch`` slips), its 95 % interval and drift."""
    m = len(per_pitch)
    slip_noise = noise.get("tread_slip", pitch_noise(per_pitch, period_pitches))
    slip_sem = slip_noise / math.sqrt(m)
    slip_dof = dof if "tread_slip" in noise else pitch_noise_dof(m, period_pitches)
    return {"mean": slip, "std": float(np.std(per_pitch)), "sem": slip_sem, "dof": slip_dof,
            "ci95": t_quantile(slip_dof) * slip_sem, "drift": periodic_trend(per_pitch, period_pitches)[0] * (m - 1)}


def detect_steady_state(
    t: np.ndarray,
    series: dict,
    *,
    tread_angle: np.ndarray,
    travel_speed: np.ndarray,
    batch_angle: np.ndarray | None = None,
    radius: float,
    pitch: float,
    start: float,
    min_pitches: int,
    tolerance: float,
    floors: dict,
    slip_target: float | None,
    slip_tolerance: float,
    sample_interval: float,
    period_pitches: int = 1,
    zero_within: float = ZERO_WITHIN,
    truncation_search: float = 0.5,
    drift_confidence: float = 0.0,
) -> SteadyState:
    """The steady window ending at the last sample, its start chosen by MSER (see the module docstring).

    t: sample times [s] (end of each sample's interval); series: name -> per-sample values;
    tread_angle: the tread's rotation angle about its axle [rad] at each sample time (unwrapped,
    increasing while driving); travel_speed: the hub's travel velocity along the tread heading [m/s];
    batch_angle: the increasing angle [rad] whose pitches are the statistics' batches (default: the tread
    angle; a wheel dragged without turning gives its travel over r);
    radius: wheel radius for the slip [m]; pitch: grouser (or spoke) pitch [rad], the batch of the
    statistics; period_pitches: windows span a multiple of this many pitches (the wheel's whole period
    when spokes and grousers repeat at different pitches); start: earliest window start [s];
    floors: name -> floor of the relative tolerance; zero_within: standard errors within which a quantity
    counts as zero within its noise (0: every quantity must hold the tolerance); truncation_search: the
    fraction of the pitches since ``start`` over which MSER looks for the transient's end (0.5: the first half,
    MSER's own rule; 1.0: up to the shortest window, the search wheelsoil made before); drift_confidence: standard
    errors of a quantity's drift (and of its halves' change) added to the estimate before it is held to the
    tolerance (0: the estimate alone, the default; :func:`_quantity_reasons`); slip_target: commanded slip
    (``None``: the tread-slip criterion is skipped, e.g. to test the statistics alone).
    """
    t = np.asarray(t, float)
    n = len(t)
    angle = np.asarray(tread_angle, float)
    batch = angle if batch_angle is None else np.asarray(batch_angle, float)
    v = np.asarray(travel_speed, float)
    k_min = int(np.searchsorted(t - sample_interval, start - 1e-12))
    period_pitches = max(1, int(period_pitches))
    # at least three pitches and two whole periods (a drift needs two of each phase)
    min_pitches = max(3, 2 * period_pitches, int(math.ceil(min_pitches / period_pitches)) * period_pitches)
    short = SteadyState(False, n, n, ((float(t[-1]) if n else 0.0),) * 2, 0,
                        reasons=[f"the tread has not yet turned through {min_pitches} pitches "
                                 f"({math.degrees(min_pitches * pitch):.0f} deg) since t = {start:.3f} s"])
    if n < 2 or k_min >= n - 1 or not np.all(np.isfinite(batch[k_min:])):
        return short
    bounds = pitch_boundaries(batch, n, pitch, max(k_min, 1))
    if len(bounds) - 1 < min_pitches:
        return short
    n_pitches = (len(bounds) - 1)
    durations, turned, speeds, batches = _pitch_means(t, angle, v, series, bounds)
    per_pitch_slip = longitudinal_slip(speeds, turned / durations, radius)
    if slip_target is not None:
        batches["tread_slip"] = per_pitch_slip
    # MSER truncation: the latest start any quantity needs, searched over the first half of the pitches since
    # the earliest start and keeping at least min_pitches (a truncation in the second half is the noise of a
    # few close pitch means, not a transient's end: see the module docstring)
    # (a quantity constant to round-off -- the tread slip of a rigid wheel -- has no transient, and its MSER
    # truncation would be decided by the last digits of its samples: it is left out)
    latest = min(n_pitches - min_pitches, int(truncation_search * n_pitches))
    start_pitch = max([mser_truncation(deseasonalised(b, period_pitches), latest)
                       for b in batches.values() if varies(b)], default=0)
    m = (n_pitches - start_pitch) // period_pitches * period_pitches
    b = bounds[: m + 1]
    k0, k1 = b[-1], b[0]
    # each quantity's noise from all its pitch means since the earliest start: the successive differences
    # see a slow transient only through its change per pitch, and a window's few pitches alone would give
    # the noise with two or three degrees of freedom
    noise = {name: pitch_noise(bm, period_pitches) for name, bm in batches.items()}
    dof = pitch_noise_dof(n_pitches, period_pitches)
    stats = {name: window_stats(np.asarray(y, float), b, noise=noise[name], period=period_pitches, noise_dof=dof)
             for name, y in series.items()}
    reasons = [r for name, st in stats.items()
               for r in _quantity_reasons(name, st, tolerance, floors, zero_within, drift_confidence)]
    w = slice(n_pitches - m, n_pitches)
    spin = turned[w].sum() / durations[w].sum()
    slip = longitudinal_slip(float(speeds[w] @ durations[w] / durations[w].sum()), spin, radius)
    stats["tread_slip"] = _tread_slip_stats(slip, per_pitch_slip[w], noise, dof, period_pitches)
    slip_sem, slip_drift = stats["tread_slip"]["sem"], stats["tread_slip"]["drift"]
    if slip_target is not None:
        if not abs(slip - slip_target) <= slip_tolerance:
            reasons.append(f"tread slip {slip:.3f} differs from the commanded {slip_target:.3f} by more "
                           f"than {slip_tolerance:g} (the tread does not turn at the hub's rate)")
        if abs(slip_drift) > slip_tolerance:
            reasons.append(f"tread slip drifts by {slip_drift:+.3f} over the window (allowed "
                           f"+-{slip_tolerance:.3g}): the wheel is still winding up")
    last = SteadyState(not reasons, k0, k1, (float(t[k0] - sample_interval), float(t[k1 - 1])), m, stats,
                       slip, slip_sem, reasons, [int(x) for x in b])
    return last


def confirm_steady(state: SteadyState, in_a_row: int, required: int) -> tuple[SteadyState, int]:
    """Count a check's verdict towards ``required`` steady verdicts in a row (checks one period apart).

    Returns the verdict to report and the new count: a steady window that is not yet the ``required``-th in a
    row is reported not steady, and says so. The detector is asked again every period while a run drives, so
    one lucky window would let a drift comparable to its noise through sooner or later; requiring two in a row
    cuts that several-fold for one period more (``docs/steady-detector.md``)."""
    in_a_row = in_a_row + 1 if state.steady else 0
    if state.steady and in_a_row < required:
        state = replace(state, steady=False, reasons=[
            f"steady at {in_a_row} check(s) in a row, one period apart; {required} are required (steady_checks)"])
    return state, in_a_row


#: Relative spread of pitch means below which a quantity counts as constant (round-off of float64 sums).
CONSTANT_SPREAD = 1e-9


def varies(batches: np.ndarray) -> bool:
    """Whether pitch means differ by more than round-off: their spread exceeds :data:`CONSTANT_SPREAD` times
    their largest magnitude (a commanded value, such as a rigid wheel's tread slip, does not)."""
    b = np.asarray(batches, float)
    return bool(b.size and np.ptp(b) > CONSTANT_SPREAD * max(float(np.max(np.abs(b))), 1e-300))


def mser_truncation(batches: np.ndarray, latest: int) -> int:
    """The MSER truncation point d in [0, latest] of a series of batch means: argmin over d of
    sum_{k>=d} (b_k - mean(b_d..))^2 / (M - d)^2 (White 1997)."""
    b = np.asarray(batches, float)
    m = len(b)
    best, best_d = math.inf, 0
    for d in range(0, max(0, min(latest, m - 2)) + 1):
        tail = b[d:]
        value = float(np.sum((tail - tail.mean()) ** 2)) / (m - d) ** 2
        if value < best:
            best, best_d = value, d
    return best_d
