"""Semi-empirical 3-D wheel--soil model: Wong--Reece stresses, Janosi--Hanamoto shear, lateral shear for a
slip angle, sidewall and grouser forces, sinkage from vertical equilibrium (vectorised NumPy).

Angles theta are measured at the wheel centre from the downward vertical, positive towards the front
(soil entry at theta_f, exit at theta_r <= 0). Conventions as the rest of wheelsoil (architecture): wheel
frame x along the heading, y along the axle, z up; slip i = 1 - v_x / (r omega) (driving, i >= 0) and the
braking branch of seed 003 eq. 4; slip angle beta between heading and travel, v_y = v_x tan(beta). Forces
are those the soil exerts on the wheel: drawbar pull along +x, lateral force along y, vertical force up,
driving torque the motor supplies. SI units; ``slip_angle`` in degrees.

Equations (seed 003 = Zhou et al., Artemis; seed 000 = Ding et al. / Kovecses et al., gravity):

* normal stress, Reece's gravity-explicit pressure--sinkage in Wong--Reece form (seed 003 eq. 7)::

      sigma(theta) = (c k'_c + rho g b k'_phi) (r / b)^n (cos theta - cos theta_f)^n         theta_m <= theta <= theta_f
      sigma(theta) = same with theta -> theta_f - (theta - theta_r) / (theta_m - theta_r) (theta_f - theta_m)
                                                                                            theta_r <= theta <= theta_m
  with n = n0 + n1 |i| (slip-sinkage, seed 003 eq. 5; n1 = 0 gives the classical constant exponent);
* angle of maximum stress theta_m = (a1 + a2 i) theta_f (seed 003 eq. 8), exit angle theta_r = -c3 theta_f;
* shear, Janosi--Hanamoto with Mohr--Coulomb strength (seed 003 eqs. 9--10, 13)::

      tau_x = (c + sigma tan phi)(1 - exp(-j_x / k_x)),   tau_y = (c + sigma tan phi)(1 - exp(-j_y / k_y))
  with the shear displacements of seed 003 eqs. 12 and 16; or, with ``shear_form = "resultant"`` (the CMU
  lab's 3-D model, Pavlov, robomechanics/3d-terramechanics ``tau_t.m``, ``tau_l.m``), the strength mobilised by
  the resultant displacement and directed along the soil's slip velocity (v_jt, v_jl) under the rim::

      (tau_x, tau_y) = (c + sigma tan phi)(1 - exp(-sqrt(j_x^2 + j_y^2) / k_x)) (v_jt, |v_jl|) / |v_j|,
      v_jt = r omega (1 - eta) - v_x cos theta  (``v_jt.m``),   v_jl = v_y = v_x tan beta;
* force integrals (seed 000 eqs. 9--11 in 3-D form, Ishigami et al. 2007)::

      F_x = r b  int (tau_x cos theta - sigma sin theta) d theta
      F_z = r b  int (tau_x sin theta + sigma cos theta) d theta
      F_y = -sign(beta) (r b int tau_y d theta + F_s)          T = r^2 b int tau_x d theta
* sidewall resistance (Schwanghart; seed 003 eqs. 17--19, q = 0) on the side the wheel slides towards, or the
  CMU lab's side bulldozing (``R_b.m``, Wong 2008); both in :mod:`.side_forces`;
* grouser forces (seed 003 eq. 20, passive earth pressure on each grouser in the soil, resolved along the
  grouser's angle), spread over the contact as an average over one grouser pitch;
* bulldozing resistance of the soil pushed ahead of the wheel (Bekker / Hegedus, :func:`bulldozing_force`);
* multipass compaction: on its n_p-th pass a wheel meets soil compacted by the earlier ones, density and
  cohesion times k1 + k2 n_p (seed 003 eq. 23, Senatore & Sandu 2011) with k1 = 1 - k2, so that the first
  pass meets undisturbed soil;
* sinkage z from vertical equilibrium F_z(z) = W (Illinois false position, vectorised over conditions).

A *drift* (``drift_field``, ``drift_condition``, ``drift_rate``) is not a mechanism: it lets one classical soil
parameter p vary linearly with one test condition, p (1 + rate u), u the condition's own measure
(:data:`DRIFT_MEASURES`). The discovery workflow fits drifts along every condition the data vary as generic rivals
of a mechanism (:mod:`wheelsoil.validation.discovery`): a mechanism is named only when the data single out its
form, not merely "some soil property changes with slip", or with the load.
"""

