"""Synthetic single-wheel measurements: the classical model plus one hidden mechanism and realistic noise.

Used to test that the discovery workflow names a mechanism it was not told about, recovers its parameter
and measures a positive held-out gain -- and that it finds nothing when nothing is hidden.
"""

from dataclasses import replace

import numpy as np

from .extensions import BASELINE_OFF
from .measured import Measurements
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
}


def conditions(slips=(0.05, 0.15, 0.3, 0.45, 0.6, 0.75), slip_angles=(0.0, 10.0, 20.0, 30.0),
               loads=(60.0, 120.0), gravities=(9.81, 1.62)):
    """The full factorial of test conditions (slip, slip angle [deg], load [N], gravity [m/s^2])."""
    grid = np.array(np.meshgrid(slips, slip_angles, loads, gravities, indexing="ij")).reshape(4, -1)
    return {"slip": grid[0], "slip_angle": grid[1], "load": grid[2], "gravity": grid[3]}


def draw_hidden_effect(rng: np.random.Generator, names=None) -> tuple[str | None, dict]:
    """A mechanism (uniformly among ``names``, default all; None means nothing hidden) and its parameters."""
    names = list(HIDDEN_RANGES if names is None else names)
    name = names[int(rng.integers(len(names)))]
    if name is None:
        return None, {}
    return name, {k: float(rng.uniform(*bounds)) for k, bounds in HIDDEN_RANGES[name].items()}


def synthetic_measurements(hidden: dict, rng: np.random.Generator, *, soil: SoilParameters = TRUE_SOIL,
                           wheel: RigidWheel = TEST_WHEEL, cond: dict | None = None, noise: float = 0.03,
                           relative_noise: float = 0.02) -> Measurements:
    """Measurements from ``soil`` with the ``hidden`` parameters changed, plus Gaussian noise of ``noise``
    times each response's spread and ``relative_noise`` times its value (the scatter of repeated rig
    tests)."""
    cond = cond or conditions()
    truth = replace(soil, **hidden)
    out = predict(truth, wheel, **cond)
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
        notes=f"hidden: {hidden or 'nothing'}",
    )

