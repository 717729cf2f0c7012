"""Periodic components in measured time series, and the mechanism whose frequency law explains them.

Seed 002 finds drawbar-pull and torque oscillations on a smooth wheel in sand whose frequency falls
linearly with slip (eq. 25, omega_osc = -36.9 i + 36.5 rad/s) and whose amplitude scales with the contact
length (eq. 24); on grousered wheels the oscillation follows the grouser spacing (its ref. [11]); a
flexible wheel's stiffness peaks at its (virtual) spokes (seed 000 eq. 19, six per turn on the ExoMars
wheel). Each of these is a frequency law for a run at wheel speed omega and slip i:

* ``grouser_passing``: f = N_g omega / (2 pi) (N_g grousers per turn);
* ``spoke_stiffness``: f = N_s omega / (2 pi) (N_s spokes or stiffness peaks per turn);
* ``wheel_rotation``: f = omega / (2 pi) (run-out, once per turn);
* ``slip_density_wave``: f = a + b i (seed 002 eqs. 20, 25; two parameters fitted across runs);
* ``natural_mode``: f = f0, whatever the wheel speed and slip: a mode of the rig that the rolling only
  excites, such as the wheel's mass heaving on the stiffness of the soil and the wheel (one parameter;
  named only when the runs span more than one wheel speed, since at one speed every counting law is a
  constant too).

:func:`dominant_component` finds the strongest sinusoid of one series (linear trend removed, periodogram
peak refined by least squares) and tests it against white noise with Fisher's g statistic.
:func:`explain_frequencies` compares the laws across runs by the spread of the measured frequencies
about each law, with BIC charging the fitted laws for their parameters: each must beat the simpler laws
by :data:`BIC_MARGIN`.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import periodogram

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.gravity import gravity_label
from wheelsoil.provenance import write_markdown_and_json

#: p-value below which a periodogram peak counts as a periodic component.
SIGNIFICANCE = 1e-3
#: Relative frequency tolerance of the counting laws (a frequency within it matches the law).
LAW_TOLERANCE = 0.05
#: BIC advantage the two-parameter slip law needs over a parameter-free counting law (strong evidence).
BIC_MARGIN = 10.0
#: Significant runs a fitted law needs beyond its parameters (a line through 3 points proves nothing).
SPARE_RUNS = 3
#: R^2 of the wheel speed explained by the slip above which the two are tied (see :func:`speed_slip_confound`).
CONFOUND_R2 = 0.98


@dataclass
class Component:
    """The strongest sinusoid of a series: y ~ A sin(2 pi f t + phase) about a linear trend."""

    frequency: float  # [Hz]
    amplitude: float  # [units of y]
    phase: float  # [rad]
    p_value: float  # Fisher's g test against white noise
    explained: float  # fraction of the detrended variance the sinusoid explains
    ar1: float = 0.0  # lag-1 autocorrelation of the noise the test assumed (0: white)

    @property
    def significant(self) -> bool:
        return self.p_value < SIGNIFICANCE


def _comb(m: int, k: int) -> float:
    from math import comb

    return float(comb(m, k))


def fisher_g(power: np.ndarray) -> float:
    """p-value of Fisher's g = max / sum of m periodogram ordinates under white noise (exact series,
    truncated where its terms vanish)."""
    power = np.asarray(power, float)
    m = power.size
    g = float(power.max() / power.sum())
    total = 0.0
    for k in range(1, int(np.floor(1.0 / g)) + 1):
        total += (-1.0) ** (k - 1) * _comb(m, k) * (1.0 - k * g) ** (m - 1)
    return float(np.clip(total, 0.0, 1.0))


def ar1_coefficient(r: np.ndarray) -> float:
    """Lag-1 autocorrelation of a zero-mean series, clipped to [0, 0.99] (the AR(1) red-noise parameter)."""
    r = np.asarray(r, float) - np.mean(r)
    return float(np.clip(np.dot(r[:-1], r[1:]) / max(np.dot(r, r), 1e-300), 0.0, 0.99))


def red_noise_spectrum(f: np.ndarray, fs: float, phi: float) -> np.ndarray:
    """Shape of the AR(1) spectrum, 1 / (1 + phi^2 - 2 phi cos(2 pi f / fs)) (Gilman et al. 1963; the red-noise
    background of Torrence & Compo 1998, eq. 16), up to the noise variance."""
    return 1.0 / (1.0 + phi * phi - 2.0 * phi * np.cos(2.0 * np.pi * np.asarray(f) / fs))


def dominant_component(t, y, *, min_cycles: float = 2.0, noise: str = "white") -> Component:
    """The strongest periodic component of a uniformly sampled series (``t`` [s], ``y``).

    ``noise``: the null hypothesis of the significance test. ``"white"``: Fisher's g on the periodogram.
    ``"red"``: the periodogram divided by the AR(1) spectrum of the residual (lag-1 autocorrelation
    estimated after removing the candidate sinusoid, so the oscillation does not redden its own
    background), then Fisher's g on those whitened ordinates, which are independent and exponential
    under the red null. Force series of a granular flow are red (neighbouring samples share contacts):
    there a white-noise test calls most records periodic, so use ``"red"`` for simulated or measured
    rig data.

    Frequencies with fewer than ``min_cycles`` periods in the record are not considered (a trend is not an
    oscillation). Raises a clear error for records that are too short or not uniformly sampled.
    """
    if noise not in ("white", "red"):
        raise WheelsoilInputError(f"noise = {noise!r}; choose 'white' or 'red'")
    t, y = np.asarray(t, float), np.asarray(y, float)
    if t.shape != y.shape or t.ndim != 1 or t.size < 16:
        raise WheelsoilInputError(f"a time series needs matching 1-D t and y of at least 16 samples, got {t.shape}, {y.shape}")
    dt = np.diff(t)
    if not (np.all(dt > 0) and np.ptp(dt) <= 1e-4 * dt.mean()):  # 1e-4: times written with 9 digits
        raise WheelsoilInputError("the time series must be uniformly sampled with increasing t")
    fs = 1.0 / dt.mean()
    design = np.stack([np.ones_like(t), t - t.mean()], axis=1)
    trend = design @ np.linalg.lstsq(design, y, rcond=None)[0]
    r = y - trend
    f, p = periodogram(r, fs=fs, detrend=False, scaling="spectrum")
    keep = f >= min_cycles / (t[-1] - t[0])
    keep[-1] = keep[-1] and (t.size % 2 == 1)  # the Nyquist ordinate has one degree of freedom
    if keep.sum() < 4:
        raise WheelsoilInputError(f"the record ({t[-1] - t[0]:.3g} s at {fs:.3g} Hz) is too short for {min_cycles} cycles")
    f, p = f[keep], p[keep]
    phi = 0.0
    if noise == "red":
        for _ in range(2):  # background from the residual once the candidate sinusoid is removed
            f_peak = f[np.argmax(p / red_noise_spectrum(f, fs, phi))]
            w = 2 * np.pi * f_peak * t
            basis = np.stack([np.sin(w), np.cos(w)], axis=1)
            phi = ar1_coefficient(r - basis @ np.linalg.lstsq(basis, r, rcond=None)[0])
        p = p / red_noise_spectrum(f, fs, phi)
    p_value = fisher_g(p)
    f0 = f[np.argmax(p)]

    # refine: the trend and the sinusoid fitted together (a separate detrend would take part of a
    # slow oscillation with few cycles in the record)
    tc = t - t.mean()

    def resid(x):
        freq, a, b, c0, c1 = x
        w = 2 * np.pi * freq * (t - t[0])
        return y - a * np.sin(w) - b * np.cos(w) - c0 - c1 * tc

    w0 = 2 * np.pi * f0 * (t - t[0])
    a0, b0, c00, c10 = np.linalg.lstsq(np.stack([np.sin(w0), np.cos(w0), np.ones_like(t), tc], axis=1), y,
                                       rcond=None)[0]
    df = f[1] - f[0] if f.size > 1 else f0
    inf = np.inf
    sol = least_squares(resid, [f0, a0, b0, c00, c10], bounds=([f0 - df, -inf, -inf, -inf, -inf], [f0 + df, inf, inf, inf, inf]))
    freq, a, b = sol.x[:3]
    explained = 1.0 - float(np.sum(resid(sol.x) ** 2) / np.sum(r ** 2))
    return Component(float(freq), float(np.hypot(a, b)), float(np.arctan2(b, a)), p_value, explained, phi)


@dataclass
class Run:
    """One steady run: wheel speed omega [rad/s], slip, and its series' dominant component."""

    omega: float
    slip: float
    component: Component


