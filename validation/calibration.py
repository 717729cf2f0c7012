"""Calibrate the semi-empirical model on measurements: normalised residuals, a bounded least-squares fit, and
what the data can and cannot tell about each parameter.

Residuals are normalised per response by a scale (the spread of the training data's measured values) so that
forces and sinkage weigh alike. A fit's parameters are judged two ways:

* **at a bound**: the fit pushed the parameter to the edge of its physical range (:meth:`Parameter.at_bound`);
  the misfit it addresses may be larger than the range allows, or the data want a value outside it. The bound
  *binds* when the data push against it (:meth:`Fit.binding_bounds`); where the parameter's effect saturates the
  bound does not bind and the data give a one-sided estimate only.
* **unidentified**: the data hardly constrain it. The choice here is the Fisher information of the
  least-squares problem, F = J^T J / s^2 with J the Jacobian of the normalised residuals in the fit's own
  coordinates (log for scale parameters) and s^2 = SSE / (n - k) the residual variance; its inverse is the
  asymptotic covariance (Bates & Watts 1988, ch. 2). A parameter whose standard error exceeds a quarter of its
  fit range (:data:`UNIDENTIFIED_RANGE_FRACTION`) has a +-2 sigma interval that spans its whole range: the data
  do not inform it. Fisher rather than profile likelihood because the Jacobian comes with the fit at no extra
  cost, where a profile needs a refit per point per parameter (minutes per dataset); where the two disagree
  (strongly curved valleys) Fisher errs towards calling a parameter identified.
"""

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import least_squares

from wheelsoil.errors import WheelsoilInputError

from .extensions import BASELINE_FREE, Parameter
from .fit_jacobian import conditions_of, forward_steps, model_jacobian, wheel_of
from .measured import Measurements
from .sinkage_solve import SinkageWarmStart
from .terramechanics import SoilParameters, predict

RESPONSES = ("drawbar_pull", "lateral_force", "sinkage", "torque")
#: A parameter whose Fisher standard error exceeds this fraction of its fit range is reported unidentified.
UNIDENTIFIED_RANGE_FRACTION = 0.25
#: A bound binds when moving past it would lower the SSE by more than this many residual variances (2 sigma).
BINDING_CHI2 = 4.0
#: The fit's parameter step for the Jacobian, relative (scipy's ``diff_step``; :mod:`.fit_jacobian`).
DIFF_STEP = 1e-4
#: Every residual of a soil outside the model's domain (e.g. a1 + a2 > 1): a cost no fit accepts.
OUTSIDE_RESIDUAL = 1e3


@dataclass
class WarmStarts:
    """The sinkage solves' warm starts over one set of measurements, one per wheel in it (a fit's successive
    evaluations start each wheel's solve from its last roots; :mod:`~wheelsoil.validation.sinkage_solve`)."""

    by_wheel: dict[tuple, SinkageWarmStart] = field(default_factory=dict)
    #: The data's rows by wheel (:func:`wheel_rows`), found on the first call.
    rows_by_wheel: list[tuple[np.ndarray, np.ndarray]] | None = None

    def for_wheel(self, key) -> SinkageWarmStart:
        return self.by_wheel.setdefault(tuple(float(v) for v in key), SinkageWarmStart())


def wheel_rows(data: Measurements) -> list[tuple[np.ndarray, np.ndarray]]:
    """(radius, width, grouser height, grouser count) of each distinct wheel in ``data`` and the mask of its rows."""
    wheels = np.stack([data.radius, data.width, data.grouser_height, data.grouser_count], axis=1)
    return [(key, np.all(wheels == key, axis=1)) for key in np.unique(wheels, axis=0)]


def wheel_predictions(soil: SoilParameters, data: Measurements, warm: WarmStarts | None = None) -> list:
    """:func:`~.terramechanics.predict` for each wheel of ``data``: (wheel key, row mask, prediction) per wheel
    (``warm`` as :func:`model_responses`)."""
    if warm is None:
        groups = wheel_rows(data)
    else:
        if warm.rows_by_wheel is None:
            warm.rows_by_wheel = wheel_rows(data)
        groups = warm.rows_by_wheel
    return [(key, rows, predict(soil, wheel_of(key), **conditions_of(data, rows),
                                warm_start=None if warm is None else warm.for_wheel(key)))
            for key, rows in groups]


def model_responses(soil: SoilParameters, data: Measurements, warm: WarmStarts | None = None) -> dict[str, np.ndarray]:
    """The model's drawbar pull, lateral force, sinkage and torque at every measured condition (``warm``: start
    the sinkage solves from the roots of the last call given the same object and data, whose rows by wheel it
    keeps)."""
    return responses_of(wheel_predictions(soil, data, warm), len(data))


def responses_of(predictions: list, count: int) -> dict[str, np.ndarray]:
    """The responses of :func:`wheel_predictions`' output by row (``count`` rows)."""
    out = {q: np.full(count, np.nan) for q in RESPONSES}
    for _, rows, pred in predictions:
        for q in RESPONSES:
            out[q][rows] = pred[q]
    return out


