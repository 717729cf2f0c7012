"""Every finished run of the CMU twin beside the trial it twins (issue 34), read from the runs' own files, so that no
number in docs/cmu-twin/README.md is copied by hand.

For each sweep folder ``RUNS/cmu-*`` (the subset, the candidates, the replicas, the speed check) and each case in it
that has finished (its ``result.h5``, read as a typed result): the wheel, steering angle, commanded slip, load and
seed of the case it ran; whether the steady-state detector found it steady and over which window; the steady (or, where not
steady, the window's) means of the drawbar pull, the lateral force and the tread sinkage with their 95 % intervals
(the detector's own: one run's, without the run-to-run spread the replicas measure), the sinkage beside the trial's
as :data:`SINKAGE_REFERENCE` says; and the measured trial of the
same wheel, steering angle and load (each trial's load is its own) with its mean and standard deviation, in wheelsoil's
signs (``wheelsoil.validation.measured.load_cmu_trials``). A run that is not steady gives no number (rule 2 of the
README); it is listed, marked, for information.

The runs' own files live outside the repository and a fresh machine does not have them, so ``OUT`` is the record: a
run recorded there earlier whose case folder is not under ``RUNS`` is kept as recorded (its record and its summary
rows; the record marked ``"recorded": "earlier"``; :func:`merge_records`, :func:`merge_summary`), and a run found
under ``RUNS`` replaces its earlier record. Nothing recorded is lost when the runs folder is new. Each record also holds
its stage's whole summary (``summary``: every quantity's mean, std, sem, 95 % interval and degrees of freedom,
``RunSummary.to_dict``), so that statistics over runs (the replicas' spread against the runs' own errors) can be taken
from the repository alone.

Writes ``OUT/runs.md`` and ``OUT/runs.json``, and copies each sweep's ``summary.csv`` to ``OUT/<sweep>/summary.csv``,
so that ``wheelsoil validate ../shared/data/measured/cmu_3d_terramechanics --model OUT/<sweep>`` and
``python docs/validation_lab_model.py --twin OUT/<sweep>`` run from the repository.

Usage (from the repository root; seconds)::

    python docs/cmu_twin_runs.py --runs RUNS --out docs/cmu-twin/runs
"""

import argparse
import csv
import json
import math
import sys
from pathlib import Path

import numpy as np

MEASURED = Path("..") / "shared" / "data" / "measured" / "cmu_3d_terramechanics"
#: The responses tabulated: summary quantity -> (dataset response, label, scale to the printed unit, unit).
QUANTITIES = {"drawbar_pull": ("drawbar_pull", "drawbar pull", 1.0, "N"),
              "lateral_force": ("lateral_force", "lateral force", 1.0, "N"),
              "tread_sinkage": ("sinkage", "tread sinkage", 1e3, "mm")}
#: How the two sinkages compare (the table's header says it). The trials' is the lab's: the carriage's travel since the
#: trial's start plus the 31.5 mm its scripts take as the wheel's sinkage at the start position
#: (``raw-data-processing/read_ft_speed_data.m``, ``Z_zero``), one value per trial; the lab's own model fit uses it as
#: the model's sinkage (``terramechanics/a_b_tuning_optimization_wrapper.m``, ``h0``). It reads as sinkage below the
#: surface: the free-rolling trials at 0 deg give 14-16 mm, and the static press of the same wheels at their loads
#: (22-26 N) reaches 12-15 mm from first contact (``force_displacement/wheel_sinkage.csv``). The twin's tread sinkage is
#: the rim's lowest point below the levelled surface; a grousered wheel first touches with its 5 mm grouser tips, so
#: the references may differ by up to the grouser height, and a difference within that is not resolved.
SINKAGE_REFERENCE = ("The trials' sinkage is the lab's (its scripts add the 31.5 mm they take as the wheel's sinkage "
                     "at its start to the carriage's travel; the free-rolling trials at 0° give 14–16 mm where the static "
                     "press of the same wheels at their loads reaches 12–15 mm, so it reads as sinkage below the "
                     "surface, as the lab's model fit uses it); the twin's tread sinkage is the rim's lowest point "
                     "below the levelled surface. The grousered wheel first touches with its 5 mm grouser tips, so a "
                     "difference within 5 mm is not resolved; the trials give one sinkage each, no std.")