from dataclasses import asdict, dataclass

import numpy as np

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.gravity import EARTH_GRAVITY

from wheelsoil.slip import heading_slip_from_travel, travel_slip_from_heading

from .passive_forces import bulldozing_force, grouser_forces
from .quadrature import QUADRATURE_POINTS, gauss_legendre, graded_gauss_on
from .shear import janosi_hanamoto, lateral_displacement, resultant_shear, tangential_displacement, wheel_speeds
from .side_forces import bearing_capacity_factors, side_bulldozing_force, sidewall_force
from .sinkage_solve import SinkageWarmStart, solve_sinkage

__all__ = ["SoilParameters", "RigidWheel", "contact_forces", "predict", "CheckedConditions", "forces_at_sinkage",
           "bearing_capacity_factors", "sidewall_force", "side_bulldozing_force", "bulldozing_force", "grouser_forces",
           "janosi_hanamoto", "resultant_shear", "QUADRATURE_POINTS", "gauss_legendre"]


#: How the shear stress is split between the heading and the axle (:class:`SoilParameters` ``shear_form``).
SHEAR_FORMS = ("independent", "resultant")

#: Classical soil parameters a drift may act on. The drifted value enters the Wong--Reece and Janosi--Hanamoto
#: stresses (normal stress, shear strength and displacement, theta_m); the sidewall, bulldozing and grouser terms
#: keep the soil's own value.
DRIFT_FIELDS = ("cohesion", "friction_angle", "shear_modulus_x", "kc_prime", "kphi_prime", "n0", "a1")
#: The measure u of each condition a drift is linear in, u = 0 at the reference state: |slip| and the signed slip
#: (a drift that grows on driving rows and falls on braking ones; added 2026-11-28, docs/validation/campaigns.md says
#: why; on rows of one sign it is |slip| again and the workflow fits it once, :func:`~.extensions.varied_conditions`),
#: sin|slip angle|,
#: the fall in gravity 1 - g / 9.81, the earlier passes n_p - 1, and for the load and the wheel's radius and width,
#: conditions of scale, the log ratio ln(x / x_ref) to the reference ``SoilParameters.drift_reference`` (the discovery
#: workflow takes the training rows' median): p (1 + rate ln(x / x_ref)) is a power law p (x / x_ref)^rate to first
#: order, the form soil properties take with the scale of a test (Bekker's exponent; until 2026-11-27 the measure was
#: x / x_ref - 1, docs/validation/campaigns.md says why it changed). Each reads a dict of the conditions
#: (:func:`drift_conditions`).
DRIFT_MEASURES = {
    "slip": lambda c: np.abs(c["slip"]),
    "signed_slip": lambda c: np.asarray(c["slip"], float),
    "slip_angle": lambda c: np.abs(np.sin(c["beta"])),
    "gravity": lambda c: 1.0 - c["gravity"] / EARTH_GRAVITY,
    "passes": lambda c: c["passes"] - 1.0,
    "load": lambda c: np.log(c["load"] / c["reference"]),
    "radius": lambda c: np.log(c["radius"] / c["reference"]),
    "width": lambda c: np.log(c["width"] / c["reference"]),
}
#: The conditions whose drift is measured from a reference value (:data:`DRIFT_MEASURES`).
RELATIVE_DRIFTS = ("load", "radius", "width")


def drift_conditions(slip, beta, gravity, passes, load, radius, width, reference=1.0) -> dict:
    """The conditions a drift measure reads (arrays or scalars; beta [rad], load [N], radius and width [m])."""
    return {"slip": slip, "beta": beta, "gravity": gravity, "passes": passes, "load": load, "radius": radius,
            "width": width, "reference": reference}
#: A drifted parameter is held at this fraction of its value or more (1 + rate u >= DRIFT_FLOOR).
DRIFT_FLOOR = 0.05

def _positive(name: str, value: float, *, allow_zero: bool = False) -> None:
    ok = np.isfinite(value) and (value >= 0.0 if allow_zero else value > 0.0)
    if not ok:
        raise WheelsoilInputError(f"{name} = {value!r} is out of range: allowed {name} {'>=' if allow_zero else '>'} 0")


