"""Calibrate the classical model, find what it gets wrong, name the mechanism, measure the gain.

Workflow (architecture, validation): measurements -> baseline fit on training conditions -> residual
diagnostics against each condition variable -> for every candidate :class:`~.extensions.Extension` the data
can show, a fit of the baseline plus that mechanism on the same training conditions -> error on the held-out
conditions with and without it, bootstrap uncertainty of the gain, and the Bayesian information criterion
on the training fit -> the mechanism found (or none).

A mechanism is *found* when its fit lowers BIC by more than :data:`BIC_MARGIN` (strong evidence, Kass &
Raftery 1995) and its held-out gain is positive beyond :data:`GAIN_SIGMAS` bootstrap standard deviations;
among several, the largest held-out gain wins. Residuals are normalised per response by a scale (the
measured spread, or the measurement standard deviation where the data give one) so that forces and
sinkage weigh alike.
"""

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import least_squares
from scipy.stats import spearmanr

from wheelsoil.errors import WheelsoilInputError

from .extensions import BASELINE_FREE, BASELINE_OFF, EXTENSIONS, Extension, Parameter
from .measured import Measurements
from .terramechanics import RigidWheel, SoilParameters, predict

BIC_MARGIN = 10.0
GAIN_SIGMAS = 2.0
RESPONSES = ("drawbar_pull", "lateral_force", "sinkage", "torque")
CONDITIONS = ("slip", "slip_angle", "load", "gravity", "passes", "grouser_height")


def model_responses(soil: SoilParameters, data: Measurements) -> dict[str, np.ndarray]:
    """The model's drawbar pull, lateral force, sinkage and torque at every measured condition."""
    out = {q: np.full(len(data), np.nan) for q in RESPONSES}
    wheels = np.stack([data.radius, data.width, data.grouser_height, data.grouser_count], axis=1)
    for key in np.unique(wheels, axis=0):
        rows = np.all(wheels == key, axis=1)
        wheel = RigidWheel(radius=key[0], width=key[1], grouser_height=key[2], grouser_count=int(key[3]))
        pred = predict(soil, wheel, slip=data.slip[rows], slip_angle=data.slip_angle[rows], load=data.load[rows],
                       gravity=data.gravity[rows], passes=data.passes[rows])
        for q in RESPONSES:
            out[q][rows] = pred[q]
    return out


def response_scales(data: Measurements, responses) -> dict[str, float]:
    """Per-response normalisation [response units]: the spread of the measured values."""
    scales = {}
    for q in responses:
        y = data.responses[q]
        y = y[np.isfinite(y)]
        spread = float(np.std(y)) if y.size > 1 else 0.0
        scales[q] = spread if spread > 0 else max(float(np.max(np.abs(y))) if y.size else 1.0, 1e-12)
    return scales


@dataclass
class Fit:
    """One calibration: the fitted soil, its free parameters and its training residuals."""

    soil: SoilParameters
    free: dict[str, float]
    residuals: np.ndarray
    success: bool
    message: str = ""

    @property
    def n(self) -> int:
        return int(self.residuals.size)

    @property
    def k(self) -> int:
        return len(self.free)

    @property
    def sse(self) -> float:
        return float(np.sum(self.residuals ** 2))

    @property
    def rmse(self) -> float:
        return float(np.sqrt(self.sse / max(self.n, 1)))

    @property
    def bic(self) -> float:
        return self.n * np.log(max(self.sse, 1e-300) / self.n) + self.k * np.log(self.n)


def normalised_residuals(soil, data, responses, scales) -> np.ndarray:
    pred = model_responses(soil, data)
    parts = []
    for q in responses:
        y = data.responses[q]
        ok = np.isfinite(y)
        parts.append((pred[q][ok] - y[ok]) / scales[q])
    return np.concatenate(parts) if parts else np.zeros(0)