def finished_runs(runs: Path) -> list[dict]:
    """One record per finished case of every ``runs/cmu-*`` sweep folder (sorted by sweep and case hash), read as
    typed results (``wheelsoil.cases.load_result``: the case it ran and its summary); a case whose drive has several
    stages (a slip ramp) gives one record per stage, at the stage's slip. A case folder linked from another sweep (a
    convergence study's reference) is listed under its own sweep only."""
    from wheelsoil.cases.results import load_result
    from wheelsoil.cases.run import RESULT_NAME

    out, seen = [], set()
    for sweep in sorted(p for p in runs.glob("cmu-*") if p.is_dir()):
        for folder in sorted((sweep / "cases").glob("*")):
            if folder.is_symlink() or not (folder / RESULT_NAME).is_file() or folder.resolve() in seen:
                continue  # a link (a convergence study's reference) is listed under the sweep it belongs to
            seen.add(folder.resolve())
            result = load_result(folder)
            case = result.case
            fill = result_drum_fill(result)  # the last frame's: the last stage's
            for k, s in enumerate(result.stages):
                record = {"sweep": sweep.name, "case_hash": folder.name, "wheel": case.wheel.preset,
                          "seed": case.case.seed, "slip": s.commanded_slip, "slip_angle": case.test.slip_angle,
                          "load": case.test.load, "drive_time": case.test.drive_time,
                          "bin": [case.soil.length, case.soil.width, case.soil.depth],
                          "steady": bool(s.steady), "window": list(s.window), "reasons": list(s.reasons),
                          "wall_seconds": result.info.get("wall_seconds"),
                          "simulated_seconds": result.info.get("simulated_seconds")}
                if len(result.stages) > 1:
                    record["stage"] = k
                for q in QUANTITIES:
                    record[q] = {"mean": s.quantity(q).mean, "ci95": s.quantity(q).ci95}
                record["tread_slip"] = s.tread_slip.mean
                record["vertical_force"] = s.vertical_force.mean
                record["side_walls"] = bool(case.wheel.side_walls)
                record["drum_fill"] = fill
                record["summary"] = s.to_dict()  # the stage's whole summary (RunSummary.from_dict reads it back)
                out.append(record)
    return out


def merge_records(found: list[dict], recorded: list[dict]) -> list[dict]:
    """The records ``found`` under the runs folder, plus those ``recorded`` earlier (``runs.json``) whose case (sweep
    and case hash) was not found, marked ``"recorded": "earlier"``; sorted by sweep and case hash, stages in order."""
    here = {(r["sweep"], r["case_hash"]) for r in found}
    kept = [{**r, "recorded": "earlier"} for r in recorded if (r["sweep"], r["case_hash"]) not in here]
    return sorted(found + kept, key=lambda r: (r["sweep"], r["case_hash"], r.get("stage", 0)))


def merge_summary(found: Path | None, recorded: Path) -> list[dict]:
    """The summary rows of a sweep: those of its ``summary.csv`` under the runs folder (``found``; None: none) plus those
    of the earlier copy ``recorded`` whose case hash that file does not hold (a case's stages stay together), sorted by
    case hash; the fields are the new file's, then any only the earlier one has."""
    def rows(path):
        if path is None or not path.is_file():
            return [], []
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            return list(reader.fieldnames or []), list(reader)

    new_fields, new_rows = rows(found)
    old_fields, old_rows = rows(recorded)
    here = {r["case_hash"] for r in new_rows}
    merged = new_rows + [r for r in old_rows if r["case_hash"] not in here]
    fields = new_fields + [f for f in old_fields if f not in new_fields]
    merged.sort(key=lambda r: r["case_hash"])
    return [{f: r.get(f, "") for f in fields} for r in merged]