def speed_slip_confound(omega: np.ndarray, slip: np.ndarray) -> tuple[float, str | None]:
    """How far the runs' wheel speed is a function of their slip, and what that means for the laws.

    A rig driven at constant carriage speed v sets omega = v / (r (1 - i)): every counting law then reads
    f = N v / (2 pi r (1 - i)), a smooth function of slip that a slip law f = a + b i follows closely, so a
    count per turn and a slip-dependent frequency cannot be told apart. The wheel speed is regressed on
    (1, i, 1 / (1 - i)); R^2 >= :data:`CONFOUND_R2` counts as tied. Returns (R^2, a note or None); one wheel
    speed is the limiting case (every counting law a constant)."""
    omega, slip = np.asarray(omega, float), np.asarray(slip, float)
    if np.ptp(omega) == 0:
        return 1.0, ("one wheel speed: every counting law is a constant frequency, so a count per turn, a natural "
                     "mode and (with slip held too) a slip law cannot be told apart; vary the wheel speed")
    design = np.column_stack([np.ones_like(slip), slip, 1.0 / np.maximum(1.0 - slip, 1e-3)])
    coef, *_ = np.linalg.lstsq(design, omega, rcond=None)
    resid = omega - design @ coef
    r2 = 1.0 - float(resid @ resid) / float(np.sum((omega - omega.mean()) ** 2))
    if r2 >= CONFOUND_R2:
        return r2, (f"the wheel speed is tied to the slip (R² = {r2:.3f}; e.g. a constant carriage speed): a count "
                    "per turn and a slip-dependent frequency cannot be told apart; vary the wheel speed at a fixed "
                    "slip")
    return r2, None


