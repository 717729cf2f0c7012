"""Synthetic single-wheel measurements: the classical model plus one hidden mechanism and realistic noise.

Used to test that the discovery workflow names a mechanism it was not told about, recovers its parameter
and measures a positive held-out gain -- and that it finds nothing when nothing is hidden.
"""

from dataclasses import replace

import numpy as np

from wheelsoil.gravity import EARTH_GRAVITY
from wheelsoil.slip import heading_slip_from_travel

from .extensions import BASELINE_OFF
from .measured import Measurements
from .oscillation import SeriesRecord, density_wave_amplitudes, spoke_radius_waveform
from .terramechanics import RigidWheel, SoilParameters, predict

#: The classical soil the synthetic data start from (dry sand, SI): every extension off.
TRUE_SOIL = replace(
    SoilParameters(density=1600.0, cohesion=1500.0, friction_angle=33.0, kc_prime=50.0, kphi_prime=800.0,
                   n0=1.0, shear_modulus_x=0.012, shear_modulus_y=0.012, a1=0.35),
    **BASELINE_OFF,
)
#: A small grousered test wheel [m].
TEST_WHEEL = RigidWheel(radius=0.15, width=0.12, grouser_height=0.008, grouser_count=18)

#: Magnitudes a hidden mechanism is drawn from (uniform), large enough to matter at the noise below.
HIDDEN_RANGES = {
    "slip_sinkage": {"n1": (0.3, 0.8)},
    "theta_m_slip": {"a2": (0.2, 0.45)},
    "soil_flow": {"soil_flow": (0.25, 0.5)},
    "sidewall": {"sidewall_scale": (1.0, 3.0)},
    "grouser": {"grouser_scale": (1.0, 3.0)},
    "surrogate_radius": {"radius_scale": (1.2, 1.5)},
    "gravity_cohesion": {"cohesion_gravity_exponent": (1.0, 2.0)},
    "bulldozing": {"bulldozing_scale": (0.15, 0.4)},
    "multipass": {"multipass_k2": (0.1, 0.3)},
    # with k'_c free the modulus is c k'_c + rho g b k'_phi (g/g0)^-eps, i.e. A + B g^(1-eps): at eps = 1 (seed
    # 000's constant K_phi) it is the classical model with k'_phi -> 0 exactly, and only the curvature in g tells
    # eps apart from Reece's linear form (largest, about 5 % of the modulus over 1.62-9.81 m/s^2, at eps 0.3-0.7)
    "gravity_pressure": {"kphi_gravity_exponent": (0.3, 0.7)},
    "gravity_soil_flow": {"soil_flow_gravity": (0.3, 0.6)},
}