def write_summary_rows(path: Path, rows: list[dict]) -> None:
    """``rows`` (dicts of one set of fields) as a CSV file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def drum_fill(positions: np.ndarray, radii: np.ndarray, hub: np.ndarray, slip_angle: float, radius: float,
              width: float, tread_thickness: float) -> float:
    """The share of an open wheel's drum (inside the tread, between its two side planes) that grains fill: the solid
    volume of the spheres [m^3] whose centres lie in it over the drum's volume, pi (r - t)^2 b. The wheel is yawed by
    -slip_angle [deg] about z (the testbed's convention, ``coupling.kinematics.yaw_matrix``), its hub at ``hub``."""
    from wheelsoil.coupling.kinematics import yaw_matrix

    yaw = yaw_matrix(math.radians(-slip_angle))
    heading, axle = yaw[:, 0], yaw[:, 1]
    p = np.asarray(positions, float) - np.asarray(hub, float)
    inside = (np.abs(p @ axle) < 0.5 * width) & (np.hypot(p @ heading, p[:, 2]) < radius - tread_thickness)
    solid = float(np.sum(4.0 / 3.0 * np.pi * np.asarray(radii, float)[inside] ** 3))
    return solid / (np.pi * (radius - tread_thickness) ** 2 * width)


def result_drum_fill(result) -> float:
    """:func:`drum_fill` of a finished run's last frame (NaN for a run that kept no frame)."""
    if not len(result.frame_times):
        return math.nan
    frame, wheel, s = result.frame(-1), result.wheel, result.series
    hub = np.array([s["hub_x"][-1], s["hub_y"][-1], s["hub_z"][-1]])
    return drum_fill(frame["position"], frame["radius"], hub, result.case.test.slip_angle, wheel.radius, wheel.width,
                     wheel.tread_thickness)


def pair_with_trials(records: list[dict], data) -> None:
    """Add each record's measured trial (same wheel, steering angle, commanded slip within 0.05 and load within 1 mN),
    or None where none matches."""
    grouser = data.grouser_height > 0
    for r in records:
        at = (grouser == r["wheel"].endswith("grouser")) & (data.slip_angle == r["slip_angle"])
        at &= (np.abs(data.travel_slip - r["slip"]) <= 0.05) & (np.abs(data.load - r["load"]) < 1e-3)
        rows = np.flatnonzero(at)
        r["trial"] = None if len(rows) != 1 else {
            q: {"mean": float(data.responses[name][rows[0]]),
                "std": float(data.std[name][rows[0]]) if name in data.std else math.nan}
            for q, (name, *_) in QUANTITIES.items()}


def _cell(value: dict, scale: float) -> str:
    return f"{scale * value['mean']:+.2f} ± {scale * value['ci95']:.2f}"


def markdown(records: list[dict]) -> list[str]:
    """The table: one row per run, its measured trial and residuals in trial standard deviations."""
    head = ("| sweep | wheel, β, slip, load, seed, drive | steady (window) | " +
            " | ".join(f"{label} [{unit}]: twin (95 %) / trial (std) / residual in trial stds"
                       if q != "tread_sinkage" else f"{label} [{unit}]: twin (95 %) / trial / twin − trial"
                       for q, (_, label, _, unit) in QUANTITIES.items()) + " | soil in the drum | wall / simulated |")
    lines = [head, "|" + "---|" * (5 + len(QUANTITIES))]
    for r in records:
        steady = (f"yes ({r['window'][0]:.2f}–{r['window'][1]:.2f} s)" if r["steady"]
                  else f"**no** (window {r['window'][0]:.2f}–{r['window'][1]:.2f} s, not a number)")
        cells = []
        for q, (_, _, scale, _) in QUANTITIES.items():
            cell = _cell(r[q], scale)
            trial = r["trial"][q] if r["trial"] else None
            if trial is not None and q != "tread_sinkage":
                z = (r[q]["mean"] - trial["mean"]) / trial["std"] if trial["std"] > 0 else math.nan
                cell += f" / {scale * trial['mean']:+.2f} ({scale * trial['std']:.2f}) / {z:+.1f}"
            elif trial is not None:  # one value per trial (no std): the difference in mm, within SINKAGE_REFERENCE
                cell += f" / {scale * trial['mean']:.1f} / {scale * (r[q]['mean'] - trial['mean']):+.1f} mm"
            cells.append(cell)
        wheel = r["wheel"].replace("cmu-k10-", "") + (", closed" if r.get("side_walls") else "")
        bin_note = "" if r["bin"] == [0.3, 0.2, 0.1] else f", bin {r['bin'][1]:g} × {r['bin'][2]:g} m"
        fill = r.get("drum_fill", math.nan)
        drum = "–" if not np.isfinite(fill) else ("closed" if r.get("side_walls") else f"{fill:.0%}")
        lines.append(f"| {r['sweep'].replace('cmu-', '')} | {wheel}, {r['slip_angle']:g}°, {r['slip']:+.3f}, "
                     f"{r['load']:.2f} N, seed {r['seed']}, {r['drive_time']:g} s drive{bin_note} | {steady} | "
                     + " | ".join(cells) +
                     f" | {drum} | {r['wall_seconds']:.0f} s / {r['simulated_seconds']:.2f} s |")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", required=True, help="folder of the twin's sweeps (outside the repository)")
    ap.add_argument("--out", default="docs/cmu-twin/runs")
    ap.add_argument("--data", default=str(MEASURED))
    args = ap.parse_args(argv)

    from wheelsoil.provenance import provenance, write_markdown_and_json
    from wheelsoil.validation.measured import load_cmu_trials

    runs, out = Path(args.runs), Path(args.out)
    found = finished_runs(runs)
    pair_with_trials(found, load_cmu_trials(args.data))
    recorded = json.loads((out / "runs.json").read_text())["runs"] if (out / "runs.json").is_file() else []
    records = merge_records(found, recorded)
    out.mkdir(parents=True, exist_ok=True)
    for sweep in sorted({r["sweep"] for r in found}):
        summary = runs / sweep / "summary.csv"
        rows = merge_summary(summary if summary.is_file() else None, out / sweep / "summary.csv")
        if rows:
            write_summary_rows(out / sweep / "summary.csv", rows)
    steady = sum(r["steady"] for r in records)
    earlier = sum(r.get("recorded") == "earlier" for r in records)
    lines = ["# The CMU twin's finished runs beside their trials (issue 34)", "",
             f"Generated by `python docs/cmu_twin_runs.py --runs RUNS --out {args.out}` from the runs' own "
             "`result.h5` (read as typed results); the rules that judge them are in [the twin's README](../README.md). "
             f"{len(records)} finished runs, {steady} of them steady"
             + (f" ({earlier} recorded earlier, their files not on the machine that wrote this: kept as recorded)"
                if earlier else "") + ". The intervals are each run's own (the steady-"
             "state detector's 95 %), without the run-to-run spread; a run not steady gives no number and is listed "
             "for information. *Soil in the drum*: the solid volume of the grains inside the open wheel's drum (inside the "
             "tread, between its side planes) over the drum's volume, in the run's last frame. Signs are wheelsoil's (the lateral force opposes the lateral slip); the residual is "
             "(twin − trial) / the trial's std. " + SINKAGE_REFERENCE, "",
             *markdown(records), ""]
    write_markdown_and_json(out / "runs.md", "\n".join(lines), out / "runs.json",
                            {"runs": records, "provenance": provenance()}, default=float)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
