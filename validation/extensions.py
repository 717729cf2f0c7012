"""Named physical mechanisms that extend the classical wheel--soil model, each with its parameters.

The classical model (:data:`BASELINE`) is Wong--Reece normal stress with Reece's gravity-explicit pressure
and a constant theta_m / theta_f ratio, Janosi--Hanamoto shear along and across the wheel, and sinkage from
vertical equilibrium (:mod:`wheelsoil.validation.terramechanics`). Its calibrated parameters are
:data:`BASELINE_FREE`; every other mechanism is switched off (:data:`BASELINE_OFF`).

An :class:`Extension` switches one mechanism on and frees its parameters. Each names the equation it comes
from (seeds 000 and 003 in ``../shared/seeds``) and says which data can reveal it (``applies``): a
mechanism that acts only under steering, on grousers or when gravity changes cannot be found in data
without those.
"""

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .terramechanics import DRIFT_FIELDS, DRIFT_MEASURES, RELATIVE_DRIFTS, drift_conditions


@dataclass(frozen=True)
class Parameter:
    """A free model parameter: a field of :class:`~wheelsoil.validation.terramechanics.SoilParameters`,
    its bounds (the physical range searched) and, for positive scale parameters, a log transform for the fit.

    sign: for a mechanism's parameter whose search range spans both sides of its off value, the side the
    mechanism's own description requires (+1: above the off value, -1: below; 0: either). A fit on the other
    side is the data asking for the opposite physics, and is not accepted as that mechanism.
    """

    name: str
    lower: float
    upper: float
    log: bool = False
    unit: str = "-"
    sign: int = 0

    def to_fit(self, value: float) -> float:
        return float(np.log(value)) if self.log else float(value)

    def from_fit(self, x: float) -> float:
        return float(np.exp(x)) if self.log else float(x)

    @property
    def fit_bounds(self) -> tuple[float, float]:
        return (self.to_fit(self.lower), self.to_fit(self.upper))

    def at_bound(self, value: float, rel: float = 1e-3) -> str | None:
        """"lower" or "upper" when ``value`` lies within ``rel`` of the fit range of a bound, else None."""
        lo, hi = self.fit_bounds
        x = self.to_fit(max(value, self.lower) if self.log else value)
        if x - lo <= rel * (hi - lo):
            return "lower"
        if hi - x <= rel * (hi - lo):
            return "upper"
        return None


@dataclass(frozen=True)
class Extension:
    """One mechanism: its name, what it is, the equation it implements, its parameters and their values
    when it is off, and a test of whether a dataset can show it."""

    name: str
    mechanism: str
    source: str
    parameters: tuple[Parameter, ...]
    off: dict
    applies: Callable
    #: the test conditions through which the mechanism acts (its effect grows with them); a name needs the data
    #: to prefer the mechanism's form to a generic drift of a classical parameter with the same condition
    #: (:func:`drift_rival`; :mod:`.discovery`)
    acts_through: tuple[str, ...] = ()
    #: the (field, condition) drifts that state the mechanism's own physics (slip-sinkage *is* n0 rising with
    #: slip): these are not rivals of any mechanism
    drifts: tuple[tuple[str, str], ...] = ()


#: Parameters the classical model is calibrated on: every soil parameter of its equations that force and
#: sinkage data can inform (the shear moduli are tied, k_y = k_x, as in Artemis). Not free: the bulk density,
#: which is measured; the exit-angle ratio c3 (0, the soil does not rebound; seed 003 Table I); and the slip
#: terms n1 and a2, which are mechanisms of their own (:data:`EXTENSIONS`). Bounds: the ranges of Wong's and
#: seed 003's tables for dry sand to clayey soil, widened.
BASELINE_FREE = (
    Parameter("kphi_prime", 10.0, 1e5, log=True),
    Parameter("kc_prime", 0.0, 2000.0),
    Parameter("cohesion", 0.0, 2e4, unit="Pa"),
    Parameter("friction_angle", 15.0, 50.0, unit="deg"),
    Parameter("shear_modulus_x", 5e-4, 0.2, log=True, unit="m"),
    Parameter("n0", 0.3, 2.0),
    Parameter("a1", 0.05, 0.6),
)

#: The classical model: every extension off.
BASELINE_OFF = {
    "n1": 0.0,
    "a2": 0.0,
    "soil_flow": 0.0,
    "sidewall_scale": 0.0,
    "grouser_scale": 0.0,
    "radius_scale": 1.0,
    "grouser_tip_fraction": 0.0,
    "cohesion_gravity_exponent": 0.0,
    "bulldozing_scale": 0.0,
    "multipass_k2": 0.0,
    "kphi_gravity_exponent": 0.0,
    "soil_flow_gravity": 0.0,
}