@dataclass(frozen=True)
class SoilParameters:
    """Terramechanics soil parameters (SI; seed 003 Table III gives typical values for dry sand).

    density: bulk density rho [kg/m^3].
    cohesion: c [Pa].
    friction_angle: internal friction angle phi [deg], in (0, 60).
    kc_prime, kphi_prime: Reece's dimensionless pressure--sinkage moduli k'_c, k'_phi [-].
    n0: sinkage exponent [-]; n1: slip-sinkage coefficient, n = n0 + n1 |i| [-].
    shear_modulus_x, shear_modulus_y: shear deformation moduli k_x, k_y [m].
    a1, a2: theta_m = (a1 + a2 i) theta_f [-] (Oida; Wong--Reece).
    c3: exit angle ratio, theta_r = -c3 theta_f [-] (0: the soil does not rebound behind the wheel).
    shear_form: "independent" (classical, Ishigami et al. 2007: each direction's shear stress saturates at the
        full strength on its own displacement) or "resultant" (the CMU lab's model: one strength, mobilised by the
        resultant displacement and shared between the directions as the slip velocity is; module docstring).

    Mechanisms beyond the classical model (see :mod:`wheelsoil.validation.extensions`, which names them):

    soil_flow: mean tangential speed of the soil under the rim as a fraction eta = v_soil / (r omega) of the
        rim speed; it reduces the shear displacement, j_x = r((theta_f - theta)(1 - eta) - (1 - i)(sin
        theta_f - sin theta)) (seed 000 eq. 8). 0: the soil under the wheel is at rest.
    sidewall_scale: factor on Schwanghart's sidewall resistance (seed 003 eq. 19); 0 leaves it out.
    side_bulldozing_scale: factor on the CMU lab's side bulldozing (``R_b.m``, Wong 2008;
        :func:`~.side_forces.side_bulldozing_force`); 0 leaves it out.
    grouser_scale: factor on the grouser forces (seed 003 eq. 20); 0 leaves them out.
    radius_scale: surrogate radius R = radius_scale r of a flexible wheel's flattened contact (seed 000,
        effective radius; Table 3); 1: rigid.
    grouser_tip_fraction: lambda of a grousered wheel's shearing radius r + lambda h: the soil between the
        grousers moves with the wheel and fails at the grouser tips (the lugged-wheel idealisation of Wong's
        Theory of Ground Vehicles; seed 000 measures the soil velocity "near the tip of the grousers"); 0: the
        rim radius.
    cohesion_gravity_exponent: cohesion scales as c (g / 9.81)^kappa (seed 000: soil strength measured at
        reduced gravity is lower); 0: cohesion independent of gravity.
    bulldozing_scale: factor on the bulldozing resistance of the soil pushed ahead of the sinking wheel
        (:func:`bulldozing_force`); 0 leaves it out, as seed 003 does (no bulldozed soil seen in MER drives).
    multipass_k2: compaction per earlier pass: on pass n_p the soil's density and cohesion are 1 + k2 (n_p - 1)
        times the undisturbed soil's (seed 003 eq. 23 with k1 = 1 - k2); 0: every pass meets undisturbed soil.
    kphi_gravity_exponent: epsilon of a frictional pressure modulus that does not scale fully with gravity,
        rho g b k'_phi (g / 9.81)^(-epsilon): 0 is Reece's gravity-explicit form (seed 000 eq. 3), 1 the constant
        K_phi of seed 000 ref. [32] (sinkage independent of gravity at equal load, as Kobayashi et al. observed).
    soil_flow_gravity: soil flow that grows at lower gravity, eta(g) = soil_flow + soil_flow_gravity (1 - g / 9.81)
        (seed 000 sec. 3.3: the soil's tangential velocity under the rim rises as gravity falls; eq. 8);
        eta is held to [0, 0.95]. 0: the soil flow does not depend on gravity.
    """

    density: float = 1600.0
    cohesion: float = 1500.0
    friction_angle: float = 35.0
    kc_prime: float = 100.0
    kphi_prime: float = 1000.0
    n0: float = 1.1
    n1: float = 0.0
    shear_modulus_x: float = 0.015
    shear_modulus_y: float = 0.015
    a1: float = 0.33
    a2: float = 0.11
    c3: float = 0.0
    shear_form: str = "independent"
    soil_flow: float = 0.0
    sidewall_scale: float = 1.0
    side_bulldozing_scale: float = 0.0
    grouser_scale: float = 1.0
    radius_scale: float = 1.0
    grouser_tip_fraction: float = 0.0
    cohesion_gravity_exponent: float = 0.0
    bulldozing_scale: float = 0.0
    multipass_k2: float = 0.0
    kphi_gravity_exponent: float = 0.0
    soil_flow_gravity: float = 0.0
    #: a generic drift (module docstring): field of :data:`DRIFT_FIELDS`, condition of :data:`DRIFT_MEASURES`
    #: and rate [-] of p (1 + rate u); "" / 0 for none
    drift_field: str = ""
    drift_condition: str = ""
    drift_rate: float = 0.0
    #: x_ref of a drift along a condition of :data:`RELATIVE_DRIFTS` [N or m]; unused by the others
    drift_reference: float = 1.0

    def __post_init__(self) -> None:
        for key in ("density", "kphi_prime", "n0", "shear_modulus_x", "shear_modulus_y"):
            _positive(key, getattr(self, key))
        for key in ("cohesion", "kc_prime", "c3", "sidewall_scale", "side_bulldozing_scale", "grouser_scale",
                    "grouser_tip_fraction", "bulldozing_scale", "multipass_k2"):
            _positive(key, getattr(self, key), allow_zero=True)
        if not (0.0 < self.friction_angle < 60.0):
            raise WheelsoilInputError(
                f"friction_angle = {self.friction_angle!r} deg is out of range: allowed 0 < friction_angle < 60")
        if not (np.isfinite(self.soil_flow) and 0.0 <= self.soil_flow < 1.0):
            raise WheelsoilInputError(f"soil_flow = {self.soil_flow!r} is out of range: allowed 0 <= soil_flow < 1")
        if not (np.isfinite(self.radius_scale) and self.radius_scale >= 1.0):
            raise WheelsoilInputError(f"radius_scale = {self.radius_scale!r} is out of range: allowed radius_scale >= 1")
        for key in ("cohesion_gravity_exponent", "kphi_gravity_exponent", "soil_flow_gravity"):
            if not np.isfinite(getattr(self, key)):
                raise WheelsoilInputError(f"{key} = {getattr(self, key)!r} must be finite")
        if not (np.isfinite(self.n1) and self.n0 + min(self.n1, 0.0) > 0.0):
            raise WheelsoilInputError(f"n1 = {self.n1!r} makes the sinkage exponent n0 + n1 |i| non-positive")
        if not (np.isfinite(self.a1) and np.isfinite(self.a2) and 0.0 <= self.a1 < 1.0 and 0.0 <= self.a1 + self.a2 <= 1.0):
            raise WheelsoilInputError(
                f"a1 = {self.a1!r}, a2 = {self.a2!r} put theta_m outside the contact: allowed 0 <= a1 < 1 and "
                f"0 <= a1 + a2 <= 1")

        if self.shear_form not in SHEAR_FORMS:
            raise WheelsoilInputError(f"shear_form = {self.shear_form!r}: allowed {list(SHEAR_FORMS)}")
        if self.drift_field not in ("",) + DRIFT_FIELDS:
            raise WheelsoilInputError(f"drift_field = {self.drift_field!r}: allowed {list(DRIFT_FIELDS)} or ''")
        if self.drift_condition not in ("",) + tuple(DRIFT_MEASURES):
            raise WheelsoilInputError(
                f"drift_condition = {self.drift_condition!r}: allowed {list(DRIFT_MEASURES)} or ''")
        if not np.isfinite(self.drift_rate) or (self.drift_rate and not (self.drift_field and self.drift_condition)):
            raise WheelsoilInputError(f"drift_rate = {self.drift_rate!r} needs a drift_field and a drift_condition")
        _positive("drift_reference", self.drift_reference)

    def to_dict(self) -> dict:
        return asdict(self)

    def drifted(self, name: str, conditions: dict):
        """The value of field ``name`` per condition (:func:`drift_conditions`, without the reference): the soil's own
        unless the drift acts on it, then p max(1 + rate u, :data:`DRIFT_FLOOR`)."""
        value = getattr(self, name)
        if name != self.drift_field or not self.drift_rate:
            return value
        u = DRIFT_MEASURES[self.drift_condition]({**conditions, "reference": self.drift_reference})
        return value * np.maximum(1.0 + self.drift_rate * u, DRIFT_FLOOR)


