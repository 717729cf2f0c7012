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
* ``drift``: the change over the window of the least-squares line through the pitch means, and
  ``drift_sem`` its standard error, noise sqrt(12 (m - 1) / (m (m + 1))) (the slope's variance
  12 sigma^2 / (m (m^2 - 1)), times (m - 1)^2).

Where the window starts -- how much of the run is start-up transient -- is chosen by the marginal standard
error rule on the pitch means (MSER: White 1997, Simulation 69, 323; White, Cobb & Spratt 2000; batch means
as in MSER-5): for each quantity the truncation d that minimises sum_{k>=d} (b_k - mean_d)^2 / (M - d)^2 over
the M pitch means b_k, and the window starts after the latest of them (every quantity past its transient).

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

The tread is where the rig wants it when the tread slip over the window -- from the tread's mean spin,
1 - v_x / (r pitch-angle / pitch-time) -- lies within ``slip_tolerance`` of the commanded slip and does not
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

import numpy as np


@dataclass
class SteadyState:
    """What the detector found.

    steady: a steady window was found.
    k0, k1: sample indices of the window, [k0, k1) (the averaged samples).
    window: (t_start, t_end) [s] of the window (t_start is the start of the first sample's interval).
    pitches: whole pitches of the tread's rotation in the window.
    stats: per quantity ``{"mean", "std", "sem", "drift"}`` over the window.
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


def pitch_noise(batches: np.ndarray) -> float:
    """Scatter sigma of a series of pitch means about its local level, from the mean square successive
    difference (von Neumann 1941): sigma^2 = sum_k (b_{k+1} - b_k)^2 / (2 (M - 1)). Unbiased for independent
    pitch means; a linear trend adds its squared change per pitch / 2. ``inf`` with fewer than two means."""
    b = np.asarray(batches, float)
    if len(b) < 2:
        return math.inf
    return float(math.sqrt(float(np.sum(np.diff(b) ** 2)) / (2.0 * (len(b) - 1))))


#: Standard errors a zero-within-noise quantity's mean, drift and halves may lie within (about 95 % each).
ZERO_WITHIN = 2.0


def window_stats(y: np.ndarray, bounds: list[int], noise: float | None = None) -> dict:
    """Mean, standard deviation, standard errors and drift of ``y`` over the window [bounds[-1], bounds[0])
    split at the pitch boundaries ``bounds`` (descending), with the pitch means' scatter ``noise`` (default:
    :func:`pitch_noise` of the window's own pitch means). See the module docstring for the formulas."""
    k0, k1 = bounds[-1], bounds[0]
    seg = y[k0:k1]
    means = np.array([y[b1:b0].mean() for b0, b1 in zip(bounds[:-1], bounds[1:])])[::-1]  # in time order
    m = len(means)
    sigma = pitch_noise(means) if noise is None else float(noise)
    sem = sigma / math.sqrt(m) if m > 1 else math.inf
    drift, drift_sem, step, step_sem = 0.0, math.inf, 0.0, math.inf
    if m > 1:
        x = np.arange(m, dtype=float)
        drift = float(np.polyfit(x, means, 1)[0] * (m - 1))
        drift_sem = sigma * math.sqrt(12.0 * (m - 1) / (m * (m + 1)))
        half = m // 2
        step = float(means[half:].mean() - means[:half].mean())
        step_sem = sigma * math.sqrt(1.0 / half + 1.0 / (m - half))
    return {"mean": float(seg.mean()), "std": float(seg.std()), "noise": sigma, "sem": sem, "drift": drift,
            "drift_sem": drift_sem, "step": step, "step_sem": step_sem}