#: Effects the catalogue does not hold (the workflow must not give them a catalogue name): each a soil parameter
#: that varies with a test condition in a way no extension models, with the range its strength is drawn from.
#: ``field``: the SoilParameters field it changes; ``law(value, strength, cond)``: the field's value per row, held at
#: ``floor`` or above where the effect gives one (a law written for the generators' factorial, driving slips and at
#: most 30 deg, can leave the physical range on the whole domain's 90 deg rows).
#: The first five are linear (or, over two loads, equivalent) drifts of one parameter with one condition, the form
#: of the workflow's generic rivals (:func:`~.extensions.drift_rival`; the load drifts have no rival, since no
#: mechanism acts through the load); the last two are outside that family too: a friction angle that rises and
#: falls again with slip, and one that falls with slip and slip angle together.
OUT_OF_CATALOGUE = {
    "friction_gravity": {
        "description": "internal friction angle rising at low gravity, phi + d (1 - g / 9.81) (a gravity effect "
                       "that acts through neither cohesion, pressure modulus nor soil flow)",
        "field": "friction_angle", "range": (4.0, 8.0),
        "law": lambda v, d, c: v + d * (1.0 - c["gravity"] / EARTH_GRAVITY)},
    "shear_modulus_load": {
        "description": "shear deformation modulus growing with the load, K (W / 90 N)^m",
        "field": "shear_modulus_x", "range": (0.8, 1.5),
        "law": lambda v, m, c: v * (c["load"] / 90.0) ** m},
    "cohesion_slip_softening": {
        "description": "cohesion lost as the soil is sheared, c (1 - s i) (strain softening; linear in the signed "
                       "slip, so braking rows, i < 0, are harder)",
        "field": "cohesion", "range": (0.7, 0.95),
        "law": lambda v, s, c: v * (1.0 - s * c["slip"])},
    "friction_steering": {
        "description": "friction angle falling with the slip angle, phi - d sin|beta| (soil disturbed sideways)",
        "field": "friction_angle", "range": (8.0, 14.0),
        "law": lambda v, d, c: v - d * np.sin(np.radians(np.abs(c["slip_angle"])))},
    "density_load": {
        "description": "bulk density of the soil under the wheel rising with the load, rho (W / 90 N)^m "
                       "(compaction under the wheel's own pressure bulb)",
        "field": "density", "range": (0.3, 0.6),
        "law": lambda v, m, c: v * (c["load"] / 90.0) ** m},
    "friction_slip_peak": {
        "description": "friction angle mobilised at moderate slip and lost again at large slip, phi + d sin(pi "
                       "min(|i| / 0.7, 1)) (dilatant peak strength, then loosened soil; not monotone in slip)",
        "field": "friction_angle", "range": (3.0, 6.0),
        "law": lambda v, d, c: v + d * np.sin(np.pi * np.minimum(np.abs(c["slip"]) / 0.7, 1.0))},
    "friction_slip_steering": {
        "description": "friction angle lost where the wheel both slips and slides sideways, phi - d (|i| / 0.7) "
                       "(sin|beta| / sin 30 deg) (an interaction of two conditions), at least 0.5 deg (at 90 deg and "
                       "|i| = 1 the law alone takes up to 34 deg off the soil's 33)",
        "field": "friction_angle", "range": (6.0, 12.0), "floor": 0.5,
        "law": lambda v, d, c: v - d * (np.abs(c["slip"]) / 0.7) * (
            np.sin(np.radians(np.abs(c["slip_angle"]))) / np.sin(np.radians(30.0)))},
    # effects that follow the load, which acts through the weight on the wheel as gravity does (issue 36: with
    # rivals only along the conditions a mechanism acts through, such an effect was read as a gravity mechanism)
    "friction_load": {
        "description": "friction angle falling as the load grows, phi - d ln(W / 90 N) (a stress-dependent friction "
                       "angle, as a sand's curved Mohr envelope)",
        "field": "friction_angle", "range": (3.0, 6.0),
        "law": lambda v, d, c: v - d * np.log(c["load"] / 90.0)},
    "cohesion_load": {
        "description": "cohesion growing with the load, c (W / 90 N)^m (an apparent cohesion of a soil packed "
                       "under the wheel)",
        "field": "cohesion", "range": (0.6, 1.0),
        "law": lambda v, m, c: v * (c["load"] / 90.0) ** m},
    "kphi_load": {
        "description": "frictional pressure modulus growing with the load, k'_phi (W / 90 N)^m (a soil stiffened "
                       "by its own compaction; the load, not the gravity, sets it)",
        "field": "kphi_prime", "range": (0.4, 0.8),
        "law": lambda v, m, c: v * (c["load"] / 90.0) ** m},
}
#: The out-of-catalogue effects that follow the load (:data:`OUT_OF_CATALOGUE`).
LOAD_EFFECTS = ("shear_modulus_load", "density_load", "friction_load", "cohesion_load", "kphi_load")


def load_gravity_conditions():
    """A design with the load and the gravity varied independently over a wider load range than
    :func:`conditions`: loads 40, 80 and 160 N (a factor of four) at 9.81 and 1.62 m/s^2 (Earth and Moon), each
    load at each gravity, the same slips and slip angles, the pass number balanced (issue 36's out-of-catalogue
    campaign)."""
    return conditions(loads=(40.0, 80.0, 160.0), gravities=(EARTH_GRAVITY, 1.62))