@dataclass(frozen=True)
class RigidWheel:
    """A rigid cylindrical wheel [m]; grousers of height ``grouser_height`` (0: smooth)."""

    radius: float
    width: float
    grouser_height: float = 0.0
    grouser_count: int = 0

    def __post_init__(self) -> None:
        _positive("radius", self.radius)
        _positive("width", self.width)
        _positive("grouser_height", self.grouser_height, allow_zero=True)
        if self.grouser_height >= self.radius:
            raise WheelsoilInputError(f"grouser_height = {self.grouser_height} must be smaller than the radius {self.radius}")
        if int(self.grouser_count) != self.grouser_count or self.grouser_count < 0:
            raise WheelsoilInputError(f"grouser_count = {self.grouser_count!r} must be a whole number >= 0")


def _conditions(slip, slip_angle, load, gravity, passes=1.0, travel_slip=None):
    """Conditions broadcast to one shape and checked (bad input named with its row and the allowed range), and the
    wheel's speeds in velocity components (:class:`~wheelsoil.slip.WheelSpeeds`): from ``travel_slip`` (the slip
    against the whole travel speed, the CMU rig's) in rows where it is given and finite, else from ``slip`` (along
    the heading). Returns (shape, heading slip, beta [rad], load, gravity, passes, travel slip)."""
    if slip is None and travel_slip is None:
        raise WheelsoilInputError("give the slip along the heading (slip) or against the travel speed (travel_slip)")
    travel_given = travel_slip is not None
    arrays = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (
        np.nan if slip is None else slip, slip_angle, load, gravity, passes, np.nan if travel_slip is None else travel_slip)))
    slip, beta_deg, load, gravity, passes, travel = (a.ravel().copy() for a in arrays)
    has_travel = np.isfinite(travel)
    sideways = np.abs(beta_deg) >= 90.0
    for name, a, ok, allowed in (
        ("slip_angle", beta_deg, np.abs(beta_deg) <= 90.0, "-90 <= slip_angle <= 90 deg"),
        ("travel_slip", travel, ~has_travel | ((travel >= -1.0) & (travel < 1.0)),
         "-1 <= travel_slip < 1 (1: a wheel spinning in place)"),
        ("slip", slip, has_travel | ((slip >= -1.0) & (slip < 1.0) & ~sideways),
         "-1 <= slip < 1 below 90 deg; at 90 deg give travel_slip (the heading slip cannot say how fast the wheel "
         "slides sideways)"),
        ("load", load, (load > 0.0) & (load < np.inf), "0 < load < inf N"),
        ("gravity", gravity, (gravity > 0.0) & (gravity < np.inf), "0 < gravity < inf m/s^2"),
        ("passes", passes, (passes >= 1.0) & (passes < np.inf), "passes >= 1"),
    ):
        bad = ~ok  # NaN fails every comparison: a missing value is out of range (NaN travel_slip means "not given")
        if bad.any():
            k = int(np.argmax(bad))
            raise WheelsoilInputError(f"{name}[{k}] = {float(a[k])!r} is out of range: allowed {allowed}")
    travel = np.where(has_travel, travel, 0.0)
    if travel_given:  # the heading slip the travel slip gives, checked against one given with it
        heading = heading_slip_from_travel(travel, beta_deg)
        both = has_travel & np.isfinite(slip)
        off = both & ~np.isclose(slip, heading, rtol=0.0, atol=1e-9)
        if off.any():
            k = int(np.argmax(off))
            raise WheelsoilInputError(
                f"slip[{k}] = {slip[k]:g} along the heading disagrees with travel_slip[{k}] = {travel[k]:g} at "
                f"{beta_deg[k]:g} deg, which gives {heading[k]:.6g}; give one or make them agree")
        slip = np.where(has_travel, heading, slip)
    if not has_travel.all():  # every row's slip along the heading is in range and below 90 deg here
        travel = np.where(has_travel, travel, travel_slip_from_heading(slip, beta_deg))
    return arrays[0].shape, slip, np.radians(beta_deg), load, gravity, passes, travel


