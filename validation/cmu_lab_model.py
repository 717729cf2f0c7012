"""The CMU lab's own 3-D terramechanics model, ported as it is: the rival wheelsoil's validation is held against.

Source: robomechanics/3d-terramechanics, ``terramechanics/*.m`` (Copyright 2022 Catherine Pavlov, Carnegie Mellon
University, MIT licence), the model behind the CMU trials in ``../shared/data/measured/cmu_3d_terramechanics``, run
as ``generate_paper_plots.m`` runs it without the trench model and without Ishigami's sidewall (``run_model(wheel,
..., 0, 0, ...)``: the variant whose files are complete; ``trench_profile.m`` is not in the repository). Its
parameters, hand tuned by the lab on these trials, are :mod:`wheelsoil.parameters.cmu_lab_model`.

What it adds to wheelsoil's classical model (:mod:`.terramechanics`), each as its file has it:

* kinematics in velocity components (``update_thetas.m``, ``v_jt.m``): carriage speed V = |(v_x, v_y)|, rim speed
  r_s omega; the wheel *slips* when r_s omega >= V (s = (r_s omega - V) / (r_s omega)) and *skids* otherwise;
* stress angles tuned per steering angle (``update_thetas.m``): slipping, theta_m = theta_f (a0 + a1 s) and
  theta_r = theta_f (b0 + b1 s); skidding, both fixed at their values at slip 0 (found at the load of the trials at
  a rim speed of 8 mm/s, ``run_model.m``); theta_f = acos(1 - h / r_s);
* a slip-dependent sinkage exponent (``sigma.m``): N = n0 + n1 s slipping, n0 - n2 s' skidding
  (s' = (r_s omega - V) / V), and the normal stress k (r (cos theta - cos theta_f))^N mixed between the rim's radius
  and the grouser tips' in the tips' area ratio mu, with Wong--Reece's rear profile through theta_m;
* the skidding wheel's soil-flow transition angle theta_0 = theta_f + s' (theta_f - theta_f / 2) and its shear
  displacement and slip velocity on either side (``j_t.m``, ``v_jt.m``);
* one shear strength (c + sigma tan phi)(1 - exp(-|j| / K)), |j| the resultant of the tangential and lateral
  displacements, shared between the directions as the slip velocity is (``tau_t.m``, ``tau_l.m``); phi is the
  angle of repose;
* side bulldozing on the leading side face (``R_b.m``, Wong 2008): R_b = (gamma h_b^2 cot^2 X_c (1 + cot X_c tan
  phi / 2) / 2 + 2 h_b c cot X_c) |sin beta|, X_c = 45 deg - phi / 2, entering the lateral force as
  r_s cos theta R_b sin beta (``forces.m``);
* the forces as the right-point sums over 101 angles from theta_r to theta_f (``forces.m``) and the sinkage by
  bisection on the vertical force to 0.1 % of the load (``find_sinkage.m``).

Inside, the signs are the lab's (``average_data_to_model.m``: drawbar pull forward, lateral force positive at
positive steering, as the dataset's files hold them); :func:`predict_trials` returns the lateral force in
wheelsoil's frame, negated as :func:`~.measured.load_cmu_file` negates the measured one.
The lab's file ``j_t.m`` takes the rim radius r where the others take r_s
(its condition r omega >= V and its displacement); kept as it is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.parameters import cmu_lab_model as params


@dataclass(frozen=True)
class LabWheel:
    """radius r, width b, grouser height h_g [m]; tip_area_ratio mu [-]."""

    radius: float
    width: float
    grouser_height: float
    tip_area_ratio: float

    @property
    def shear_radius(self) -> float:
        """r_s = r + h_g [m] (``set_rover_params.m``)."""
        return self.radius + self.grouser_height


@dataclass(frozen=True)
class LabSoil:
    """sinkage_modulus k [N/m^(n+2)], specific_weight gamma [N/m^3], friction_angle phi [deg], cohesion c [Pa],
    shear_modulus K [m], sinkage exponent constants n0, n1, n2 [-]."""

    sinkage_modulus: float
    specific_weight: float
    friction_angle: float
    cohesion: float
    shear_modulus: float
    n0: float
    n1: float
    n2: float

    @property
    def phi(self) -> float:
        return np.radians(self.friction_angle)

    @property
    def destructive_angle(self) -> float:
        """X_c = 45 deg - phi / 2 [rad] (``set_soil_params.m``, Wong 2008)."""
        return np.pi / 4 - self.phi / 2


@dataclass(frozen=True)
class LabState:
    """The wheel's motion: carriage velocity in the wheel frame v_x, v_y [m/s] (v_y = -V sin beta, as
    ``run_model.m`` sets it), angular speed omega [rad/s], steering angle beta [rad]; the stress-angle constants
    (a0, a1, b0, b1) and the skidding wheel's fixed theta_m0, theta_r0 [rad]."""

    v_x: float
    v_y: float
    omega: float
    beta: float
    tuned: tuple
    theta_m0: float = np.nan
    theta_r0: float = np.nan

    @property
    def speed(self) -> float:
        return float(np.hypot(self.v_x, self.v_y))