def detect_steady_state(
    t: np.ndarray,
    series: dict,
    *,
    tread_angle: np.ndarray,
    travel_speed: np.ndarray,
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
) -> SteadyState:
    """The steady window ending at the last sample, its start chosen by MSER (see the module docstring).

    t: sample times [s] (end of each sample's interval); series: name -> per-sample values;
    tread_angle: the tread's rotation angle about its axle [rad] at each sample time (unwrapped,
    increasing while driving); travel_speed: the hub's travel velocity along the tread heading [m/s];
    radius: wheel radius for the slip [m]; pitch: grouser (or spoke) pitch [rad], the batch of the
    statistics; period_pitches: windows span a multiple of this many pitches (the wheel's whole period
    when spokes and grousers repeat at different pitches); start: earliest window start [s];
    floors: name -> floor of the relative tolerance; zero_within: standard errors within which a quantity
    counts as zero within its noise (0: every quantity must hold the tolerance); slip_target: commanded slip
    (``None``: the tread-slip criterion is skipped, e.g. to test the statistics alone).
    """
    t = np.asarray(t, float)
    n = len(t)
    angle = np.asarray(tread_angle, float)
    v = np.asarray(travel_speed, float)
    k_min = int(np.searchsorted(t - sample_interval, start - 1e-12))
    period_pitches = max(1, int(period_pitches))
    min_pitches = max(3, int(math.ceil(min_pitches / period_pitches)) * period_pitches)
    short = SteadyState(False, n, n, ((float(t[-1]) if n else 0.0),) * 2, 0,
                        reasons=[f"the tread has not yet turned through {min_pitches} pitches "
                                 f"({math.degrees(min_pitches * pitch):.0f} deg) since t = {start:.3f} s"])
    if n < 2 or k_min >= n - 1 or not np.all(np.isfinite(angle[k_min:])):
        return short
    bounds = pitch_boundaries(angle, n, pitch, max(k_min, 1))
    if len(bounds) - 1 < min_pitches:
        return short
    n_pitches = (len(bounds) - 1)
    pairs_all = list(zip(bounds[1:], bounds[:-1]))[::-1]  # (start, end) of each pitch, in time order
    durations = np.array([t[e - 1] - t[s - 1] for s, e in pairs_all])
    turned = np.array([angle[e - 1] - angle[s - 1] for s, e in pairs_all])
    speeds = np.array([v[s:e].mean() for s, e in pairs_all])
    per_pitch_slip = 1.0 - speeds / (radius * turned / durations)
    batches = {name: np.array([np.asarray(y, float)[s:e].mean() for s, e in pairs_all]) for name, y in series.items()}
    if slip_target is not None:
        batches["tread_slip"] = per_pitch_slip
    # MSER truncation: the latest start any quantity needs, keeping at least min_pitches
    start_pitch = max(mser_truncation(b, n_pitches - min_pitches) for b in batches.values())
    m = (n_pitches - start_pitch) // period_pitches * period_pitches
    b = bounds[: m + 1]
    k0, k1 = b[-1], b[0]
    # each quantity's noise from all its pitch means since the earliest start: the successive differences
    # see a slow transient only through its change per pitch, and a window's few pitches alone would give
    # the noise with two or three degrees of freedom
    noise = {name: pitch_noise(bm) for name, bm in batches.items()}
    stats = {name: window_stats(np.asarray(y, float), b, noise=noise[name]) for name, y in series.items()}
    reasons = []
    for name, st in stats.items():
        allowed = tolerance * max(abs(st["mean"]), floors.get(name, 0.0))
        st["zero_within_noise"] = bool(abs(st["mean"]) < zero_within * st["sem"])
        if st["zero_within_noise"]:
            # no value to hold: steady when it does not trend beyond its noise
            if abs(st["drift"]) > zero_within * st["drift_sem"] or abs(st["step"]) > zero_within * st["step_sem"]:
                reasons.append(f"{name} is zero within its noise ({st['mean']:+.3g} +- {st['sem']:.2g}) but trends: "
                               f"drift {st['drift']:+.4g} +- {st['drift_sem']:.2g}, change between the window's halves "
                               f"{st['step']:+.4g} +- {st['step_sem']:.2g} (allowed: {zero_within:g} standard errors)")
        elif abs(st["drift"]) > allowed:
            reasons.append(f"{name} drifts by {st['drift']:+.4g} +- {st['drift_sem']:.2g} over the window (allowed "
                           f"+-{allowed:.3g})" + ("; within its own noise: a longer window would tell"
                                                  if abs(st["drift"]) < 2.0 * st["drift_sem"] else ""))
        elif abs(st["step"]) > allowed:
            reasons.append(f"{name} changes by {st['step']:+.4g} between the window's halves (allowed +-{allowed:.3g})")
    w = slice(n_pitches - m, n_pitches)
    spin = turned[w].sum() / durations[w].sum()
    slip = 1.0 - float(speeds[w] @ durations[w] / durations[w].sum()) / (radius * spin) if spin > 0 else math.nan
    slip_noise = noise.get("tread_slip", pitch_noise(per_pitch_slip[w]))
    slip_sem = slip_noise / math.sqrt(m)
    slip_drift = float(np.polyfit(np.arange(m, dtype=float), per_pitch_slip[w], 1)[0] * (m - 1))
    stats["tread_slip"] = {"mean": slip, "std": float(np.std(per_pitch_slip[w])), "sem": slip_sem, "drift": slip_drift}
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