def calibrate(data: Measurements, start: SoilParameters, free: tuple[Parameter, ...], *, responses, scales,
              max_evaluations: int = 400) -> Fit:
    """Least-squares fit of ``free`` (bounded, log-transformed where marked) from ``start``."""
    names = [p.name for p in free]

    def soil_of(x):
        values = {p.name: p.from_fit(v) for p, v in zip(free, x)}
        if "shear_modulus_x" in values and "shear_modulus_y" not in values:
            values["shear_modulus_y"] = values["shear_modulus_x"]
        return replace(start, **values)

    def residual(x):
        try:
            return normalised_residuals(soil_of(x), data, responses, scales)
        except WheelsoilInputError:  # a combination outside the model's domain (e.g. a1 + a2 > 1)
            return np.full(n_res, 1e3)

    n_res = normalised_residuals(start, data, responses, scales).size
    lo, hi = np.array([p.fit_bounds for p in free]).T
    x0 = np.clip([p.to_fit(getattr(start, p.name)) for p in free], lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
    sol = least_squares(residual, x0, bounds=(lo, hi), x_scale="jac", max_nfev=max_evaluations, diff_step=1e-4)
    soil = soil_of(sol.x)
    return Fit(soil, {n: getattr(soil, n) for n in names}, residual(sol.x), bool(sol.success), sol.message)


def holdout_mask(data: Measurements, *, fraction: float = 0.3, by: str | None = None, level=None,
                 seed: int = 0) -> np.ndarray:
    """Held-out rows: the rows where condition ``by`` equals ``level`` (leave one level out), or a random
    ``fraction`` of the rows (seeded)."""
    if by is not None:
        values = getattr(data, by)
        mask = np.isclose(values, level) if np.issubdtype(np.asarray(values).dtype, np.number) else values == level
        if not mask.any() or mask.all():
            raise WheelsoilInputError(f"holding out {by} = {level!r} leaves no training or no held-out rows")
        return mask
    rng = np.random.default_rng(seed)
    mask = np.zeros(len(data), bool)
    mask[rng.choice(len(data), size=max(1, int(round(fraction * len(data)))), replace=False)] = True
    return mask


def residual_trends(soil, data, responses, scales) -> list[dict]:
    """Spearman rank correlation of each response's residual with each condition variable that varies."""
    pred = model_responses(soil, data)
    rows = []
    for q in responses:
        y = data.responses[q]
        ok = np.isfinite(y)
        res = (pred[q] - y) / scales[q]
        for c in CONDITIONS:
            x = np.asarray(getattr(data, c), float)
            if ok.sum() < 4 or np.ptp(x[ok]) == 0:
                continue
            rho, p = spearmanr(x[ok], res[ok])
            rows.append({"response": q, "condition": c, "spearman": float(rho), "p_value": float(p)})
    return sorted(rows, key=lambda r: r["p_value"])


@dataclass
class Candidate:
    """An extension's evidence: training fit, held-out error, bootstrap gain over the baseline, BIC."""

    extension: Extension
    fit: Fit
    heldout_rmse: float
    gain: float  # baseline held-out RMSE - extended held-out RMSE (normalised units)
    gain_std: float
    delta_bic: float
    effect: float  # RMS of the normalised responses the mechanism adds to the fitted model

    @property
    def found(self) -> bool:
        return bool(self.delta_bic < -BIC_MARGIN and self.gain > GAIN_SIGMAS * self.gain_std and self.gain > 0)

    def to_dict(self) -> dict:
        return {"name": self.extension.name, "mechanism": self.extension.mechanism, "source": self.extension.source,
                "parameters": {p.name: self.fit.free[p.name] for p in self.extension.parameters},
                "train_rmse": self.fit.rmse, "heldout_rmse": self.heldout_rmse, "gain": self.gain,
                "gain_std": self.gain_std, "delta_bic": self.delta_bic, "effect": self.effect, "found": self.found}


@dataclass
class Discovery:
    """What the workflow found: the baseline, every candidate ranked, and the mechanism found (or None)."""

    baseline: Fit
    baseline_heldout_rmse: float
    candidates: list[Candidate]
    trends: list[dict]
    responses: tuple
    scales: dict
    n_train: int
    n_heldout: int
    skipped: dict = field(default_factory=dict)

    @property
    def found(self) -> Candidate | None:
        hits = [c for c in self.candidates if c.found]
        return max(hits, key=lambda c: c.gain) if hits else None

    def to_dict(self) -> dict:
        f = self.found
        return {
            "responses": list(self.responses), "scales": self.scales, "n_train": self.n_train,
            "n_heldout": self.n_heldout,
            "baseline": {"parameters": self.baseline.free, "train_rmse": self.baseline.rmse,
                         "heldout_rmse": self.baseline_heldout_rmse},
            "candidates": [c.to_dict() for c in self.candidates],
            "found": f.to_dict() if f else None,
            "residual_trends": self.trends[:12],
            "not_applicable": self.skipped,
        }


def mechanism_effect(soil: SoilParameters, extension: Extension, data: Measurements, responses, scales) -> float:
    """RMS over conditions and responses of what ``extension`` adds to the model ``soil`` (normalised).

    Scale-type parameters (sidewall, grouser) multiply formulas that also hold cohesion and friction, so a
    fit may trade the scale against them; the mechanism's contribution to the responses is what the data
    fix, and what this measures.
    """
    on = model_responses(soil, data)
    off = model_responses(replace(soil, **extension.off), data)
    parts = [(on[q] - off[q]) / scales[q] for q in responses]
    return float(np.sqrt(np.mean(np.concatenate(parts) ** 2)))


def _best_extended(train, baseline: SoilParameters, start: SoilParameters, ext: Extension, responses, scales) -> Fit:
    """Baseline plus ``ext`` fitted from the baseline fit, and from the baseline fit with the cohesion of
    ``start`` and the extension's parameters mid-range: a baseline fit can park a parameter where the
    mechanism has no gradient (cohesion 0 for a gravity-scaled cohesion)."""
    free = BASELINE_FREE + ext.parameters
    mid = {p.name: p.from_fit(0.5 * sum(p.fit_bounds)) for p in ext.parameters}
    starts = [baseline, replace(baseline, cohesion=max(baseline.cohesion, start.cohesion), **mid)]
    fits = [calibrate(train, s, free, responses=responses, scales=scales) for s in starts]
    return min(fits, key=lambda f: f.sse)


def _best_baseline(train, start, responses, scales) -> Fit:
    """The baseline from the given start and from two generic dry-sand starts; the lowest error wins
    (the classical model's error surface has flat valleys, e.g. in theta_m / theta_f)."""
    starts = [start, replace(start, a1=0.35, n0=1.0, shear_modulus_x=0.02, shear_modulus_y=0.02),
              replace(start, a1=0.2, n0=0.8, friction_angle=30.0, cohesion=100.0, kphi_prime=500.0)]
    fits = [calibrate(train, s, BASELINE_FREE, responses=responses, scales=scales) for s in starts]
    return min(fits, key=lambda f: f.sse)


def discover(data: Measurements, *, start: SoilParameters | None = None, responses=None, heldout=None,
             candidates=None, bootstrap: int = 400, seed: int = 0) -> Discovery:
    """Run the workflow on ``data`` (see the module docstring).

    start: parameters to start from; the baseline's extension parameters are switched off
        (:data:`~.extensions.BASELINE_OFF`). responses: which measured responses to fit (default: those
        with data). heldout: boolean mask of held-out rows (default: a seeded random 30 %). candidates:
        extension names to try (default: all that the data can show).
    """
    if len(data) < 8:
        raise WheelsoilInputError(f"{data.name}: {len(data)} measurements are too few to calibrate and hold out")
    responses = tuple(responses or [q for q in RESPONSES if np.isfinite(data.responses.get(q, np.nan * data.slip)).any()])
    unknown = [q for q in responses if q not in RESPONSES]
    if unknown:
        raise WheelsoilInputError(f"unknown response(s) {unknown}; choose from {list(RESPONSES)}")
    heldout = holdout_mask(data, seed=seed) if heldout is None else np.asarray(heldout, bool)
    train, test = data.select(~heldout), data.select(heldout)
    scales = response_scales(data, responses)
    base_start = replace(start or SoilParameters(), **BASELINE_OFF)
    baseline = _best_baseline(train, base_start, responses, scales)
    base_err = normalised_residuals(baseline.soil, test, responses, scales)
    base_rmse = float(np.sqrt(np.mean(base_err ** 2)))

    names = list(candidates or EXTENSIONS)
    skipped = {n: "the data cannot show it" for n in names if not EXTENSIONS[n].applies(data)}
    rng = np.random.default_rng(seed)
    results = []
    for name in names:
        if name in skipped:
            continue
        ext = EXTENSIONS[name]
        fit = _best_extended(train, baseline.soil, base_start, ext, responses, scales)
        err = normalised_residuals(fit.soil, test, responses, scales)
        rmse = float(np.sqrt(np.mean(err ** 2)))
        # bootstrap over held-out residuals (paired): the spread of the RMSE difference
        idx = rng.integers(0, err.size, size=(bootstrap, err.size))
        diffs = np.sqrt(np.mean(base_err[idx] ** 2, axis=1)) - np.sqrt(np.mean(err[idx] ** 2, axis=1))
        results.append(Candidate(ext, fit, rmse, base_rmse - rmse, float(np.std(diffs)), fit.bic - baseline.bic,
                                 mechanism_effect(fit.soil, ext, data, responses, scales)))
    results.sort(key=lambda c: -c.gain)
    trends = residual_trends(baseline.soil, train, responses, scales)
    return Discovery(baseline, base_rmse, results, trends, responses, scales, len(train), len(test), skipped)