def effective_radius(soil: SoilParameters, wheel: RigidWheel) -> float:
    """The radius the contact integrals use [m]: the shearing radius r + lambda h of a grousered wheel times
    the surrogate-radius scale of a flexible one (both 1 / 0 for the classical rigid wheel)."""
    return (wheel.radius + soil.grouser_tip_fraction * wheel.grouser_height) * soil.radius_scale


def contact_points(theta_f, theta_m, theta_r):
    """The contact's quadrature points (C conditions, 2Q points: the Q of [theta_m, theta_f], then the Q of
    [theta_r, theta_m]): theta [rad], the weights, and their sines and cosines (taken once: every integral of
    :func:`contact_forces` needs them). Each region's nodes cluster at its outer end, theta_f and theta_r, where the
    stress vanishes as a power of the distance (:func:`.quadrature.graded_gauss_on`), with the same nodes in both:
    the rear region's stress is evaluated at the angle mapped linearly onto [theta_m, theta_f] (Wong & Reece, seed 003
    eq. 7), theta_f - (theta - theta_r) / (theta_m - theta_r) (theta_f - theta_m), which at a rear node is the front
    node of the same rank, so the front points' stress serves both (:func:`normal_stress`)."""
    th_front, w_front = graded_gauss_on(theta_f, theta_m)
    th_rear, w_rear = graded_gauss_on(theta_r, theta_m)
    theta = np.concatenate([th_front, th_rear], axis=1)
    weight = np.concatenate([w_front, w_rear], axis=1)
    return theta, weight, np.sin(theta), np.cos(theta)


