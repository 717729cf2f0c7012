"""The Jacobian of a fit's normalised residuals, differentiated through the sinkage instead of around it.

Every model response R (drawbar pull, lateral force, torque, and the sinkage itself) depends on a soil parameter p
directly and through the sinkage z that vertical equilibrium F_z(z, p) = W sets. By the implicit function theorem

    dz/dp = -(dF_z/dp)_z / (dF_z/dz)_p,        dR/dp = (dR/dp)_z + (dR/dz)_p dz/dp,

so one column needs the forces at the solved sinkage with p stepped (no solve) and, once for all columns, the forces
at a slightly larger sinkage. A forward difference of the whole prediction instead re-solves F_z(z) = W at every
stepped parameter (about three force evaluations each from a warm start) and inherits the solve's tolerance (1e-10 of
W) divided by the step (1e-4): noise of about 1e-6 in every column, which this form does not have. Rows where even
the deepest sinkage allowed cannot carry W (``supported`` False) keep that sinkage: dz/dp = 0 there, as a forward
difference would find.

The parameter steps are scipy's for its two-point scheme (``scipy.optimize.approx_derivative``): h = rel_step
sign(x) max(1, |x|), reversed where it would leave the bounds, and the step actually taken, (x + h) - x. The sinkage
step is :data:`SINKAGE_STEP` of the sinkage (the forces are smooth in z and no solve adds noise, so a step near the
square root of the machine epsilon is the accurate one).
"""

from collections.abc import Callable

import numpy as np

from wheelsoil.errors import WheelsoilInputError

from .measured import Measurements
from .terramechanics import CheckedConditions, RigidWheel, SoilParameters, forces_at_sinkage

#: The model's responses with a force's form (the sinkage is the fourth, :data:`.calibration.RESPONSES`).
FORCES = ("drawbar_pull", "lateral_force", "torque")
#: The sinkage step of dR/dz and dF_z/dz, relative to the sinkage.
SINKAGE_STEP = 1e-7


def forward_steps(x: np.ndarray, lower: np.ndarray, upper: np.ndarray, rel_step: float) -> np.ndarray:
    """The step of each coordinate of ``x`` for a forward difference inside [lower, upper] (scipy's two-point rule)."""
    h = rel_step * np.where(x >= 0.0, 1.0, -1.0) * np.maximum(1.0, np.abs(x))
    outside = (x + h > upper) | (x + h < lower)
    h = np.where(outside & (x - h >= lower) & (x - h <= upper), -h, h)
    return (x + h) - x


def conditions_of(data: Measurements, rows: np.ndarray) -> dict:
    """The conditions of ``data``'s ``rows`` as :func:`~.terramechanics.predict` takes them."""
    return {"slip": data.slip[rows], "slip_angle": data.slip_angle[rows], "load": data.load[rows],
            "gravity": data.gravity[rows], "passes": data.passes[rows], "travel_slip": data.travel_slip[rows]}


def wheel_of(key) -> RigidWheel:
    """The wheel of a (radius, width, grouser height, grouser count) key."""
    return RigidWheel(radius=key[0], width=key[1], grouser_height=key[2], grouser_count=int(key[3]))


def model_jacobian(soil_of: Callable[[np.ndarray], SoilParameters], x: np.ndarray, steps: np.ndarray,
                   data: Measurements, predictions: list) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """d(response)/d(x_k) for every row of ``data`` and coordinate k (``soil_of(x)``: the soil at fit coordinates x;
    ``steps``: :func:`forward_steps`; ``predictions``: (wheel key, row mask, :func:`~.terramechanics.predict`'s output)
    per wheel at x). Returns {response: (rows, k) array} and a mask of the coordinates whose stepped soil is outside
    the model's domain (their columns are left zero)."""
    soil = soil_of(x)
    count = len(data)
    derivative = {q: np.zeros((count, x.size)) for q in FORCES + ("sinkage",)}
    stepped = []
    invalid = np.zeros(x.size, bool)
    for k in range(x.size):
        xk = x.copy()
        xk[k] += steps[k]
        try:
            stepped.append(soil_of(xk))
        except WheelsoilInputError:
            stepped.append(None)
            invalid[k] = True
    for key, rows, pred in predictions:
        wheel, cond = wheel_of(key), CheckedConditions.of(**conditions_of(data, rows))  # checked once for all
        z = np.asarray(pred["sinkage"], float)
        supported = np.asarray(pred["supported"], bool)
        dz = SINKAGE_STEP * z
        deeper = forces_at_sinkage(soil, wheel, z + dz, cond)
        slope_fz = (deeper["vertical_force"] - pred["vertical_force"]) / dz
        slope = {q: (deeper[q] - pred[q]) / dz for q in FORCES}
        for k, soil_k in enumerate(stepped):
            if soil_k is None:
                continue
            try:
                moved = forces_at_sinkage(soil_k, wheel, z, cond)
            except WheelsoilInputError:
                invalid[k] = True
                continue
            dz_dp = np.where(supported, -(moved["vertical_force"] - pred["vertical_force"]) / steps[k] / slope_fz, 0.0)
            for q in FORCES:
                derivative[q][rows, k] = (moved[q] - pred[q]) / steps[k] + slope[q] * dz_dp
            derivative["sinkage"][rows, k] = dz_dp
    return derivative, invalid