def explain_frequencies(runs: list[Run], *, grousers: int = 0, spokes: int = 0) -> dict:
    """Which frequency law explains the significant components of ``runs`` (see the module docstring).

    Returns {"found": law name or None, "laws": {name: {"rms_relative_error", "bic", "parameters"}},
    "significant_runs": n}. A counting law is found when every significant frequency lies within
    :data:`LAW_TOLERANCE` of it; the slip law when it fits with lower BIC than every counting law and its
    relative error is within the same tolerance. Nothing is found without significant components in at
    least three runs, and a fitted law is considered only with :data:`SPARE_RUNS` more significant runs than
    it has parameters.

    Two checks keep a law from being named where the data cannot support it: the slip law must have seed 002's
    sign (eq. 25: the frequency falls with slip, b < 0), and where the wheel speed is tied to the slip
    (:func:`speed_slip_confound`) a law is named only if no other law fits within the tolerance too; otherwise
    ``ambiguous`` lists the laws that fit and ``confound`` says why. Significant components that no law explains
    (and no ambiguity covers) are described in ``unexplained``: their count per wheel turn, or their frequency
    range, beside the wheel's declared grousers and spokes.
    """
    sig = [r for r in runs if r.component.significant]
    out = {"found": None, "laws": {}, "significant_runs": len(sig)}
    if len(sig) < 3:
        return out
    f = np.array([r.component.frequency for r in sig])
    omega = np.array([r.omega for r in sig])
    slip = np.array([r.slip for r in sig])
    n = f.size
    laws = {"wheel_rotation": omega / (2 * np.pi)}
    if grousers:
        laws["grouser_passing"] = grousers * omega / (2 * np.pi)
    if spokes:
        laws["spoke_stiffness"] = spokes * omega / (2 * np.pi)
    for name, pred in laws.items():
        rel = (f - pred) / f
        out["laws"][name] = {"rms_relative_error": float(np.sqrt(np.mean(rel ** 2))), "parameters": {},
                             "bic": n * np.log(max(np.mean(rel ** 2), 1e-300))}
    rel = (f - f.mean()) / f
    fitted = {"natural_mode": n >= 1 + SPARE_RUNS, "slip_density_wave": n >= 2 + SPARE_RUNS}
    out["laws"]["natural_mode"] = {
        "rms_relative_error": float(np.sqrt(np.mean(rel ** 2))), "parameters": {"f_hz": float(f.mean())},
        "bic": n * np.log(max(np.mean(rel ** 2), 1e-300)) + np.log(n),
    }
    if np.ptp(slip) > 0:
        coef = np.polyfit(slip, f, 1)
        rel = (f - np.polyval(coef, slip)) / f
        out["laws"]["slip_density_wave"] = {
            "rms_relative_error": float(np.sqrt(np.mean(rel ** 2))),
            "parameters": {"a_hz": float(coef[1]), "b_hz": float(coef[0])},
            "bic": n * np.log(max(np.mean(rel ** 2), 1e-300)) + 2 * np.log(n),
        }
    r2, confound = speed_slip_confound(omega, slip)
    out["speed_slip_r2"] = r2
    if confound and np.ptp(omega) > 0:
        out["confound"] = confound
    if slip_law_fit := out["laws"].get("slip_density_wave"):
        b = slip_law_fit["parameters"]["b_hz"]
        slip_law_fit["seed_002_sign"] = bool(b < 0)
        if b >= 0:
            slip_law_fit["note"] = (f"frequency rising with slip (b = {b:+.3g} Hz): the opposite of seed 002 eq. 25 "
                                    "(omega_osc = -36.9 i + 36.5 rad/s), so not its density wave")
    counting = [k for k in out["laws"] if k not in ("slip_density_wave", "natural_mode")]
    best = min(counting, key=lambda k: out["laws"][k]["bic"])
    # a law with fitted parameters must beat the simpler laws by strong evidence: the one-parameter
    # natural mode the parameter-free counting laws, the two-parameter slip law both (it nests the mode)
    if fitted["natural_mode"] and out["laws"]["natural_mode"]["bic"] < out["laws"][best]["bic"] - BIC_MARGIN:
        best = "natural_mode"
    slip_law = out["laws"].get("slip_density_wave")
    if (fitted["slip_density_wave"] and slip_law
            and slip_law["bic"] < min(out["laws"][best]["bic"], out["laws"]["natural_mode"]["bic"]) - BIC_MARGIN):
        best = "slip_density_wave"
    fitting = sorted(k for k, v in out["laws"].items() if v["rms_relative_error"] <= LAW_TOLERANCE
                     and (k != "slip_density_wave" or (fitted["slip_density_wave"] and v["seed_002_sign"]))
                     and (k != "natural_mode" or fitted["natural_mode"]))
    if best == "slip_density_wave" and not slip_law["seed_002_sign"]:
        out["note"] = slip_law["note"]
    elif out["laws"][best]["rms_relative_error"] <= LAW_TOLERANCE and "confound" in out and len(fitting) > 1:
        out["ambiguous"] = fitting
        out["note"] = f"{' and '.join(fitting)} all fit: {out['confound']}"
    elif out["laws"][best]["rms_relative_error"] <= LAW_TOLERANCE:
        if best == "natural_mode" and np.ptp(omega) == 0:
            # at one wheel speed every counting law is a constant frequency too
            out["note"] = (f"a constant frequency of {f.mean():.3g} Hz at one wheel speed: a natural mode and a "
                           "counting law cannot be told apart; vary the wheel speed")
        else:
            out["found"] = best
    if out["found"] is None and "ambiguous" not in out:
        out["unexplained"] = _unexplained_oscillation(f, omega, grousers, spokes)
    return out