def _varies(values, tol: float = 1e-9) -> bool:
    values = np.asarray(values, float)
    return values.size > 1 and float(np.nanmax(values) - np.nanmin(values)) > tol


EXTENSIONS = {
    e.name: e
    for e in (
        Extension(
            "slip_sinkage", "sinkage exponent rising with slip: the wheel digs in as it slips",
            "seed 003 eq. 5, seed 000 eq. 4: n = n0 + n1 |i|",
            (Parameter("n1", -0.3, 1.5, sign=1),), {"n1": 0.0},
            lambda d: _varies(d.slip), ("slip",), (("n0", "slip"),),
        ),
        Extension(
            "theta_m_slip", "angle of maximum normal stress moving forward with slip",
            "seed 003 eq. 8 (Oida; Wong--Reece): theta_m = (a1 + a2 i) theta_f",
            (Parameter("a2", -0.3, 0.6, sign=1),), {"a2": 0.0},
            # linear in the signed slip: a1 drifting with it is this mechanism, not a rival
            lambda d: _varies(d.slip), ("slip", "signed_slip"), (("a1", "slip"), ("a1", "signed_slip")),
        ),
        Extension(
            "soil_flow", "soil under the rim carried along with it, reducing the shear displacement",
            "seed 000 eq. 8: j = r((theta_f - theta)(1 - v_soil / (r omega)) - (1 - i)(sin theta_f - sin theta))",
            (Parameter("soil_flow", 0.0, 0.9),), {"soil_flow": 0.0},
            lambda d: _varies(d.slip), ("slip",),
        ),
        Extension(
            "sidewall", "passive soil resistance on the wheel's sidewall when it slides sideways",
            "seed 003 eqs. 17--19 (Schwanghart; modified Terzaghi factors)",
            (Parameter("sidewall_scale", 0.0, 10.0),), {"sidewall_scale": 0.0},
            lambda d: bool(np.any(np.abs(d.slip_angle) > 0)) and np.isfinite(d.responses["lateral_force"]).any(),
            ("slip_angle",),
        ),
        Extension(
            "grouser", "passive earth pressure on the grousers in the soil",
            "seed 003 eq. 20 (Wong 2001)",
            (Parameter("grouser_scale", 0.0, 10.0),), {"grouser_scale": 0.0},
            lambda d: bool(np.any((d.grouser_height > 0) & (d.grouser_count > 0))),
        ),
        Extension(
            "grouser_tip_radius", "soil trapped between grousers: the shearing surface at the grouser tips",
            "lugged-wheel idealisation (Wong, Theory of Ground Vehicles): radius r + lambda h",
            (Parameter("grouser_tip_fraction", 0.0, 1.5),), {"grouser_tip_fraction": 0.0},
            lambda d: bool(np.any(d.grouser_height > 0)),
        ),
        Extension(
            "surrogate_radius", "flexible wheel flattening: a larger effective radius in the contact",
            "seed 000 sec. 4 (effective radius R > r, Table 3; eq. 19 without the periodic part)",
            (Parameter("radius_scale", 1.0, 2.0),), {"radius_scale": 1.0},
            lambda d: True,
        ),
        Extension(
            "bulldozing", "soil pushed ahead of the sinking wheel: a passive-pressure resistance against travel",
            "Bekker / Hegedus 1960 (seed 002 ref. 7; named in seed 003 sec. 3.3.4): R_b = b (0.67 c z K_pc + "
            "0.5 gamma z^2 K_pgamma)",
            (Parameter("bulldozing_scale", 0.0, 3.0),), {"bulldozing_scale": 0.0},
            lambda d: np.isfinite(d.responses["drawbar_pull"]).any(),
        ),
        Extension(
            "multipass", "soil compacted by the earlier passes of the wheel (or of the wheels ahead of it)",
            "seed 003 eq. 23 (Senatore & Sandu 2011): gamma_n = gamma_0 (k1 + k2 n_p), cohesion alike, with k1 = 1 - k2 "
            "(undisturbed soil on the first pass)",
            (Parameter("multipass_k2", 0.0, 1.0),), {"multipass_k2": 0.0},
            # compaction raises density and cohesion; density enters the classical stresses only as rho k'_phi
            lambda d: _varies(d.passes), ("passes",), (("cohesion", "passes"), ("kphi_prime", "passes")),
        ),
        Extension(
            "gravity_cohesion", "soil strength that falls with gravity (cohesion ~ g^kappa)",
            "seed 000 sec. 5: measured soil strength is lower at reduced gravity",
            (Parameter("cohesion_gravity_exponent", -1.0, 3.0, sign=1),), {"cohesion_gravity_exponent": 0.0},
            lambda d: _varies(d.gravity), ("gravity",), (("cohesion", "gravity"),),
        ),
        Extension(
            "gravity_pressure", "frictional pressure modulus that does not scale fully with gravity: sinkage "
            "nearly independent of gravity at equal load",
            "seed 000 eqs. 3 and 5: (K_c + K_phi g) with K_phi = rho k'_phi / b^(n-1) held constant (ref. [32]) "
            "against Reece's gravity-explicit form; here rho g b k'_phi (g / g0)^-epsilon",
            (Parameter("kphi_gravity_exponent", -0.5, 1.5, sign=1),), {"kphi_gravity_exponent": 0.0},
            # with k'_c free, two gravity levels fix (c k'_c + rho g b k'_phi g^-eps) at both exactly: a third
            # level is needed to tell the exponent from the split between k'_c and k'_phi
            lambda d: np.unique(np.round(np.asarray(d.gravity, float), 6)).size >= 3,
            ("gravity",), (("kphi_prime", "gravity"),),
        ),
        Extension(
            "gravity_soil_flow", "soil under the rim carried along faster at lower gravity, lowering traction",
            "seed 000 sec. 3.3 and eq. 8: eta(g) = eta_g (1 - g / g0) in j = r((theta_f - theta)(1 - eta) - ...)",
            (Parameter("soil_flow_gravity", 0.0, 0.9),), {"soil_flow_gravity": 0.0},
            lambda d: _varies(d.gravity), ("gravity",),
        ),
    )
}