#: Travel slips of the whole-domain design below 90 deg: dragged (-1), braking (-0.5, -0.2) and driving, as the CMU rig
#: sets them.
WHOLE_DOMAIN_SLIPS = (-1.0, -0.5, -0.2, 0.05, 0.2, 0.35, 0.5, 0.7)
#: Travel slips of its rows at 90 deg: a wheel dragged sideways without turning (-1), and turning ones.
SIDEWAYS_SLIPS = (-1.0, 0.2, 0.5)


#: Five gravity levels [m/s^2], about evenly spaced in log g from the Moon to the Earth with Mars among them: the three
#: of seed 000's flights plus 2.45 (a quarter g) and 6.0. With three levels a power law in g (a gravity mechanism)
#: and another parameter's linear drift along g differ only in how they bend between the levels, and at the
#: campaigns' noise they often fit alike (docs/validation/campaigns.md, "the gravity ties"); five levels show the bend.
FIVE_GRAVITY_LEVELS = (EARTH_GRAVITY, 6.0, 3.71, 2.45, 1.62)


def whole_domain_five_gravity_conditions():
    """:func:`whole_domain_conditions` at the :data:`FIVE_GRAVITY_LEVELS` (350 conditions): the design fixed on
    2026-11-29, before any of its draws, to ask whether the gravity ties are the design's or the rules'."""
    return whole_domain_conditions(gravities=FIVE_GRAVITY_LEVELS)


def whole_domain_conditions(slips=WHOLE_DOMAIN_SLIPS, slip_angles=(0.0, 10.0, 20.0, 30.0),
                            sideways_slips=SIDEWAYS_SLIPS, loads=(60.0, 120.0),
                            gravities=(EARTH_GRAVITY, 3.71, 1.62), passes=(1, 2, 3)):
    """The rig's whole domain (issue 36): :func:`conditions` with the slip given as the CMU rig gives it, against the
    whole travel speed, braking as well as driving, plus rows at 90 deg where the wheel ploughs sideways (dragged
    without turning, and turning), each at every load and gravity. 8 x 4 x 2 x 3 + 3 x 2 x 3 = 210 conditions
    by default. Returns :func:`conditions`' keys plus ``travel_slip``; ``slip`` is the heading slip it gives
    (+-1 at 90 deg, where the heading slip cannot say how fast the wheel slides: the model reads the travel slip)."""
    below = conditions(slips=slips, slip_angles=slip_angles, loads=loads, gravities=gravities, passes=passes)
    side = conditions(slips=sideways_slips, slip_angles=(90.0,), loads=loads, gravities=gravities, passes=passes)
    out = {k: np.concatenate([below[k], side[k]]) for k in below}
    out["travel_slip"] = out.pop("slip")
    out["slip"] = heading_slip_from_travel(out["travel_slip"], out["slip_angle"])
    return out


def conditions(slips=(0.05, 0.2, 0.35, 0.5, 0.7), slip_angles=(0.0, 10.0, 20.0, 30.0),
               loads=(60.0, 120.0), gravities=(EARTH_GRAVITY, 3.71, 1.62), passes=(1, 2, 3)):
    """The full factorial of test conditions (slip, slip angle [deg], load [N], gravity [m/s^2]: Earth, Mars and
    Moon, the three levels of seed 000's flights; three are needed to tell a gravity exponent of the pressure
    modulus from the split between k'_c and k'_phi), each run on
    one of ``passes`` (the wheel's pass number over the same soil). The pass number cycles with the sum of the
    other factors' level indices, a balanced design in which it is not aliased with any one of them, so that
    adding it costs no extra conditions."""
    grid = np.array(np.meshgrid(slips, slip_angles, loads, gravities, indexing="ij")).reshape(4, -1)
    levels = np.array(np.meshgrid(*(np.arange(len(v)) for v in (slips, slip_angles, loads, gravities)),
                                  indexing="ij")).reshape(4, -1).sum(axis=0)
    n_p = np.asarray(passes, float)[levels % len(passes)]
    return {"slip": grid[0], "slip_angle": grid[1], "load": grid[2], "gravity": grid[3], "passes": n_p}