def _unexplained_oscillation(f: np.ndarray, omega: np.ndarray, grousers: int, spokes: int) -> str:
    """What the significant components ``f`` [Hz] that no law explains look like, in words: the count per wheel
    turn when it is steady across runs (within :data:`LAW_TOLERANCE`), else their frequency range."""
    counts = 2 * np.pi * f / omega
    declared = f"the declared wheel has {grousers} grousers and {spokes} spokes"
    if np.std(counts) <= LAW_TOLERANCE * np.mean(counts):
        return (f"significant oscillations in {f.size} runs at {np.mean(counts):.3g} ± {np.std(counts):.2f} per "
                f"wheel turn, which no law explains ({declared})")
    return (f"significant oscillations in {f.size} runs at {f.min():.3g}-{f.max():.3g} Hz ({counts.min():.3g}-"
            f"{counts.max():.3g} per wheel turn), which no law explains ({declared})")


# -------------------------------------------------------------------- simulated time series
@dataclass
class SeriesRun(Run):
    """A :class:`Run` taken from a result file, with where it came from and its record."""

    name: str = ""
    quantity: str = ""
    record_seconds: float = 0.0

    @property
    def cycles(self) -> float:
        """Periods of the dominant component inside the record."""
        return self.component.frequency * self.record_seconds