def normal_stress(k_pressure, n, theta_f, cos_theta):
    """The normal stress sigma [Pa] at the contact points of :func:`contact_points` (``cos_theta`` their cosines):
    k (cos theta_s - cos theta_f)^n (seed 003 eq. 7; ``k_pressure`` [Pa] and the exponent ``n`` per condition) at the
    front points, theta_s = theta, and the same at the rear points of the same rank, whose mapped angle theta_s is
    that front point's (:func:`contact_points`)."""
    q = cos_theta.shape[1] // 2
    front = k_pressure[:, None] * np.clip(cos_theta[:, :q] - np.cos(theta_f)[:, None], 0.0, None) ** n[:, None]
    return np.concatenate([front, front], axis=1)


def contact_forces(soil: SoilParameters, wheel: RigidWheel, sinkage, slip, slip_angle, gravity,
                   extra_pressure=0.0, passes=1.0, vertical_only: bool = False, travel_slip=None, load=np.nan) -> dict:
    """Soil forces on the wheel at a given sinkage (arrays broadcast together; ``slip_angle`` in degrees).

    ``slip`` is along the heading (it sets theta_m, the sinkage exponent and slip drifts); the shear displacements
    take the wheel's speeds in velocity components (:class:`~wheelsoil.slip.WheelSpeeds`), from ``travel_slip``
    (against the whole travel speed) where it is given and finite, else from ``slip``: at 90 deg give
    ``travel_slip`` (:func:`predict` derives ``slip`` from it).

    ``extra_pressure`` [Pa] is added to the normal stress over the whole contact, as seed 002 eq. 17 adds its
    oscillating term A_gamma sin(omega t + Phi) (:mod:`wheelsoil.validation.oscillation`); 0 by default.
    ``passes`` is the wheel's pass number n_p over the same soil (1: undisturbed; see ``multipass_k2``). ``load``
    [N] is read only by a drift along the load (:data:`DRIFT_MEASURES`; :func:`predict` passes it).

    Returns a dict of 1-D arrays: drawbar_pull, lateral_force, vertical_force, torque [N, N m] and the
    contact angles theta_f, theta_m, theta_r [rad]; with ``vertical_only`` just vertical_force (what the
    sinkage solve of :func:`predict` needs, about a third cheaper).
    """
    z, i, beta_deg, g, p_extra, n_p, s_travel, w_load = (a.ravel() for a in np.broadcast_arrays(*(
        np.asarray(v, float) for v in (sinkage, slip, slip_angle, gravity, extra_pressure, passes,
                                       np.nan if travel_slip is None else travel_slip, load))))
    beta = np.radians(beta_deg)
    speeds = wheel_speeds(i, beta_deg, s_travel)
    i = np.where(np.isfinite(s_travel), speeds.heading_slip, i)  # the heading slip the speeds give
    r, b = effective_radius(soil, wheel), wheel.width
    if soil.drift_rate and soil.drift_condition == "load" and not np.isfinite(w_load).all():
        raise WheelsoilInputError("a drift along the load needs the load of every condition (contact_forces load=)")
    at = drift_conditions(i, beta, g, n_p, w_load, wheel.radius, wheel.width)
    drifted = lambda name: soil.drifted(name, at)  # noqa: E731  (the soil's own unless drifting)
    phi = np.radians(drifted("friction_angle"))
    compaction = 1.0 + soil.multipass_k2 * (n_p - 1.0)  # seed 003 eq. 23 with k1 = 1 - k2
    density = soil.density * compaction
    cohesion = soil.cohesion * (g / EARTH_GRAVITY) ** soil.cohesion_gravity_exponent * compaction
    strength_cohesion = (drifted("cohesion") * (g / EARTH_GRAVITY) ** soil.cohesion_gravity_exponent * compaction
                         if soil.drift_field == "cohesion" else cohesion)  # the stresses' cohesion
    theta_f = np.arccos(np.clip(1.0 - z / r, -1.0, 1.0))
    theta_m = np.clip(drifted("a1") + soil.a2 * i, 0.0, 1.0) * theta_f
    theta_r = -soil.c3 * theta_f
    n = drifted("n0") + soil.n1 * np.abs(i)
    kphi = drifted("kphi_prime") * (g / EARTH_GRAVITY) ** (-soil.kphi_gravity_exponent)  # 0: Reece (seed 000 eq. 3)
    k_pressure = (strength_cohesion * drifted("kc_prime") + density * g * b * kphi) * (r / b) ** n
    shear_modulus = drifted("shear_modulus_x")  # k_y = k_x when k_x drifts (tied, as calibrated)
    shear_modulus_y = shear_modulus if soil.drift_field == "shear_modulus_x" else soil.shear_modulus_y

    theta, weight, sin_theta, cos_theta = contact_points(theta_f, theta_m, theta_r)
    sigma = normal_stress(k_pressure, n, theta_f, cos_theta)
    sigma = sigma + p_extra[:, None]  # seed 002 eq. 17 (0 unless an oscillating pressure is asked for)

    # seed 000 eq. 8: the soil under the rim moves with it, faster at lower gravity (sec. 3.3)
    eta = np.clip(soil.soil_flow + soil.soil_flow_gravity * (1.0 - g / EARTH_GRAVITY), 0.0, 0.95)
    jx = tangential_displacement(r, theta_f, theta, speeds, eta, sin_theta)
    strength = np.broadcast_to(strength_cohesion, i.shape)[:, None] + sigma * np.broadcast_to(np.tan(phi), i.shape)[:, None]
    k_x = np.broadcast_to(shear_modulus, i.shape)[:, None]
    resultant = soil.shear_form == "resultant"
    if resultant:
        tau_x, tau_y = resultant_shear(strength, jx, lateral_displacement(r, theta_f, theta, speeds), k_x, speeds, eta,
                                       theta, cos_theta)
    else:
        tau_x = janosi_hanamoto(strength, jx, k_x)
    fz = r * b * np.sum(weight * (tau_x * sin_theta + sigma * cos_theta), axis=1)
    grousers = bool(wheel.grouser_count and wheel.grouser_height > 0.0 and soil.grouser_scale > 0.0)
    if grousers:
        gx, gz, gt = grouser_forces(soil, wheel, theta_f, theta_r, g, density, cohesion)
        fz = fz + soil.grouser_scale * gz
    if vertical_only:
        return {"vertical_force": fz}
    if not resultant:  # the lateral shear is not needed for the sinkage solve
        shear_modulus_y = np.broadcast_to(shear_modulus_y, i.shape)[:, None]
        tau_y = janosi_hanamoto(strength, lateral_displacement(r, theta_f, theta, speeds), shear_modulus_y)

    fx = r * b * np.sum(weight * (tau_x * cos_theta - sigma * sin_theta), axis=1)
    torque = r * r * b * np.sum(weight * tau_x, axis=1)
    f_lateral = r * b * np.sum(weight * tau_y, axis=1)
    if soil.sidewall_scale > 0.0:
        f_lateral = f_lateral + soil.sidewall_scale * sidewall_force(soil, wheel, z, beta, g, density, cohesion)
    if soil.side_bulldozing_scale > 0.0:
        f_lateral = f_lateral + soil.side_bulldozing_scale * side_bulldozing_force(
            soil, wheel, theta_f, theta_r, beta, g, density, cohesion)
    if soil.bulldozing_scale > 0.0:
        fx = fx - soil.bulldozing_scale * bulldozing_force(soil, wheel, z, g, cohesion, density)
    if grousers:
        fx = fx + soil.grouser_scale * gx
        torque = torque + soil.grouser_scale * gt
    return {
        "drawbar_pull": fx,
        "lateral_force": -np.sign(beta) * f_lateral,
        "vertical_force": fz,
        "torque": torque,
        "theta_f": theta_f,
        "theta_m": theta_m,
        "theta_r": theta_r,
    }


