"""Ask the steady-state detector again about stored runs: when would each have stopped, over which window?

A run's ``series.csv`` holds every sample the detector saw, and its ``summary.json`` when the drive was held,
so the detector's checks can be replayed exactly as :class:`wheelsoil.coupling.testbed.Testbed` makes them
(:func:`wheelsoil.coupling.run_statistics.detect_from_rows`, first one pitch plus ``average_time`` after the hold,
then once per pitch, ``steady_checks`` steady verdicts in a row ending the run) -- with the detector of the
installed wheelsoil, or with its MSER search up to the shortest window (``--truncation-search 1``, the search
before the first-half rule) and every batch taken for a whole period of the wheel (``--batch-is-period``, as
before the detector knew the 180-deg period of a wheel with 8 grousers and 6 spokes). A run that stopped steady holds its series only up to the stop, so a detector that
would have driven on says "not steady by the stored end".

Usage (from the repository root; seconds)::

    python docs/steady_replay.py RUN_DIR [RUN_DIR ...] [--truncation-search 0.5] [--batch-is-period]
"""

import argparse
import csv
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from wheelsoil.cases import build
from wheelsoil.cases.schema import load_case
from wheelsoil.coupling.steady import confirm_steady
from wheelsoil.coupling.run_statistics import detect_from_rows
from wheelsoil.coupling.rig import batches_per_period, statistics_pitch


def read_series(path: Path) -> dict:
    """The columns of a run's series.csv by quantity name (units stripped from the header)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    names = [h.split("[")[0] for h in rows[0]]
    data = np.array(rows[1:], float)
    return {name: data[:, j] for j, name in enumerate(names)}


def replay(run_dir: Path, truncation_search: float = 0.5, whole_periods: bool = True,
           drift_confidence: float | None = None):
    """The verdict that would have ended the stored run (or the last one by its stored end), the time of that
    check [s] and how many checks were made. ``whole_periods=False``: every batch taken for a whole period of
    the wheel (the detector before it knew the period of a wheel whose grousers and spokes differ);
    ``drift_confidence``: the detector's (None: the case's ``output.steady_drift_confidence``)."""
    case = load_case(run_dir / "case.toml")
    spec, bed, wheel = build.testbed_spec(case), build.bed_spec(case), build.wheel_geometry(case)
    run = json.loads((run_dir / "summary.json").read_text())["run"]
    rows = read_series(run_dir / "series.csv")
    t = rows["t"]
    dt_sample = float(t[1] - t[0])
    pitch = statistics_pitch(wheel)
    periods = batches_per_period(wheel) if whole_periods else 1
    batch_time = pitch / spec.angular_velocity
    start = run["t_hold"] + batch_time
    check, end = start + spec.average_time, run["t_wind_up"] + spec.drive_time
    kwargs = dict(slip=spec.slip, load=spec.load, angular_velocity=spec.angular_velocity,
                  average_time=spec.average_time, steady_tolerance=spec.steady_tolerance,
                  slip_tolerance=spec.slip_tolerance, radius=wheel.radius, pitch=pitch,
                  mean_diameter=0.5 * (bed.diameter_min + bed.diameter_max), sample_interval=dt_sample, start=start,
                  period_pitches=periods,
                  drift_confidence=spec.steady_drift_confidence if drift_confidence is None else drift_confidence)
    state, in_a_row, checks, t_check = None, 0, 0, math.nan
    for k in range(len(t)):
        if t[k] < check - 1e-12:
            continue
        check = t[k] + batch_time
        n = k + 1
        state = detect_from_rows({q: y[:n] for q, y in rows.items()}, **kwargs, truncation_search=truncation_search)
        if state.steady and state.window[1] - state.window[0] < spec.average_time * (1.0 - 1e-9):
            state = replace(state, steady=False, reasons=["the steady window is shorter than average_time"])
        state, in_a_row = confirm_steady(state, in_a_row, spec.steady_checks)
        checks, t_check = checks + 1, float(t[k])
        if state.steady or t[k] >= end - 1e-12:
            break
    return state, t_check, checks


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("runs", type=Path, nargs="+", help="run folders (series.csv, summary.json, case.toml)")
    p.add_argument("--truncation-search", type=float, default=0.5,
                   help="fraction of the pitches MSER searches for the transient's end (default 0.5)")
    p.add_argument("--drift-confidence", type=float, default=None,
                   help="standard errors added to each drift before the tolerance (default: the case's own)")
    p.add_argument("--batch-is-period", action="store_true",
                   help="take every batch for a whole period of the wheel (the detector before)")
    args = p.parse_args()
    print("| run | stored: steady, window [s] | replayed: steady | window [s] | pitches | DP [N] | F_y [N] "
          "| 95 % interval DP / F_y [N] (dof) | tread slip | reasons |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for run_dir in args.runs:
        stored = json.loads((run_dir / "summary.json").read_text())["summary"]
        state, _, _ = replay(run_dir, args.truncation_search, not args.batch_is_period, args.drift_confidence)
        dp, fy = state.stats.get("drawbar_pull", {}), state.stats.get("lateral_force", {})
        print(f"| {run_dir.name} | {'yes' if stored['steady'] else 'no'}, "
              f"{stored['window'][0]:.2f}–{stored['window'][1]:.2f} | {'yes' if state.steady else 'no'} | "
              f"{state.window[0]:.2f}–{state.window[1]:.2f} | {state.pitches} | "
              f"{dp.get('mean', math.nan):.1f} ± {dp.get('sem', math.nan):.1f} | "
              f"{fy.get('mean', math.nan):.1f} ± {fy.get('sem', math.nan):.1f} | "
              f"±{dp.get('ci95', math.nan):.1f} / ±{fy.get('ci95', math.nan):.1f} ({dp.get('dof', math.nan):.1f}) | "
              f"{state.tread_slip:.3f} | "
              f"{'; '.join(state.reasons)} |", flush=True)


if __name__ == "__main__":
    main()