def draw_out_of_catalogue(rng: np.random.Generator, names=None) -> tuple[str, float]:
    """An effect of :data:`OUT_OF_CATALOGUE` (uniformly among ``names``, default all) and its strength."""
    names = list(OUT_OF_CATALOGUE if names is None else names)
    name = names[int(rng.integers(len(names)))]
    return name, float(rng.uniform(*OUT_OF_CATALOGUE[name]["range"]))


def draw_hidden_effect(rng: np.random.Generator, names=None) -> tuple[str | None, dict]:
    """A mechanism (uniformly among ``names``, default all; None means nothing hidden) and its parameters."""
    names = list(HIDDEN_RANGES if names is None else names)
    name = names[int(rng.integers(len(names)))]
    if name is None:
        return None, {}
    return name, {k: float(rng.uniform(*bounds)) for k, bounds in HIDDEN_RANGES[name].items()}


def _predict_with_effect(truth: SoilParameters, wheel: RigidWheel, cond: dict, effect: tuple | None) -> dict:
    """:func:`predict` at every condition; ``effect`` = (name, strength) of :data:`OUT_OF_CATALOGUE` makes one soil
    field vary with the conditions (rows grouped by its value, each group predicted with its own soil)."""
    if effect is None:
        return predict(truth, wheel, **cond)
    name, strength = effect
    spec = OUT_OF_CATALOGUE[name]
    n = np.asarray(cond["slip"]).size
    arrays = {k: np.broadcast_to(np.asarray(v, float), (n,)) for k, v in cond.items()}
    values = spec["law"](getattr(truth, spec["field"]), strength, arrays)
    values = np.maximum(np.broadcast_to(np.asarray(values, float), (n,)), spec.get("floor", -np.inf))
    out = {}
    for v in np.unique(values):
        rows = values == v
        changes = {spec["field"]: float(v)}
        if spec["field"] == "shear_modulus_x":
            changes["shear_modulus_y"] = float(v)
        part = predict(replace(truth, **changes), wheel, **{k: a[rows] for k, a in arrays.items()})
        for q, a in part.items():
            out.setdefault(q, np.zeros(n, np.asarray(a).dtype))[rows] = a
    return out


def synthetic_measurements(hidden: dict, rng: np.random.Generator, *, soil: SoilParameters = TRUE_SOIL,
                           wheel: RigidWheel = TEST_WHEEL, cond: dict | None = None, noise: float = 0.03,
                           relative_noise: float = 0.02, effect: tuple | None = None) -> Measurements:
    """Measurements from ``soil`` with the ``hidden`` parameters changed, plus Gaussian noise of ``noise``
    times each response's spread and ``relative_noise`` times its value (the scatter of repeated rig
    tests: heteroscedastic, larger where the response is larger). ``effect`` = (name, strength) adds an effect
    of :data:`OUT_OF_CATALOGUE`."""
    cond = cond or conditions()
    truth = replace(soil, **hidden)
    out = _predict_with_effect(truth, wheel, cond, effect)
    n = out["sinkage"].size
    responses = {}
    for q in ("drawbar_pull", "lateral_force", "sinkage", "torque"):
        y = np.asarray(out[q], float).ravel()
        sigma = noise * np.std(y) + relative_noise * np.abs(y)
        responses[q] = y + sigma * rng.standard_normal(n)
    full = lambda v: np.full(n, float(v))  # noqa: E731
    return Measurements(
        name="synthetic", slip=np.asarray(cond["slip"], float), slip_angle=np.asarray(cond["slip_angle"], float),
        load=np.asarray(cond["load"], float), gravity=np.asarray(cond["gravity"], float),
        radius=full(wheel.radius), width=full(wheel.width), grouser_height=full(wheel.grouser_height),
        grouser_count=full(wheel.grouser_count), group=np.full(n, "synthetic"), responses=responses,
        notes=f"hidden: {hidden or 'nothing'}{f'; out of catalogue: {effect[0]} {effect[1]:.3g}' if effect else ''}",
        passes=np.asarray(cond.get("passes", np.ones(n)), float),
        travel_slip=np.asarray(cond["travel_slip"], float) if "travel_slip" in cond else None,
    )



