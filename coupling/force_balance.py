"""The wheel's vertical force balance, recorded at every sample (issue 35 item 1).

Over a sample interval T the wheel's vertical momentum P_z (its free nodes' m v and the hub's whole mass times its
velocity, :meth:`~wheelsoil.flexwheel.structure.Structure.linear_momentum`) changes by the impulses of what acts on
it, so its rate

    dP_z / dt = F_applied + L + D + R + S + G

with F_applied the soil's vertical force as the wheel's sub-steps applied it (for a flexible wheel the contact's
linearised force f - k (x - x_a), which differs from the force the contact evaluated and reports as
``vertical_force`` by how far the nodes move over the DEM step; for a rigid wheel the same), L the rig's load on the
free slide (-(W - m g) once released), D the slide's damper (-c v_z), R the held slide's reaction (while the wheel is
lowered at a prescribed speed), S the structural damping's resultant and G the weight -m g. The residual of that sum
against the momentum's rate is round-off when every force the integrator applied is in the record: a residual above
round-off is a force the record misses. Since L + G = -W once released, over a steady window

    F_applied = W + dP_z/dt - D - S,

so a soil force short of the load W is read off as the slide's damper holding part of it (a wheel still sinking),
the structural damping's resultant, or a wheel still accelerating.
"""

from __future__ import annotations

import numpy as np

#: The balance's columns in the testbed's series (units N), in the order of the sum above, then its two sides.
BALANCE_UNITS = {
    "vertical_force_applied": "N",
    "rig_load": "N",
    "slide_damper": "N",
    "slide_reaction": "N",
    "structural_damping": "N",
    "weight": "N",
    "momentum_rate": "N",
    "balance_residual": "N",
}


def balance_row(account, momentum_change: np.ndarray, applied_force: np.ndarray, slide_damper: float,
                weight: np.ndarray) -> dict:
    """The balance's columns (:data:`BALANCE_UNITS`, vertical components [N]) over one interval.

    account: the structure's :class:`~wheelsoil.flexwheel.structure.MomentumAccount` of the interval (its impulses
        [N s] and duration [s]); momentum_change: the change of its linear momentum [kg m/s]; applied_force: the
        rig's force on the hub over the interval [N] (held constant); slide_damper: the damper's part of it [N];
        weight: the structure's weight [N] (3-vectors except ``slide_damper``).
    """
    t = account.duration
    if not t > 0.0:
        return {k: float("nan") for k in BALANCE_UNITS}
    row = {
        "vertical_force_applied": account.contact[2] / t,
        "rig_load": applied_force[2] - slide_damper,
        "slide_damper": slide_damper,
        "slide_reaction": account.reaction[2] / t,
        "structural_damping": account.damping[2] / t,
        "weight": weight[2],
        "momentum_rate": momentum_change[2] / t,
    }
    forces = sum(row[k] for k in ("vertical_force_applied", "rig_load", "slide_damper", "slide_reaction",
                                  "structural_damping", "weight"))
    row["balance_residual"] = row["momentum_rate"] - forces
    return {k: float(v) for k, v in row.items()}
