"""The testbed's statistics of its recorded series: the steady-state verdict on the rows (:func:`detect_from_rows`,
what a running testbed asks once per pitch and what a stored ``series.csv`` can be asked again) and the run's summary
over the window it found (:func:`summarise_window`). NumPy only; :mod:`.steady` holds the detector itself."""

from __future__ import annotations

import math

import numpy as np

from .kinematics import rig_command
from .rig import batch_rate
from .run_summary import SERIES_UNITS, STEADY_CHECKED, STEADY_QUANTITIES, QuantityStats, RunSummary
from .steady import SteadyState, detect_steady_state, window_stats


def detect_from_rows(rows: dict, *, slip: float, load: float, angular_velocity: float, average_time: float,
                     steady_tolerance: float, slip_tolerance: float, radius: float, pitch: float,
                     mean_diameter: float, sample_interval: float, start: float, period_pitches: int = 1,
                     truncation_search: float = 0.5, drift_confidence: float = 0.0) -> SteadyState:
    """The testbed's steady-state verdict on its series ``rows`` (name -> per-sample values, the columns of
    :data:`SERIES_UNITS`) -- what a running testbed asks once per pitch, and what a stored run's ``series.csv``
    can be asked again (``docs/steady_replay.py``).

    slip, load [N], angular_velocity [rad/s] (the reference spin), average_time [s], steady_tolerance,
    slip_tolerance: the rig's settings (:class:`~.rig.TestbedSpec`); radius [m], pitch [rad] (the batch:
    :func:`~.rig.statistics_pitch`) and
    period_pitches (its whole period in batches): the wheel's; mean_diameter [m]: the soil's mean particle
    diameter (half of it is the sinkage's floor); sample_interval [s]; start [s]: earliest window start.
    The floors of the relative tolerance are 5 % of W for the forces, 5 % of W r for the torque.
    truncation_search, drift_confidence: see :func:`~.steady.detect_steady_state`.
    """
    series = {q: np.asarray(rows[q], float) for q in STEADY_CHECKED}
    floors = {"drawbar_pull": 0.05 * load, "lateral_force": 0.05 * load, "vertical_force": 0.05 * load,
              "torque": 0.05 * load * radius, "sinkage": 0.5 * mean_diameter}
    t = np.asarray(rows["t"], float)
    # the tread angle from its per-sample spin, and the speed the tread slip is taken against (recorded; a
    # series stored before it was, from runs that only drove, recovered from i_t = 1 - v_x / (r omega_t))
    omega_t = np.asarray(rows["tread_omega"], float)
    if "slip_speed" in rows:
        heading_speed = np.asarray(rows["slip_speed"], float)
    else:
        heading_speed = (1.0 - np.asarray(rows["tread_slip"], float)) * radius * omega_t
    angle = np.cumsum(omega_t * sample_interval)
    rate = batch_rate(slip, angular_velocity, radius)
    # a dragged wheel does not turn: its batches are the angles it would roll through at the speed its slip is
    # taken against (batch_rate)
    batch_angle = angle if rig_command(slip, angular_velocity, radius)[0] > 0.0 else \
        np.cumsum(heading_speed * sample_interval) / radius
    min_pitches = int(math.ceil(average_time * rate / pitch))
    return detect_steady_state(
        t, series, tread_angle=angle, batch_angle=batch_angle, travel_speed=heading_speed, radius=radius,
        pitch=pitch, start=start,
        min_pitches=min_pitches, tolerance=steady_tolerance, floors=floors, slip_target=slip,
        slip_tolerance=slip_tolerance, sample_interval=sample_interval, period_pitches=period_pitches,
        truncation_search=truncation_search, drift_confidence=drift_confidence)


def summarise_window(rows: dict, state: SteadyState, k0: int, k1: int, *, period_pitches: int, sample_interval: float,
                     pitch: float, commanded_slip: float, commanded_slip_angle: float) -> RunSummary:
    """The run's summary over samples ``k0:k1`` of ``rows`` (the steady window ``state`` found, or the last window
    averaged for information): each quantity's mean and fluctuation, with the detector's standard error, interval and
    drift where the window is whole pitches; ``sample_interval`` [s], ``pitch`` [rad], the rig's command [-, deg]."""
    t = rows["t"]
    quantities = {}
    for q in STEADY_QUANTITIES:
        if q not in rows:  # a series recorded before the quantity was (the force balance's): no statistics
            continue
        y = rows[q][k0:k1]
        st = state.stats.get(q)
        if st is None and len(state.bounds) > 2 and (state.bounds[-1], state.bounds[0]) == (k0, k1):
            # batch means over the same pitches
            st = window_stats(np.asarray(rows[q], float), state.bounds, period=period_pitches)
        st = st or {}
        quantities[q] = QuantityStats(
            mean=float(np.mean(y)), std=float(np.std(y)), sem=float(st.get("sem", math.nan)),
            ci95=float(st.get("ci95", math.nan)), dof=float(st.get("dof", math.nan)),
            drift=float(st.get("drift", math.nan)), drift_sem=float(st.get("drift_sem", math.nan)),
            units=SERIES_UNITS[q],
            zero_within_noise=bool(st["zero_within_noise"]) if "zero_within_noise" in st else None)
    ts = state.stats.get("tread_slip")
    if ts is not None:
        quantities["tread_slip"] = QuantityStats(**{k: float(v) for k, v in ts.items()}, units="1")
    else:
        y = rows["tread_slip"][k0:k1]
        quantities["tread_slip"] = QuantityStats(float(np.mean(y)), float(np.std(y)), units="1")
    return RunSummary(
        steady=bool(state.steady), window=(float(t[k0] - sample_interval), float(t[k1 - 1])),
        samples=int(k1 - k0), pitches=int(state.pitches), pitch_deg=math.degrees(pitch),
        period_pitches=period_pitches, reasons=tuple(state.reasons), commanded_slip=commanded_slip,
        commanded_slip_angle=commanded_slip_angle, **quantities)
