"""How large the oscillations are: the amplitude side of the periodic mechanisms, each with its own parameter.

:mod:`.periodic` finds the oscillation in each run's time series and names the law its *frequency*
follows. This module asks which mechanism explains its *amplitude* from run to run, given the calibrated
steady model (:mod:`.terramechanics`), and measures the gain on held-out runs:

* ``density_wave`` (seed 002 eqs. 17--19, 24, 26). Under a slipping smooth wheel the soil's weight density
  varies by d gamma about gamma = rho g (seed 002 uses d gamma = 0.10 gamma: :data:`DENSITY_VARIATION`);
  this adds A_gamma sin(omega t + Phi) to the normal stress over the whole contact, with::

      A_gamma = l_c d gamma k'_a        (eq. 24),      l_c = r (theta_f - theta_r)        (eq. 19)

  Parameter: the amplitude factor k'_a (110 in seed 002 Table 2). The force and torque integrals are linear
  in the normal stress, so a response X oscillates with amplitude |X(sigma + A_gamma) - X(sigma)| at the
  steady sinkage (the oscillation, omega ~ 36 rad/s in seed 002 eq. 25, is fast against the sinkage).
* ``spoke_radius`` (seed 000 eq. 19, Table 3). A flexible wheel's surrogate radius varies with its rotation
  angle theta_w, stiff where its (virtual) spokes meet the ground::

      R(theta_w) = R_max W,   W = 1 - (R_max - R_min) / (2 R_max) (1 + tanh(cos(nu theta_w)))      (eq. 19)

  with nu stiffness peaks per turn. W averages 1 - (R_max - R_min) / (2 R_max) over a period (tanh(cos) is
  odd about a quarter period), so with the steady surrogate radius R_bar as the mean, R_max = R_bar + dR / 2.
  Parameter: the swing dR / r. A period is slow against the sinkage (seed 000: 6 peaks at a 20 mm/s rim
  speed), so the sinkage follows vertical equilibrium at each angle; the amplitude is the first harmonic at
  nu of the response over one period. The radius never falls below the rim's.
* ``constant``: the same amplitude in every run (one parameter): what a mechanism must beat.

:func:`explain_amplitudes` fits each to the measured amplitudes (least squares in log amplitude, so that
small and large oscillations count alike), compares them by BIC and by the error on held-out groups of runs
(fit on the others), and names a mechanism only when it beats the constant by :data:`BIC_MARGIN` and its
held-out gain exceeds twice its bootstrap standard error.
"""

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import minimize_scalar

from wheelsoil.errors import WheelsoilInputError

from .periodic import Run, dominant_component, explain_frequencies
from .terramechanics import RigidWheel, SoilParameters, contact_forces, effective_radius, predict

#: d gamma / gamma of the density wave (seed 002 sec. 4: "a value of gamma 0.10 was used for d gamma").
DENSITY_VARIATION = 0.10
#: Strong evidence (Kass & Raftery): the BIC advantage a mechanism needs over the constant amplitude.
BIC_MARGIN = 10.0
#: Angles per stiffness period at which the spoke-radius waveform is evaluated.
WAVEFORM_SAMPLES = 12
#: Largest radius swing dR / r the fit considers (seed 000 Table 3 reaches 2.2 at lunar gravity).
MAX_SWING = 3.0
#: Which amplitude mechanism goes with which frequency law of :mod:`.periodic`.
LAW_MECHANISM = {"slip_density_wave": "density_wave", "spoke_stiffness": "spoke_radius"}


@dataclass
class AmplitudeRun:
    """One run's conditions and the measured amplitude of its oscillation [units of the response]."""

    slip: float
    slip_angle: float  # [deg]
    load: float  # [N]
    gravity: float  # [m/s^2]
    amplitude: float
    group: str = ""  # runs held out together (e.g. one load)


def _conditions(runs) -> dict:
    return {k: np.array([getattr(r, k) for r in runs], float) for k in ("slip", "slip_angle", "load", "gravity")}


def density_wave_amplitudes(soil: SoilParameters, wheel: RigidWheel, cond: dict, k_a: float,
                            quantity: str = "drawbar_pull") -> np.ndarray:
    """Amplitude of ``quantity`` under seed 002's oscillating pressure A_gamma = l_c d gamma k'_a (eqs. 19, 24)."""
    steady = predict(soil, wheel, **cond)
    r = effective_radius(soil, wheel)
    l_c = r * (steady["theta_f"] - steady["theta_r"])
    a_gamma = l_c * DENSITY_VARIATION * soil.density * np.asarray(cond["gravity"], float) * k_a
    args = (steady["sinkage"], cond["slip"], cond["slip_angle"], cond["gravity"])
    base = contact_forces(soil, wheel, *args)[quantity]
    raised = contact_forces(soil, wheel, *args, extra_pressure=a_gamma)[quantity]
    return np.abs(raised - base)