#: The smooth twin of :data:`TEST_WHEEL` (same rim). With both wheels in one set, a mechanism that acts only on
#: grousers (the shearing radius at the grouser tips) is no longer the same as a larger radius for both; the
#: periodic sets use it too (seed 002's effect is a smooth wheel's).
SMOOTH_WHEEL = RigidWheel(radius=TEST_WHEEL.radius, width=TEST_WHEEL.width)
#: Mechanisms that need the two-wheel set to be told from others, with their hidden ranges.
TWO_WHEEL_HIDDEN_RANGES = {"grouser_tip_radius": {"grouser_tip_fraction": (0.5, 1.2)}}


def two_wheel_conditions():
    """A smaller factorial per wheel, so that the two-wheel set has as many rows as :func:`conditions`."""
    return conditions(slips=(0.05, 0.2, 0.4, 0.6), slip_angles=(0.0, 15.0, 30.0))


def synthetic_two_wheel_measurements(hidden: dict, rng: np.random.Generator, *, soil: SoilParameters = TRUE_SOIL,
                                     cond: dict | None = None, **noise) -> Measurements:
    """:func:`synthetic_measurements` for the grousered :data:`TEST_WHEEL` and its smooth twin at the same
    conditions, in one set (groups ``grouser`` and ``smooth``), as the CMU rig tests both wheels."""
    cond = cond or two_wheel_conditions()
    parts = [synthetic_measurements(hidden, rng, soil=soil, wheel=w, cond=cond, **noise)
             for w in (TEST_WHEEL, SMOOTH_WHEEL)]
    cat = lambda key: np.concatenate([getattr(m, key) for m in parts])  # noqa: E731
    n = len(parts[0])
    return Measurements(
        name="synthetic (two wheels)", slip=cat("slip"), slip_angle=cat("slip_angle"), load=cat("load"),
        gravity=cat("gravity"), radius=cat("radius"), width=cat("width"), grouser_height=cat("grouser_height"),
        grouser_count=cat("grouser_count"), group=np.array(["grouser"] * n + ["smooth"] * n),
        responses={q: np.concatenate([m.responses[q] for m in parts]) for q in parts[0].responses},
        notes=f"hidden: {hidden or 'nothing'}", passes=cat("passes"),
    )

# ------------------------------------------------------------------------ periodic effects in time series
#: Periodic mechanisms a synthetic time-series set can hide, with the ranges their parameters are drawn from:
#: seed 002's density wave (amplitude factor k'_a, and the slip law omega = a + b i of eq. 25 in rad/s) and
#: seed 000's spoke-stiffness radius (swing dR / r about a surrogate radius of 1.5 r).
HIDDEN_OSCILLATIONS = {
    "density_wave": {"k_a": (60.0, 160.0), "a": (30.0, 40.0), "b": (-40.0, -30.0)},
    "spoke_radius": {"radius_swing": (0.3, 0.9)},
}
#: Stiffness peaks per turn of the synthetic flexible wheel (the ExoMars wheel's six, seed 000).
SYNTHETIC_SPOKES = 6
#: A periodic effect outside the catalogue: an oscillation at a count per turn the declared wheel does not have
#: (neither its grousers nor its spokes), with its amplitude as a fraction of the median steady value.
UNDECLARED_COUNT = {"count": (8, 11), "amplitude": (0.05, 0.12)}


def oscillation_conditions(slips=(0.1, 0.25, 0.4, 0.55), loads=(40.0, 80.0, 160.0), omegas=(1.5, 2.0, 2.5),
                           carriage_speed: float | None = None, radius: float = TEST_WHEEL.radius):
    """Runs for a periodic set: every slip at every load (a load is a held-out group), the wheel speed cycling
    through ``omegas`` [rad/s] so that a counting law can be told from a constant frequency; or, with
    ``carriage_speed`` [m/s], the wheel speed a rig at that constant carriage speed sets, v / (r (1 - i)), which
    ties it to the slip (the confound :func:`~wheelsoil.validation.periodic.speed_slip_confound` reports)."""
    slip, load = (a.ravel() for a in np.meshgrid(slips, loads, indexing="ij"))
    if carriage_speed is not None:
        omega = carriage_speed / (radius * (1.0 - slip))
    else:
        omega = np.array([omegas[k % len(omegas)] for k in range(slip.size)], float)
    return {"slip": slip, "slip_angle": np.zeros(slip.size), "load": load, "gravity": np.full(slip.size, EARTH_GRAVITY),
            "omega": omega}