#: Every (field, condition) drift that a catalogue mechanism states: not a rival.
CATALOGUE_DRIFTS = frozenset(d for e in EXTENSIONS.values() for d in e.drifts)
#: The range searched for a drift's rate (p (1 + rate u), u of order 1 at the largest condition).
DRIFT_RATE = Parameter("drift_rate", -1.5, 1.5)


def drift_rival(field: str, condition: str) -> Extension:
    """A generic rival, not a mechanism: the classical parameter ``field`` varying linearly with ``condition``
    (:data:`~.terramechanics.DRIFT_MEASURES`). Fitted in place of a mechanism: if it explains the residual better
    (:data:`~.discovery.RIVAL_MARGIN`), the data prefer another form to the mechanism's."""
    return Extension(f"{field} ~ {condition}",
                     f"{field.replace('_x', '').replace('_', ' ')} varying linearly with "
                     f"{condition.replace('_', ' ')} (a generic form outside the catalogue)",
                     "generic drift p (1 + rate u), not a mechanism", (DRIFT_RATE,), {"drift_rate": 0.0},
                     lambda d: True)


def varied_conditions(data) -> tuple[str, ...]:
    """The conditions of :data:`~.terramechanics.DRIFT_MEASURES` whose measure varies over ``data``'s rows (a drift
    along a constant condition is the classical parameter again), each once: a condition whose measure equals an
    earlier one's on every row (the signed slip on rows that all drive is |slip|) is left out, its drift being the
    same fit."""
    rows = drift_conditions(*(np.asarray(v, float) for v in (data.slip, np.radians(data.slip_angle), data.gravity,
                                                              data.passes, data.load, data.radius, data.width)))
    kept, measures = [], []
    for c, measure in DRIFT_MEASURES.items():
        u = np.broadcast_to(measure({**rows, "reference": drift_reference(data, c)}), np.shape(rows["slip"]))
        if np.ptp(u) > 0.0 and not any(np.array_equal(u, m) for m in measures):
            kept.append(c)
            measures.append(u)
    return tuple(kept)


def drift_reference(data, condition: str) -> float:
    """x_ref of a drift along ``condition`` over ``data`` (the median of the rows; 1 for the conditions whose
    measure needs none)."""
    if condition not in RELATIVE_DRIFTS:
        return 1.0
    return float(np.median(np.asarray(getattr(data, condition), float)))


def drift_rivals(ext: Extension, conditions=None) -> list[tuple[str, str]]:
    """The (field, condition) drifts that rival ``ext``: every classical field drifting with each of
    ``conditions`` (those the data vary, :func:`varied_conditions`; by default the ones the mechanism acts
    through), except the drifts that are catalogue mechanisms. A mechanism is named only when it beats the drifts
    along every condition the data vary, not only those it acts through: an effect that follows the load must not
    be read as the nearest mechanism that acts through gravity."""
    conditions = ext.acts_through if conditions is None else conditions
    return [(f, c) for c in conditions for f in DRIFT_FIELDS if (f, c) not in CATALOGUE_DRIFTS]