def spoke_radius_scales(mean_scale: float, swing: float, phase) -> np.ndarray:
    """Surrogate radius / r at ``phase`` = nu theta_w (seed 000 eq. 19) for mean ``mean_scale`` and swing
    dR / r = ``swing``, floored at 1 (the rim)."""
    r_max = mean_scale + 0.5 * swing
    w = 1.0 - swing / (2.0 * r_max) * (1.0 + np.tanh(np.cos(np.asarray(phase, float))))
    return np.maximum(1.0, r_max * w)


def spoke_radius_waveform(soil: SoilParameters, wheel: RigidWheel, cond: dict, swing: float,
                          quantity: str = "drawbar_pull", samples: int = WAVEFORM_SAMPLES):
    """``quantity`` over one stiffness period: (phases nu theta_w [rad], values of shape (samples, runs)),
    with the sinkage in vertical equilibrium at each angle."""
    phase = 2.0 * np.pi * np.arange(samples) / samples
    scales = spoke_radius_scales(soil.radius_scale, swing, phase)
    values = np.array([np.ravel(predict(replace(soil, radius_scale=float(s)), wheel, **cond)[quantity])
                       for s in scales])
    return phase, values


def spoke_radius_amplitudes(soil: SoilParameters, wheel: RigidWheel, cond: dict, swing: float,
                            quantity: str = "drawbar_pull", samples: int = WAVEFORM_SAMPLES) -> np.ndarray:
    """Amplitude of the first harmonic (at nu theta_w) of ``quantity`` under seed 000 eq. 19's radius."""
    phase, values = spoke_radius_waveform(soil, wheel, cond, swing, quantity, samples)
    return np.abs(2.0 / samples * np.exp(-1j * phase) @ values)


# ------------------------------------------------------------------------------------- comparison
def _fit(model: str, soil, wheel, cond, amplitude, quantity) -> tuple[float, np.ndarray]:
    """(parameter, predicted amplitudes) of ``model`` fitted in log amplitude to ``amplitude``."""
    log_a = np.log(amplitude)
    if model == "constant":
        value = float(np.exp(np.mean(log_a)))
        return value, np.full(amplitude.shape, value)
    if model == "density_wave":  # linear in k'_a: the log fit is closed form
        unit = density_wave_amplitudes(soil, wheel, cond, 1.0, quantity)
        k_a = float(np.exp(np.mean(log_a - np.log(np.maximum(unit, 1e-300)))))
        return k_a, k_a * unit
    if model == "spoke_radius":
        def sse(swing):
            pred = spoke_radius_amplitudes(soil, wheel, cond, swing, quantity)
            return float(np.sum((np.log(np.maximum(pred, 1e-300)) - log_a) ** 2))

        best = minimize_scalar(sse, bounds=(1e-4, MAX_SWING), method="bounded", options={"xatol": 1e-3})
        swing = float(best.x)
        return swing, spoke_radius_amplitudes(soil, wheel, cond, swing, quantity)
    raise WheelsoilInputError(f"unknown amplitude model {model!r}; choose constant, density_wave or spoke_radius")


PARAMETER_NAMES = {"constant": "amplitude", "density_wave": "k_a", "spoke_radius": "radius_swing"}