def response_scales(data: Measurements, responses) -> dict[str, float]:
    """Per-response normalisation [response units]: the spread of the measured values of ``data`` (pass the
    training set: the held-out or test data must not set the scale they are judged on)."""
    scales = {}
    for q in responses:
        y = data.responses[q]
        y = y[np.isfinite(y)]
        spread = float(np.std(y)) if y.size > 1 else 0.0
        scales[q] = spread if spread > 0 else max(float(np.max(np.abs(y))) if y.size else 1.0, 1e-12)
    return scales


def normalised_residuals(soil, data, responses, scales, *, split: bool = False, warm: WarmStarts | None = None):
    """(model - measured) / scale over the measured values of each response, concatenated (or a dict by
    response with ``split``); ``warm`` as :func:`model_responses`."""
    return residuals_of(model_responses(soil, data, warm), data, responses, scales, split=split)


def residuals_of(model: dict[str, np.ndarray], data: Measurements, responses, scales, *, split: bool = False):
    """:func:`normalised_residuals` of the model's responses by row ``model``; a response's rows may carry a trailing
    axis (its derivatives, which stack the same way: the Jacobian's rows)."""
    parts = {}
    for q in responses:
        y = data.responses[q]
        ok = np.isfinite(y)
        values = model[q][ok]
        parts[q] = ((values - y[ok]) if values.ndim == 1 else values) / scales[q]
    if split:
        return parts
    return np.concatenate(list(parts.values())) if parts else np.zeros(0)


@dataclass
class Fit:
    """One calibration: the fitted soil, its free parameters, the training residuals and the Jacobian of the
    residuals in fit coordinates (for the Fisher information)."""

    soil: SoilParameters
    free: dict[str, float]
    residuals: np.ndarray
    success: bool
    message: str = ""
    parameters: tuple[Parameter, ...] = ()
    jacobian: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)), repr=False)

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

    def standard_errors(self) -> dict[str, float]:
        """Fisher standard error of each free parameter in fit coordinates (log for log parameters).

        The information matrix is inverted in range-scaled coordinates (each parameter's fit range = 1) through
        its eigen-decomposition, with eigenvalues floored at 1e-14 of the largest instead of dropped: a direction
        the data do not inform then shows as a huge variance (a pseudo-inverse would discard it and report the
        parameters along it as well determined)."""
        if self.jacobian.size == 0:
            return {p.name: float("nan") for p in self.parameters}
        width = np.array([p.fit_bounds[1] - p.fit_bounds[0] for p in self.parameters])
        js = self.jacobian * width[None, :]
        s2 = self.sse / max(self.n - self.k, 1)
        lam, vec = np.linalg.eigh(js.T @ js)
        lam = np.maximum(lam, 1e-14 * max(float(lam.max()), 1e-300))
        var = s2 * (vec ** 2 / lam[None, :]).sum(axis=1)
        return {p.name: float(np.sqrt(v) * w) for p, v, w in zip(self.parameters, var, width)}

    def at_bounds(self) -> dict[str, str]:
        """Free parameters the fit pushed to a bound: name -> "lower" / "upper"."""
        out = {}
        for p in self.parameters:
            side = p.at_bound(self.free[p.name])
            if side:
                out[p.name] = side
        return out

    def binding_bounds(self) -> dict[str, str]:
        """Parameters at a bound that the data push against: moving the parameter alone past the bound would
        lower the SSE by more than :data:`BINDING_CHI2` residual variances (one Gauss-Newton step from the
        gradient J^T r and curvature J^T J of the normalised residuals). A parameter whose effect saturates (a
        flat profile towards the bound, e.g. c (g / g0)^kappa at low gravity for large kappa) sits at a bound
        that does not bind: the data give it a one-sided estimate only."""
        out = {}
        if self.jacobian.size == 0:
            return dict(self.at_bounds())
        s2 = self.sse / max(self.n - self.k, 1)
        index = {p.name: j for j, p in enumerate(self.parameters)}
        for name, side in self.at_bounds().items():
            col = self.jacobian[:, index[name]]
            grad, curv = float(col @ self.residuals), float(col @ col)
            outward = 1.0 if side == "upper" else -1.0
            gain = grad * grad / curv if curv > 0 else 0.0
            if grad * outward < 0 and gain > BINDING_CHI2 * s2:
                out[name] = side
        return out

    def unidentified(self) -> dict[str, float]:
        """Free parameters the data do not inform: name -> standard error / fit range (> 0.25)."""
        out = {}
        for p, se in zip(self.parameters, self.standard_errors().values()):
            lo, hi = p.fit_bounds
            ratio = se / (hi - lo) if np.isfinite(se) else float("inf")
            if ratio > UNIDENTIFIED_RANGE_FRACTION:
                out[p.name] = float(ratio)
        return out

    def parameter_table(self) -> list[dict]:
        """Every free parameter: value, unit, bounds, standard error (in the parameter's units, linearised
        from the fit coordinates), at-bound side and whether the data identify it."""
        se = self.standard_errors()
        bounds, binding, unident = self.at_bounds(), self.binding_bounds(), self.unidentified()
        rows = []
        for p in self.parameters:
            v = self.free[p.name]
            err = se[p.name] * (v if p.log else 1.0)  # d value = value d log(value)
            rows.append({"name": p.name, "value": v, "unit": p.unit, "lower": p.lower, "upper": p.upper,
                         "std_error": err, "at_bound": bounds.get(p.name), "bound_binds": p.name in binding,
                         "identified": p.name not in unident})
        return rows