def runs_from_results(results, quantity: str = "torque", *, noise: str = "red", min_cycles: float = 2.0) -> list:
    """The dominant component of ``quantity`` in the driving part of each result (after the spin-up), as
    :class:`SeriesRun` objects for :func:`explain_frequencies`.

    ``results``: :class:`~wheelsoil.cases.results.Result` objects (``wheelsoil.cases.load_result``). Wheel
    speed and slip come from each result's case.
    """
    runs = []
    for r in results:
        if quantity not in r.series:
            raise WheelsoilInputError(f"{r.path} has no series {quantity!r}; it has {sorted(r.series)}")
        case = r.case
        t0 = float(drive_start(r.info)) + case.test.spin_up_time
        sel = r.series["t"] >= t0 - 1e-12
        t, y = r.series["t"][sel], r.series[quantity][sel]
        comp = dominant_component(t, y, min_cycles=min_cycles, noise=noise)
        runs.append(SeriesRun(case.test.angular_velocity, case.test.slip, comp, name=case.name, quantity=quantity,
                              record_seconds=float(t[-1] - t[0])))
    return runs


def wheel_counts(geometry) -> tuple[int, int]:
    """(grousers, stiffness peaks per turn) of a wheel geometry, for the counting laws."""
    return int(geometry.grouser_count), int(round(360.0 / geometry.spoke_pitch))


def rig_configuration(case) -> str:
    """The label of what sets a run's natural modes besides the wheel speed and slip: wheel kind, gravity, load."""
    g = -case.soil.gravity_vector[2]
    gname = gravity_label(g, moon="moon", other="g={g:.3g}")
    return f"{'rigid' if case.wheel.rigid else 'flexible'} wheel, {gname}, W = {case.test.load:g} N"


def drive_start(info: dict) -> float:
    """Simulated time [s] at which a run's spin-up began, from its run info (``t_spin_up``; result files
    written before the wind-up protocol call it ``t_drive_start``)."""
    for key in ("t_spin_up", "t_drive_start"):
        if key in info:
            return float(info[key])
    raise WheelsoilInputError(f"the run info has no spin-up time (t_spin_up); keys: {sorted(info)}")