def predict(soil: SoilParameters, wheel: RigidWheel, *, slip=None, slip_angle=0.0, load, gravity=EARTH_GRAVITY,
            passes=1.0, travel_slip=None, max_sinkage_ratio: float = 0.95, tolerance: float = 1e-10,
            max_iterations: int = 200, warm_start: SinkageWarmStart | None = None) -> dict:
    """Steady-state forces and sinkage for each condition (arrays broadcast together).

    The wheel's motion: ``slip`` along the heading (architecture), ``travel_slip`` against the whole travel speed
    (the CMU rig's convention), or both (they must agree where both are finite). Below 90 deg either will do; at
    90 deg only the travel slip says how fast the wheel slides sideways against its rim speed. NaN in
    ``travel_slip`` falls back on ``slip`` row by row.

    Solves F_z(z) = W for the sinkage z in (0, max_sinkage_ratio r) (F_z rises with z) by the Illinois
    variant of false position, vectorised over conditions, to |F_z - W| <= tolerance W
    (:func:`~wheelsoil.validation.sinkage_solve.solve_sinkage`; with ``warm_start``, from the roots of the last
    call that passed the same object, as a fit's successive calls do); then evaluates :func:`contact_forces`.
    Returns arrays shaped like the broadcast inputs: sinkage [m], drawbar_pull, lateral_force, vertical_force [N],
    torque [N m], theta_f, theta_m, theta_r [rad], and ``supported`` (False where even z = max_sinkage_ratio r
    cannot carry W; those rows hold that sinkage).
    """
    c = CheckedConditions.of(slip=slip, slip_angle=slip_angle, load=load, gravity=gravity, passes=passes,
                             travel_slip=travel_slip)

    def excess(z, rows):
        vertical = contact_forces(soil, wheel, z, c.slip[rows], c.slip_angle[rows], c.gravity[rows],
                                  passes=c.passes[rows], vertical_only=True, travel_slip=c.travel_slip[rows],
                                  load=c.load[rows])["vertical_force"]
        return vertical - c.load[rows]

    solution = solve_sinkage(excess, c.load, max_sinkage_ratio * wheel.radius, tolerance=tolerance,
                             max_iterations=max_iterations, warm=warm_start)
    sinkage = np.reshape(solution.sinkage, c.shape)
    return {**forces_at_sinkage(soil, wheel, sinkage, c), "sinkage": sinkage,
            "supported": np.reshape(solution.supported, c.shape)}