@dataclass(frozen=True)
class Angles:
    """theta_f, theta_r, theta_m, theta_0 [rad] at one sinkage."""

    front: float
    rear: float
    max_stress: float
    transition: float


def _slipping(wheel: LabWheel, state: LabState) -> bool:
    return state.omega * wheel.shear_radius >= state.speed


def stress_angles(h: float, wheel: LabWheel, state: LabState) -> Angles:
    """``update_thetas.m`` (trench model off) at sinkage ``h`` [m]."""
    rs, V, w = wheel.shear_radius, state.speed, state.omega
    a0, a1, b0, b1 = state.tuned
    front = float(np.arccos(1.0 - h / rs))
    if _slipping(wheel, state):
        s = (w * rs - V) / (w * rs)
        rear, peak = front * (b0 + b1 * s), front * (a0 + a1 * s)
    else:
        rear, peak = state.theta_r0, state.theta_m0
    transition = front + (w * rs - V) / V * (front - front / 2.0)
    return Angles(front, rear, peak, transition)


def sinkage_exponent(soil: LabSoil, wheel: LabWheel, state: LabState) -> float:
    """N of ``sigma.m``: n0 + n1 s slipping, n0 - n2 s' skidding."""
    rs, V, w = wheel.shear_radius, state.speed, state.omega
    if _slipping(wheel, state):
        return soil.n0 + soil.n1 * (w * rs - V) / (w * rs)
    return soil.n0 - soil.n2 * (w * rs - V) / V


def normal_stress(theta: np.ndarray, a: Angles, soil: LabSoil, wheel: LabWheel, state: LabState) -> np.ndarray:
    """sigma(theta) [Pa] (``sigma.m``); NaN where the lab's stress is complex (theta_m beyond theta_f)."""
    N = sinkage_exponent(soil, wheel, state)
    ahead = (theta <= a.front) & (theta >= a.max_stress)
    behind = (theta < a.max_stress) & (theta >= a.rear)
    with np.errstate(divide="ignore", invalid="ignore"):
        equiv = a.front - (theta - a.rear) / (a.max_stress - a.rear) * (a.front - a.max_stress)
        base = np.where(ahead, np.cos(theta) - np.cos(a.front), np.cos(equiv) - np.cos(a.front))
        shape = np.where(base >= 0.0, np.abs(base) ** N, np.nan)
    shape = np.where(ahead | behind, shape, 0.0)
    k, mu = soil.sinkage_modulus, wheel.tip_area_ratio
    return mu * wheel.shear_radius ** N * k * shape + (1.0 - mu) * wheel.radius ** N * k * shape