def explain_amplitudes(runs: list, soil: SoilParameters, wheel: RigidWheel, *, quantity: str = "drawbar_pull",
                       spokes: int = 0, law: str | None = None, bootstrap: int = 400, seed: int = 0) -> dict:
    """Which mechanism explains the oscillation amplitudes of ``runs`` (:class:`AmplitudeRun`).

    ``soil`` is the calibrated steady model, ``spokes`` the wheel's stiffness peaks per turn (0: not a
    spoked wheel, so no ``spoke_radius``). With ``law`` (the frequency law :mod:`.periodic` named), only the
    mechanism that goes with it is a candidate (:data:`LAW_MECHANISM`). Runs are held out a group at a time
    (:attr:`AmplitudeRun.group`; every run its own group when none are given).

    Returns {"found": mechanism or None, "models": {name: {"parameter", "value", "bic", "rms_log_error",
    "held_out_rms_log_error", "gain", "gain_se", "predicted"}}, "measured": amplitudes, "runs": n}, with each
    model's fitted amplitudes in the order of ``measured``.
    """
    runs = [r for r in runs if np.isfinite(r.amplitude) and r.amplitude > 0]
    if len(runs) < 4:
        raise WheelsoilInputError(f"{len(runs)} runs with a measured amplitude; at least 4 are needed")
    cond = _conditions(runs)
    amplitude = np.array([r.amplitude for r in runs], float)
    groups = np.array([r.group or str(k) for k, r in enumerate(runs)])
    if len(set(groups)) < 2:
        groups = np.array([str(k) for k in range(len(runs))])
    candidates = ["density_wave"] + (["spoke_radius"] if spokes else [])
    if law is not None:
        candidates = [LAW_MECHANISM[law]] if LAW_MECHANISM.get(law) in candidates else []
    n = len(runs)
    out = {"found": None, "models": {}, "runs": n, "quantity": quantity, "candidates": candidates,
           "measured": amplitude.tolist()}
    held_sq = {}
    for model in ["constant"] + candidates:
        value, pred = _fit(model, soil, wheel, cond, amplitude, quantity)
        resid = np.log(np.maximum(pred, 1e-300)) - np.log(amplitude)
        held = np.empty(n)
        for g in np.unique(groups):
            test = groups == g
            train = ~test
            sub = {k: v[train] for k, v in cond.items()}
            v_train, _ = _fit(model, soil, wheel, sub, amplitude[train], quantity)
            test_cond = {k: v[test] for k, v in cond.items()}
            if model == "constant":
                p_test = np.full(int(test.sum()), v_train)
            elif model == "density_wave":
                p_test = density_wave_amplitudes(soil, wheel, test_cond, v_train, quantity)
            else:
                p_test = spoke_radius_amplitudes(soil, wheel, test_cond, v_train, quantity)
            held[test] = np.log(np.maximum(p_test, 1e-300)) - np.log(amplitude[test])
        held_sq[model] = held ** 2
        out["models"][model] = {
            "parameter": PARAMETER_NAMES[model], "value": value,
            "rms_log_error": float(np.sqrt(np.mean(resid ** 2))),
            "bic": float(n * np.log(max(np.mean(resid ** 2), 1e-300)) + np.log(n)),
            "held_out_rms_log_error": float(np.sqrt(np.mean(held ** 2))),
            "predicted": np.asarray(pred, float).tolist(),
        }
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, n, size=(bootstrap, n))
    base = out["models"]["constant"]
    for model in candidates:
        diff = np.sqrt(held_sq["constant"][idx].mean(axis=1)) - np.sqrt(held_sq[model][idx].mean(axis=1))
        m = out["models"][model]
        m["gain"] = base["held_out_rms_log_error"] - m["held_out_rms_log_error"]
        m["gain_se"] = float(np.std(diff))
    if candidates:
        best = min(candidates, key=lambda k: out["models"][k]["bic"])
        m = out["models"][best]
        if m["bic"] < base["bic"] - BIC_MARGIN and m["gain"] > 2.0 * m["gain_se"]:
            others = [k for k in candidates if k != best]
            if all(out["models"][k]["bic"] > m["bic"] + BIC_MARGIN for k in others):
                out["found"] = best
            else:
                out["note"] = f"{best} and {', '.join(others)} explain the amplitudes about equally well"
    return out


# --------------------------------------------------------------------------- from time series to a cause
@dataclass
class SeriesRecord:
    """One run's time series of a response, with the run's conditions and wheel speed omega [rad/s]."""

    t: np.ndarray  # [s]
    y: np.ndarray
    omega: float
    slip: float
    slip_angle: float
    load: float
    gravity: float
    group: str = ""


def oscillation_findings(records: list, soil: SoilParameters, wheel: RigidWheel, *, quantity: str = "drawbar_pull",
                         grousers: int = 0, spokes: int = 0, noise: str = "red") -> dict:
    """The whole chain for periodic effects: the dominant component of every record (:mod:`.periodic`, tested
    against ``noise``), the law its frequency follows across runs, and -- when that law has an amplitude
    mechanism (:data:`LAW_MECHANISM`) -- which mechanism explains the amplitudes, with its parameter and its
    held-out gain (:func:`explain_amplitudes` on the significant runs).

    Returns {"components": [...], "frequency": explain_frequencies(...), "amplitude": explain_amplitudes(...) or
    None, "found": mechanism or None}.
    """
    comps = [dominant_component(r.t, r.y, noise=noise) for r in records]
    freq = explain_frequencies([Run(r.omega, r.slip, c) for r, c in zip(records, comps)],
                               grousers=grousers, spokes=spokes)
    out = {"components": comps, "frequency": freq, "amplitude": None, "found": None}
    law = freq["found"]
    if law in LAW_MECHANISM:
        runs = [AmplitudeRun(r.slip, r.slip_angle, r.load, r.gravity, c.amplitude, r.group)
                for r, c in zip(records, comps) if c.significant]
        if len(runs) >= 4:
            out["amplitude"] = explain_amplitudes(runs, soil, wheel, quantity=quantity, spokes=spokes, law=law)
            out["found"] = out["amplitude"]["found"]
    return out
