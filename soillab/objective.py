"""The calibration objective: how far a candidate soil's lab results are from the CMU sand's own measurements.

objective = mean over the plates' points of (ln p_DEM - ln p_measured)^2 + ((repose_DEM - repose_sand) / 2 deg)^2

* the plates' points are the 60 and 100 mm plates at 5, 10, 15, 20 and 25 mm of sinkage where both the DEM curve and
  the mean of the sand's measured trials reach (the 100 mm plates were measured to 17--22 mm, so their 25 mm point
  drops out: 9 points); a log error weighs a factor of two the same at 5 and 25 mm;
* the repose error is in units of 2 deg, the spread of the draw-down angle over packings (``docs/soillab``).

Fixed before any candidate ran (``docs/soillab_calibration.py``); plain NumPy on the stored curves, so a
calibration's choice can be checked again from its candidate files.
"""

from __future__ import annotations

import numpy as np

from wheelsoil.parameters import cmu_k10

#: Sinkages [m] at which the plates' pressures are compared.
SINKAGES = (0.005, 0.01, 0.015, 0.02, 0.025)
#: The repose error's unit [deg].
REPOSE_UNIT = 2.0


def score(row: dict) -> dict:
    """``row`` with ``plate_points``, ``plate_log_mse``, ``repose_error`` and ``objective`` set from its stored
    ``plates`` (diameter -> ``simulated_Pa`` and ``measured_Pa`` at :data:`SINKAGES`) and ``repose_deg``."""
    errors = []
    for plate in row["plates"].values():
        sim, mea = np.asarray(plate["simulated_Pa"], float), np.asarray(plate["measured_Pa"], float)
        both = np.isfinite(sim) & np.isfinite(mea) & (sim > 0) & (mea > 0)
        errors += list(np.log(sim[both] / mea[both]))
    row["plate_points"] = len(errors)
    row["plate_log_mse"] = float(np.mean(np.square(errors)))
    row["repose_error"] = ((row["repose_deg"] - cmu_k10.ANGLE_OF_REPOSE) / REPOSE_UNIT) ** 2
    row["objective"] = row["plate_log_mse"] + row["repose_error"]
    return row


def best(rows: list[dict]) -> dict:
    """The candidate of least objective (each rescored from its stored curves)."""
    if not rows:
        raise ValueError("no candidate to choose from")
    return min((score(dict(r)) for r in rows), key=lambda r: r["objective"])