def tangential_displacement(theta: np.ndarray, a: Angles, wheel: LabWheel, state: LabState) -> np.ndarray:
    """j_t [m] (``j_t.m``, with its r in place of r_s)."""
    r, V, w, vx = wheel.radius, state.speed, state.omega, state.v_x
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = vx / w if w != 0.0 else np.inf * np.sign(vx)
        if r * w >= V:
            return r * (a.front - theta) - (np.sin(a.front) - np.sin(theta)) * ratio
        at = np.abs(theta - a.transition) < 1e-6
        front = (theta > a.transition) & (theta < a.front)
        rear = (theta <= a.transition) & (theta > a.rear)
        chord = (a.front - theta) / (a.front - a.transition) * (np.sin(a.front) - np.sin(a.transition))
        j_front = ratio * (chord - (np.sin(a.front) - np.sin(theta)))
        j_rear = r * (a.transition - theta) - (np.sin(a.transition) - np.sin(theta)) * ratio
        return np.where(at, 0.0, np.where(front, j_front, np.where(rear, j_rear, 0.0)))


def lateral_displacement(theta: np.ndarray, a: Angles, state: LabState) -> np.ndarray:
    """j_l = (theta_f - theta)(-v_y) / omega [m] (``j_l.m``; 0 with no lateral slip and at theta_f)."""
    vjl = -state.v_y
    if vjl == 0.0:
        return np.zeros_like(theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        j = (a.front - theta) * vjl / state.omega if state.omega != 0.0 else (a.front - theta) * np.sign(vjl) * np.inf
    return np.where(theta == a.front, 0.0, j)


def tangential_slip_velocity(theta: np.ndarray, a: Angles, wheel: LabWheel, state: LabState) -> np.ndarray:
    """v_jt [m/s] (``v_jt.m``)."""
    rs, w, vx = wheel.shear_radius, state.omega, state.v_x
    base = rs * w - vx * np.cos(theta)
    if _slipping(wheel, state):
        return base
    at = np.abs(theta - a.transition) < 1e-6
    front = (theta > a.transition) & (theta <= a.front)
    rear = (theta <= a.transition) & (theta >= a.rear)
    shift = (np.sin(a.front) - np.sin(a.transition)) / (a.front - a.transition) * vx - rs * w
    return np.where(at, 0.0, np.where(front, base + shift, np.where(rear, base, 0.0)))


def side_bulldozing(theta: np.ndarray, a: Angles, soil: LabSoil, wheel: LabWheel, state: LabState) -> np.ndarray:
    """R_b(theta) [N/m] (``R_b.m``, Wong 2008, without Ishigami's form)."""
    rs, phi, xc, c = wheel.shear_radius, soil.phi, soil.destructive_angle, soil.cohesion
    depth = (np.sin(theta) - np.sin(a.rear)) / (np.sin(a.front) - np.sin(a.rear)) * rs * (
        np.cos(a.rear) - np.cos(a.front)) - rs * (np.cos(a.rear) - np.cos(theta))
    hb = np.minimum(2.0 * rs * np.cos(theta), depth)
    cot = 1.0 / np.tan(xc)
    rb = 0.5 * soil.specific_weight * hb ** 2 * cot ** 2 * (1.0 + cot * np.tan(phi) / 2.0) + 2.0 * hb * c * cot
    rb = rb * abs(np.sin(state.beta))
    return np.where((np.abs(theta) > np.pi / 2) | (theta == a.front) | (theta == a.rear), 0.0, rb)


def forces(h: float, soil: LabSoil, wheel: LabWheel, state: LabState) -> tuple[float, float, float]:
    """(F_x, F_y, F_z) [N] at sinkage ``h`` [m] (``forces.m``: right-point sums over ``linspace(theta_r, theta_f,
    101)``); NaN where the lab's stress is complex."""
    a = stress_angles(h, wheel, state)
    theta = np.linspace(a.rear, a.front, params.THETA_POINTS)
    sigma = normal_stress(theta, a, soil, wheel, state)
    jt = tangential_displacement(theta, a, wheel, state)
    jl = lateral_displacement(theta, a, state)
    with np.errstate(invalid="ignore", over="ignore"):
        mobilised = np.minimum(1.0 - np.exp(-np.sqrt(jt ** 2 + jl ** 2) / soil.shear_modulus), 1.0)
    vjt = tangential_slip_velocity(theta, a, wheel, state)
    vjl = -state.v_y
    strength = (soil.cohesion + sigma * np.tan(soil.phi)) * mobilised
    with np.errstate(divide="ignore", invalid="ignore"):
        norm = np.sqrt(vjt ** 2 + vjl ** 2)
        tau_t = np.where(vjt == 0.0, 0.0, vjt / norm * strength)
        tau_l = np.zeros_like(theta) if vjl == 0.0 else vjl / norm * strength
    rb = side_bulldozing(theta, a, soil, wheel, state)
    rs, b = wheel.shear_radius, wheel.width
    dtheta = np.diff(theta)
    px = rs * b * (-sigma * np.sin(theta) + tau_t * np.cos(theta))
    py = rs * b * tau_l + rs * np.cos(theta) * rb * np.sin(state.beta)
    pz = rs * b * (sigma * np.cos(theta) + tau_t * np.sin(theta))
    return tuple(float(np.sum(dtheta * p[1:])) for p in (px, py, pz))


def find_sinkage(load: float, soil: LabSoil, wheel: LabWheel, state: LabState) -> tuple[float, bool]:
    """(h [m], found) with F_z(h) = ``load`` [N] to 0.1 % (``find_sinkage.m``: bisection on [1e-4 m, 1.5 r], a
    complex F_z read as too little sinkage; not found when the bracket closes to 1e-8 m first)."""
    lo, hi, fz = 1e-4, 1.5 * wheel.radius, 0.0
    h = 0.5 * (lo + hi)
    while not abs(load - fz) <= abs(0.001 * load):  # a complex (NaN) F_z is not a balance
        h = 0.5 * (hi + lo)
        fz = forces(h, soil, wheel, state)[2]
        if not np.isfinite(fz) or fz < load:
            lo = h
        else:
            hi = h
        if hi - lo < 1e-8:
            return h, False
    return h, True


def skid_angles(wheel_name: str, slip_angle: float, carriage_speed: float, load: float) -> tuple[float, float]:
    """theta_m0, theta_r0 [rad] of the skidding wheel at ``slip_angle`` [deg] (``run_model.m``): theta_m and theta_r
    at slip 0 (omega = V / r_s) under ``load`` [N] (the trials' mean at a rim speed of 8 mm/s), ``carriage_speed``
    [m/s] (the trials' mean at rim speed 0)."""
    soil, wheel = lab_soil(wheel_name), lab_wheel(wheel_name)
    beta = np.radians(slip_angle)
    tuned = tuned_angles(wheel_name, slip_angle)
    V = carriage_speed
    # omega r_s = V: the slipping branch at s = 0 (one ulp up, so that rounding cannot tip it into skidding)
    state = LabState(v_x=V * np.cos(beta), v_y=V * np.sin(beta), omega=float(np.nextafter(V / wheel.shear_radius,
                                                                                           np.inf)),
                     beta=beta, tuned=tuned)
    h, _ = find_sinkage(load, soil, wheel, state)
    a = stress_angles(h, wheel, state)
    return a.max_stress, a.rear


def lab_soil(wheel_name: str) -> LabSoil:
    return LabSoil(**params.SOILS[_known(wheel_name)])


def lab_wheel(wheel_name: str) -> LabWheel:
    return LabWheel(**params.WHEELS[_known(wheel_name)])


def tuned_angles(wheel_name: str, slip_angle: float) -> tuple:
    table = params.TUNED_ANGLES[_known(wheel_name)]
    key = float(slip_angle)
    if key not in table:
        raise WheelsoilInputError(f"steering angle {slip_angle!r} deg: the CMU lab's model is tuned at "
                                  f"{sorted(table)} deg only")
    return table[key]


def _known(wheel_name: str) -> str:
    if wheel_name not in params.WHEELS:
        raise WheelsoilInputError(f"wheel {wheel_name!r}: the CMU lab's model knows {sorted(params.WHEELS)}")
    return wheel_name


@dataclass(frozen=True)
class TrialRows:
    """The trials the lab's model is run on, one entry per row: wheel name, steering angle [deg], rim speed and
    carriage speed [m/s], vertical load [N]."""

    wheel: np.ndarray
    slip_angle: np.ndarray
    rim_speed: np.ndarray
    carriage_speed: np.ndarray
    load: np.ndarray


def read_trials(folder) -> TrialRows:
    """The rows of the CMU trial files (both wheels, file order: grouser then smooth, as
    :func:`~.measured.load_cmu_trials` reads them)."""
    from pathlib import Path

    from .measured import load_table

    cols = {k: [] for k in ("wheel", "slip_angle", "rim_speed", "carriage_speed", "load")}
    for name in ("grouser_wheel_trials.csv", "smooth_wheel_trials.csv"):
        t = load_table(Path(folder) / name)
        t.require("wheel", "steering_angle", "rim_speed", "carriage_speed", "vertical_load")  # SI (load_table)
        c = t.columns
        cols["wheel"].append(np.asarray(c["wheel"]).astype(str))
        cols["slip_angle"].append(np.asarray(c["steering_angle"], float))
        cols["rim_speed"].append(np.asarray(c["rim_speed"], float))
        cols["carriage_speed"].append(np.asarray(c["carriage_speed"], float))
        cols["load"].append(np.asarray(c["vertical_load"], float))
    return TrialRows(**{k: np.concatenate(v) for k, v in cols.items()})


def predict_trials(rows: TrialRows) -> dict:
    """The lab's model on every row: ``drawbar_pull``, ``lateral_force`` [N] (in wheelsoil's frame, the sign of
    :func:`~.measured.load_cmu_file`: the lab's F_y negated), ``sinkage`` [m] (from the undisturbed surface) and
    ``found`` (the bisection met the load), as ``run_model.m`` runs it on each trial's own
    rim speed (omega = rim speed / r), carriage speed and load, with theta_m0 and theta_r0 per wheel and angle from
    the trials at rim speeds 8 and 0 mm/s."""
    n = len(rows.load)
    out = {"drawbar_pull": np.full(n, np.nan), "lateral_force": np.full(n, np.nan), "sinkage": np.full(n, np.nan),
           "found": np.zeros(n, bool)}
    skid = {}
    for wheel_name, angle in sorted(set(zip(rows.wheel, rows.slip_angle))):
        same = (rows.wheel == wheel_name) & (rows.slip_angle == angle)
        reference = same & np.isclose(rows.rim_speed, params.SKID_REFERENCE_RIM_SPEED / 1000.0)
        rest = same & (rows.rim_speed == 0.0)
        if not reference.any() or not rest.any():
            raise WheelsoilInputError(f"the {wheel_name} wheel at {angle:g} deg has no trial at rim speed "
                                      f"{params.SKID_REFERENCE_RIM_SPEED:g} mm/s and 0 mm/s: the lab's model fixes "
                                      "the skidding wheel's stress angles from them")
        skid[wheel_name, angle] = skid_angles(wheel_name, angle, float(np.mean(rows.carriage_speed[rest])),
                                              float(np.mean(rows.load[reference])))
    for k in range(n):
        wheel_name, angle = str(rows.wheel[k]), float(rows.slip_angle[k])
        soil, wheel = lab_soil(wheel_name), lab_wheel(wheel_name)
        beta, V = np.radians(angle), float(rows.carriage_speed[k])
        m0, r0 = skid[wheel_name, angle]
        state = LabState(v_x=V * np.cos(beta), v_y=-V * np.sin(beta), omega=float(rows.rim_speed[k]) / wheel.radius,
                         beta=beta, tuned=tuned_angles(wheel_name, angle), theta_m0=m0, theta_r0=r0)
        h, found = find_sinkage(float(rows.load[k]), soil, wheel, state)
        fx, fy, _ = forces(h, soil, wheel, state)
        out["drawbar_pull"][k], out["lateral_force"][k], out["sinkage"][k], out["found"][k] = fx, -fy, h, found
    return out