#: How a fit's Jacobian is formed: through the sinkage (:mod:`.fit_jacobian`, the default) or by scipy's forward
#: differences of the whole prediction (as before 2026-11-29; kept to measure the two against each other).
JACOBIANS = ("implicit", "difference")


def calibrate(data: Measurements, start: SoilParameters, free: tuple[Parameter, ...], *, responses, scales,
              max_evaluations: int = 400, jacobian: str = "implicit") -> Fit:
    """Least-squares fit of ``free`` (bounded, log-transformed where marked) from ``start``; ``jacobian`` one of
    :data:`JACOBIANS`."""
    if jacobian not in JACOBIANS:
        raise WheelsoilInputError(f"jacobian = {jacobian!r}: allowed {list(JACOBIANS)}")
    names = [p.name for p in free]

    def soil_of(x):
        values = {p.name: p.from_fit(v) for p, v in zip(free, x)}
        if "shear_modulus_x" in values and "shear_modulus_y" not in values:
            values["shear_modulus_y"] = values["shear_modulus_x"]
        return replace(start, **values)

    warm = WarmStarts()  # each evaluation starts its sinkage solves from the last one's roots
    last: dict = {}  # the last evaluation: coordinates, residuals, predictions by wheel (None outside the domain)

    def residual(x):
        last["x"], last["predictions"] = np.array(x, float), None
        try:
            last["predictions"] = wheel_predictions(soil_of(x), data, warm)
            last["residuals"] = residuals_of(responses_of(last["predictions"], len(data)), data, responses, scales)
        except WheelsoilInputError:  # a combination outside the model's domain (e.g. a1 + a2 > 1)
            last["residuals"] = np.full(n_res, OUTSIDE_RESIDUAL)
        return last["residuals"]

    def jacobian_through_sinkage(x):
        """Through the sinkage (:mod:`.fit_jacobian`), with scipy's two-point steps."""
        x = np.asarray(x, float)
        if "x" not in last or not np.array_equal(last["x"], x):
            residual(x)
        r0 = last["residuals"]
        steps = forward_steps(x, lo, hi, DIFF_STEP)
        if last["predictions"] is None:  # outside the domain at x itself: plain forward differences
            return np.stack([(residual(x + steps[k] * np.eye(x.size)[k]) - r0) / steps[k] for k in range(x.size)],
                            axis=1)
        derivative, invalid = model_jacobian(soil_of, x, steps, data, last["predictions"])
        jac = residuals_of(derivative, data, responses, scales)
        jac[:, invalid] = (OUTSIDE_RESIDUAL - r0[:, None]) / steps[invalid]  # what a difference would see
        return jac

    n_res = normalised_residuals(start, data, responses, scales).size
    lo, hi = np.array([p.fit_bounds for p in free]).T
    x0 = np.clip([p.to_fit(getattr(start, p.name)) for p in free], lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
    jac = jacobian_through_sinkage if jacobian == "implicit" else "2-point"
    sol = least_squares(residual, x0, jac=jac, bounds=(lo, hi), x_scale="jac", max_nfev=max_evaluations,
                        diff_step=DIFF_STEP)
    soil = soil_of(sol.x)
    return Fit(soil, {n: getattr(soil, n) for n in names}, residual(sol.x), bool(sol.success), sol.message,
               tuple(free), np.asarray(sol.jac, float))


def calibrate_baseline(train: Measurements, start: SoilParameters, responses, scales,
                       free: tuple[Parameter, ...] = BASELINE_FREE) -> Fit:
    """The model from the given start and from two generic dry-sand starts; the lowest error wins (the
    classical model's error surface has flat valleys, e.g. in theta_m / theta_f)."""
    starts = [start, replace(start, a1=0.35, n0=1.0, shear_modulus_x=0.02, shear_modulus_y=0.02),
              replace(start, a1=0.2, n0=0.8, friction_angle=30.0, cohesion=100.0, kphi_prime=500.0, kc_prime=20.0)]
    fits = [calibrate(train, s, free, responses=responses, scales=scales) for s in starts]
    return min(fits, key=lambda f: f.sse)
