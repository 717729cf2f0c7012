"""The checks a CMU trial file's rows must pass before any work (issue 36, bad input): slip and steering angle in the
rig's range, and the rig's speeds, where the file records them, telling a braked wheel from a dragged one. Each error
names the file, the data row and the column."""

from __future__ import annotations

import numpy as np

from wheelsoil.errors import WheelsoilInputError

#: The rig's ranges: column -> (lowest, highest, unit as printed).
RIG_RANGES = {"slip": (-1.0, 1.0, ""), "steering_angle": (-90.0, 90.0, " deg")}


def check_cmu_rows(t, path) -> None:
    """Refuse a CMU file (its :class:`~.measured.Table` ``t``, read from ``path``) whose rows the rig cannot have
    made: a slip or steering angle out of :data:`RIG_RANGES`, or rig speeds that disagree with the slip
    (:func:`check_rig_speeds`)."""
    for key, (lo, hi, unit) in RIG_RANGES.items():
        values = np.asarray(t.columns[key], float)
        bad = np.flatnonzero(~((values >= lo) & (values <= hi)))
        if bad.size:
            raise WheelsoilInputError(f"{path}: column {key!r} holds {values[bad[0]]:g}{unit} in data row "
                                      f"{bad[0] + 1} ({bad.size} such row(s)); the rig's {key} lies in "
                                      f"[{lo:g}, {hi:g}]{unit}")
    check_rig_speeds(t, path, np.asarray(t.columns["slip"], float))


def check_rig_speeds(t, path, slip: np.ndarray) -> None:
    """Where a file records the rig's speeds (``rim_speed``, ``carriage_speed``), they are what tells a braked wheel
    (its rim turning slower than the carriage moves) from a dragged one (its rim at rest, slip -1): a braking row
    (slip < 0) needs both, and a dragged row's rim must be at rest and a braked row's not. A row that lacks them or
    disagrees is refused, naming the file, the data row and the column. A file with neither column is read by its
    slip alone."""
    present = [k for k in ("rim_speed", "carriage_speed") if k in t.columns]
    if not present:
        return
    if len(present) == 1:
        raise WheelsoilInputError(f"{path}: has the column {present[0]!r} but not "
                                  f"{({'rim_speed', 'carriage_speed'} - set(present)).pop()!r}: the rig's speeds come "
                                  "as a pair (together they tell a braked wheel from a dragged one)")
    braking = slip < 0.0
    for key in present:
        bad = np.flatnonzero(braking & ~np.isfinite(np.asarray(t.columns[key], float)))
        if bad.size:
            raise WheelsoilInputError(
                f"{path}: column {key!r} is empty in braking data row {bad[0] + 1} ({bad.size} such row(s)); a braking "
                "row needs the rim and carriage speeds that tell a braked wheel (its rim turning slower than the "
                "carriage) from a dragged one (its rim at rest, slip -1)")
    rim = np.asarray(t.columns["rim_speed"], float)
    wrong = np.flatnonzero(braking & ((slip <= -1.0) != (rim == 0.0)))
    if wrong.size:
        k = wrong[0]
        raise WheelsoilInputError(
            f"{path}: data row {k + 1} has slip {slip[k]:g} with column 'rim_speed' {rim[k]:g} m/s ({wrong.size} such "
            "row(s)): a dragged wheel (slip -1) has its rim at rest, a braked one (-1 < slip < 0) a turning rim")