@dataclass(frozen=True)
class CheckedConditions:
    """Test conditions as :func:`predict` takes them, broadcast, checked and in its internal form, made once
    (:meth:`of`) for several force evaluations at them (:func:`forces_at_sinkage`): ``shape`` of the broadcast
    inputs; per row (flattened): slip along the heading, steering angle [deg], load [N], gravity [m/s^2], pass number
    and the travel slip."""

    shape: tuple
    slip: np.ndarray
    slip_angle: np.ndarray
    load: np.ndarray
    gravity: np.ndarray
    passes: np.ndarray
    travel_slip: np.ndarray

    @classmethod
    def of(cls, *, slip=None, slip_angle=0.0, load, gravity=EARTH_GRAVITY, passes=1.0,
           travel_slip=None) -> "CheckedConditions":
        shape, i, beta, load, g, n_p, s_travel = _conditions(slip, slip_angle, load, gravity, passes, travel_slip)
        return cls(shape, i, np.degrees(beta), load, g, n_p, s_travel)


def forces_at_sinkage(soil: SoilParameters, wheel: RigidWheel, sinkage, conditions: CheckedConditions) -> dict:
    """The forces of :func:`predict` at a given ``sinkage`` [m] instead of the solved one, at ``conditions``
    (:meth:`CheckedConditions.of`, with :func:`predict`'s arguments; the same numbers where ``sinkage`` is its
    root): with F_z(z) = W solved once, a parameter's effect at fixed sinkage and the forces' slope with the sinkage
    give its whole effect through the sinkage it moves (implicit differentiation;
    :func:`wheelsoil.validation.calibration.calibrate`'s Jacobian). Returns arrays shaped like the conditions, the keys
    of :func:`contact_forces`."""
    c = conditions
    z = np.broadcast_to(np.asarray(sinkage, float), c.shape).ravel()
    out = contact_forces(soil, wheel, z, c.slip, c.slip_angle, c.gravity, passes=c.passes, travel_slip=c.travel_slip,
                         load=c.load)
    return {k: np.reshape(v, c.shape) for k, v in out.items()}