def synthetic_oscillation_series(hidden: str | None, params: dict, rng: np.random.Generator, *,
                                 soil: SoilParameters = TRUE_SOIL, wheel: RigidWheel = SMOOTH_WHEEL,
                                 cond: dict | None = None, duration: float = 12.0, rate: float = 100.0,
                                 noise: float = 0.03, ar1: float = 0.9, quantity: str = "drawbar_pull") -> list:
    """Drawbar-pull records: the steady value, the ``hidden`` periodic mechanism (None: nothing) and red
    AR(1) noise of lag-1 correlation ``ar1`` whose standard deviation is ``noise`` times the median steady value.

    ``soil`` is the steady truth; the spoke-radius set uses it with a surrogate radius of 1.5 r.
    Returns :class:`~wheelsoil.validation.oscillation.SeriesRecord` objects grouped by load.
    """

    cond = cond or oscillation_conditions()
    steady_cond = {k: cond[k] for k in ("slip", "slip_angle", "load", "gravity")}
    if hidden == "spoke_radius":
        soil = replace(soil, radius_scale=1.5)
    steady = np.ravel(predict(soil, wheel, **steady_cond)[quantity])
    t = np.arange(int(duration * rate)) / rate
    n = steady.size
    if hidden == "density_wave":
        amp = density_wave_amplitudes(soil, wheel, steady_cond, params["k_a"], quantity)
        omega_osc = params["a"] + params["b"] * cond["slip"]  # seed 002 eq. 25 form [rad/s]
        phase = rng.uniform(0.0, 2.0 * np.pi, n)
        signal = amp[:, None] * np.sin(omega_osc[:, None] * t[None, :] + phase[:, None])
    elif hidden == "spoke_radius":
        phases, values = spoke_radius_waveform(soil, wheel, steady_cond, params["radius_swing"], quantity)
        coef = np.fft.rfft(values - values.mean(axis=0), axis=0) / values.shape[0]  # trigonometric interpolation
        angle = SYNTHETIC_SPOKES * cond["omega"][:, None] * t[None, :] + rng.uniform(0, 2 * np.pi, n)[:, None]
        signal = np.zeros((n, t.size))
        for k in range(1, coef.shape[0]):
            weight = 1.0 if 2 * k == values.shape[0] else 2.0
            signal += weight * np.real(coef[k][:, None] * np.exp(1j * k * angle))
    elif hidden == "undeclared_count":
        amp = params["amplitude"] * float(np.median(np.abs(steady)))
        angle = int(params["count"]) * cond["omega"][:, None] * t[None, :] + rng.uniform(0, 2 * np.pi, n)[:, None]
        signal = amp * np.sin(angle)
    elif hidden is None:
        signal = np.zeros((n, t.size))
    else:
        raise ValueError(f"unknown periodic mechanism {hidden!r}; choose one of {sorted(HIDDEN_OSCILLATIONS)}")
    sigma = noise * float(np.median(np.abs(steady)))
    innovations = rng.standard_normal((n, t.size)) * sigma * np.sqrt(1.0 - ar1 ** 2)
    red = np.zeros((n, t.size))
    red[:, 0] = rng.standard_normal(n) * sigma
    for k in range(1, t.size):
        red[:, k] = ar1 * red[:, k - 1] + innovations[:, k]
    return [SeriesRecord(t, steady[j] + signal[j] + red[j], float(cond["omega"][j]), float(cond["slip"][j]),
                         float(cond["slip_angle"][j]), float(cond["load"][j]), float(cond["gravity"][j]),
                         group=f"{cond['load'][j]:g} N") for j in range(n)]