def periodic_report(results, quantity: str = "torque", *, source: str = "the runs", report=None,
                    command: str = "") -> dict:
    """Dominant components of ``quantity`` over finished runs and, for each rig configuration (wheel kind,
    gravity, load: :func:`rig_configuration`), the frequency law that explains them; a markdown + JSON report in
    ``report`` (if given).

    results: finished runs as read by the caller (``wheelsoil.cases.results.load_result``): each with ``wheel``
    (its :class:`~wheelsoil.flexwheel.geometry.WheelGeometry`), ``case`` (its case file: ``wheel.rigid``,
    ``soil.gravity_vector``, ``test``), ``info`` and ``series``, as :func:`runs_from_results` reads them;
    source: what they are, for titles and errors (e.g. the sweep folder). Validation reads results through this
    interface and does not import the case layer."""
    results = list(results)
    if not results:
        raise WheelsoilInputError(f"{source} holds no finished runs; run 'wheelsoil batch' first")
    wheels = {wheel_counts(r.wheel) for r in results}
    if len(wheels) != 1:
        raise WheelsoilInputError(f"{source} use different wheels {sorted(wheels)}; the frequency laws "
                                  "compare runs of one wheel")
    grousers, spokes = wheels.pop()
    runs = runs_from_results(results, quantity)
    configs = [rig_configuration(r.case) for r in results]
    groups = {}
    for config in sorted(set(configs)):
        members = [run for run, c in zip(runs, configs) if c == config]
        groups[config] = explain_frequencies(members, grousers=grousers, spokes=spokes)
    rows = [{"case": r.name, "configuration": c, "omega_rad_s": r.omega, "slip": r.slip,
             "frequency_hz": r.component.frequency, "amplitude": r.component.amplitude,
             "p_value": r.component.p_value, "ar1": r.component.ar1, "record_s": r.record_seconds,
             "cycles": r.cycles, "significant": r.component.significant}
            for r, c in sorted(zip(runs, configs), key=lambda rc: (rc[1], rc[0].omega, rc[0].slip, rc[0].name))]
    out = {"quantity": quantity, "grousers": grousers, "stiffness_peaks_per_turn": spokes, "runs": rows,
           "configurations": groups}
    if report is not None:
        report = Path(report)
        lines = [f"# Periodic components of {quantity} in {source}", ""]
        if command:
            lines += [f"Reproduce: `{command}`", ""]
        lines += [f"Dominant component of each run's {quantity} over its drive (after the spin-up), tested against "
                  f"red (AR(1)) noise at p < {SIGNIFICANCE:g}; the wheel has {grousers} grousers and {spokes} "
                  "stiffness peaks per turn. Laws are compared within each rig configuration (wheel kind, "
                  "gravity, load), since those set a natural mode.", "",
                  "| case | configuration | omega [rad/s] | slip | f [Hz] | amplitude | p | AR(1) | cycles |",
                  "|---|---|---|---|---|---|---|---|---|"]
        lines += [f"| {r['case']} | {r['configuration']} | {r['omega_rad_s']:g} | {r['slip']:g} | "
                  f"{r['frequency_hz']:.2f} | {r['amplitude']:.3g} | {r['p_value']:.1e} | {r['ar1']:.2f} | "
                  f"{r['cycles']:.1f} |" for r in rows]
        for config, found in groups.items():
            lines += ["", f"## {config}", ""]
            if found["laws"]:
                lines += ["| law | rms relative error | BIC | parameters |", "|---|---|---|---|"]
                lines += [f"| {k} | {v['rms_relative_error']:.3f} | {v['bic']:.1f} | "
                          + ", ".join(f"{p} = {x:.3g}" for p, x in v["parameters"].items()) + " |"
                          for k, v in found["laws"].items()]
            if "confound" in found:
                lines += ["", f"Confound: {found['confound']}."]
            if found["found"]:
                lines += ["", f"**{found['found']}** explains the significant components (within {LAW_TOLERANCE:.0%})."]
            elif "note" in found:
                lines += ["", f"No law named: {found['note']}."]
            else:
                short = "; at least 3 are needed" if found["significant_runs"] < 3 else ""
                lines += ["", f"No law explains them within {LAW_TOLERANCE:.0%} and beats the simpler laws by "
                          f"{BIC_MARGIN:g} in BIC ({found['significant_runs']} significant runs{short})."]
            if "unexplained" in found:
                lines += ["", f"Unexplained: {found['unexplained']}."]
        out["report"] = str(write_markdown_and_json(report / "periodic.md", "\n".join(lines) + "\n",
                                                    report / "periodic.json", out))
    return out
