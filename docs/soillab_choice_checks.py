"""Issue 33's owed checks on the wide-box calibration's choice (``docs/soillab/choice-checks/run.sh``, fixed before
they ran): the repose and the plates over three seeds, the shear box at half its speed, the held-out wheel check over
three seeds, and the 100 mm plate's particle scale extrapolated to zero size. Writes ``summary.md`` and
``summary.json`` into the checks' folder; a check that has not run yet is said to be missing.

Usage (from the repository root)::

    python docs/soillab_choice_checks.py [--out docs/soillab/choice-checks]

The rules, from run.sh: the shear box is quasi-static when every normal stress's peak shear stress changes by less
than 10 % between 20 and 10 mm/s. The objective of each seed is the calibration's (``soillab.objective.score``: the
plates' mean squared log-pressure error plus the repose error in units of 2 deg) on that seed's repose and plates;
their spread says how far apart two candidates' single-seed objectives must be before the choice between them is
more than the draw of the packing.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

DOCS = Path(__file__).resolve().parent
CALIBRATION = DOCS / "soillab" / "calibration-epsd-box"
DESIGN = "epsd-box"
#: The 100 mm plate's seeds 1 and 2 of cmu_sand's particles in the wide box, run before these checks by the same
#: command (docs/soillab/box/wide-seeds.sh).
WIDE_BOX_SEEDS = {1: DOCS / "soillab" / "box" / "wide-seed1", 2: DOCS / "soillab" / "box" / "wide-seed2"}
#: cmu_sand's held-out wheel check, seed 0 (docs/soillab/cmu-sand/run.sh).
CMU_SAND_WHEELS = DOCS / "soillab" / "cmu-sand"
SEEDS = (0, 1, 2)
SHEAR_TOLERANCE = 0.10
WHEEL_DEPTHS_MM = (5.0, 10.0, 15.0, 20.0, 25.0, 30.0)


def chosen_candidate() -> tuple[Path, dict]:
    """The calibration's choice by its rule (``docs/soillab_calibration.py choice``) and its row."""
    sys.path.insert(0, str(DOCS))
    from soillab_calibration import design_choice

    from wheelsoil.errors import WheelsoilInputError

    try:
        return design_choice(CALIBRATION, DESIGN)
    except WheelsoilInputError as exc:
        raise SystemExit(str(exc)) from None


def is_cmu_sand(row: dict) -> bool:
    from wheelsoil.parameters import cmu_sand

    pair, material = cmu_sand.PARTICLE_PAIR, cmu_sand.PARTICLE_MATERIAL
    return (row["friction"], row["rolling_friction"], row["rolling_model"], row["density"]) == (
        pair.static_friction, pair.rolling_friction, pair.rolling_model, material.density)


def _json(path: Path) -> dict | None:
    return json.loads(path.read_text()) if path.is_file() else None


def repose(out: Path, row: dict) -> dict:
    data = _json(out / "repose" / "repose.json")
    if data is None:
        return {"missing": "repose"}
    angles = [float(a) for a in data["angles_deg"]]
    return {"angles_deg": angles, "mean_deg": float(np.mean(angles)), "sd_deg": float(np.std(angles, ddof=1)),
            "calibration_seed0_deg": row["repose_deg"], "seed0_change_deg": angles[0] - row["repose_deg"]}


def shear_speed(out: Path) -> dict:
    fast, slow = _json(out / "shear-20mms" / "shear.json"), _json(out / "shear-10mms" / "shear.json")
    if fast is None or slow is None:
        return {"missing": "shear-20mms and shear-10mms"}
    peaks_fast = np.array([r["peak_Pa"] for r in fast["runs"]])
    peaks_slow = np.array([r["peak_Pa"] for r in slow["runs"]])
    change = peaks_slow / peaks_fast - 1.0
    return {"normal_stresses_Pa": [r["imposed_normal_Pa"] for r in fast["runs"]],
            "peak_20mms_Pa": peaks_fast.tolist(), "peak_10mms_Pa": peaks_slow.tolist(), "change": change.tolist(),
            "peak_angle_20mms_deg": fast["peak"]["friction_angle_deg"],
            "peak_angle_10mms_deg": slow["peak"]["friction_angle_deg"],
            "quasi_static": bool(np.all(np.abs(change) < SHEAR_TOLERANCE))}


def plate_pressures(out: Path, row: dict, cmu_sand: bool) -> dict[int, dict[str, list[float]]]:
    """Per seed, per plate diameter (the calibration's keys, '0.06' and '0.1'), the simulated pressure [Pa] at the
    objective's sinkages: seed 0 the calibration's own, seeds 1 and 2 from the checks (cmu_sand's 100 mm plate from
    the wide box's seeds)."""
    seeds = {0: {d: list(p["simulated_Pa"]) for d, p in row["plates"].items()}}
    for seed in SEEDS[1:]:
        found = {}
        sources = [out / f"plate-seed{seed}" / "plate.json"]
        if cmu_sand:
            sources.append(WIDE_BOX_SEEDS[seed] / "plate.json")
        for source in sources:
            data = _json(source)
            for entry in (data or {}).get("pressure", []):
                found.setdefault(f"{entry['diameter_m']:g}", {})[round(entry["sinkage_m"], 6)] = entry["simulated_Pa"]
        if set(found) == set(row["plates"]):
            seeds[seed] = {d: [found[d].get(round(z, 6), float("nan")) for z in row["plates"][d]["sinkage_m"]]
                           for d in row["plates"]}
    return seeds


def plates(out: Path, row: dict, cmu_sand: bool, repose_angles: list[float] | None) -> dict:
    from wheelsoil.soillab.objective import score

    seeds = plate_pressures(out, row, cmu_sand)
    per_seed = {}
    for seed, pressures in seeds.items():
        scored = score({"plates": {d: {"simulated_Pa": pressures[d], "measured_Pa": row["plates"][d]["measured_Pa"]}
                                   for d in row["plates"]},
                        "repose_deg": repose_angles[seed] if repose_angles else row["repose_deg"]})
        per_seed[seed] = {"pressure_Pa": pressures, "plate_log_mse": scored["plate_log_mse"],
                          "objective": scored["objective"]}
    table = {}
    for d, plate in row["plates"].items():
        p = np.array([per_seed[s]["pressure_Pa"][d] for s in sorted(per_seed)])
        table[d] = {"sinkage_m": plate["sinkage_m"], "mean_Pa": np.nanmean(p, 0).tolist(),
                    "sd_Pa": (np.nanstd(p, 0, ddof=1) if len(p) > 1 else np.full(p.shape[1], np.nan)).tolist(),
                    "measured_Pa": plate["measured_Pa"], "measured_sd_Pa": plate["measured_sd_Pa"]}
    objectives = [per_seed[s]["objective"] for s in sorted(per_seed)]
    return {"seeds": sorted(per_seed), "per_seed": per_seed, "table": table,
            "objective_mean": float(np.mean(objectives)),
            "objective_sd": float(np.std(objectives, ddof=1)) if len(objectives) > 1 else float("nan"),
            "repose_of_each_seed": bool(repose_angles)}


def runner_up(row: dict) -> dict:
    """The calibration's second-least objective, for the gap the seeds' spread is set against."""
    from wheelsoil.soillab.objective import score

    rows = sorted((score(json.loads(p.read_text())) for p in (CALIBRATION / "candidates").glob("*.json")),
                  key=lambda r: r["objective"])
    second = next(r for r in rows if (r["friction"], r["rolling_friction"]) != (row["friction"],
                                                                               row["rolling_friction"]))
    return {"friction": second["friction"], "rolling_friction": second["rolling_friction"],
            "objective": second["objective"], "gap": second["objective"] - score(dict(row))["objective"]}


def wheel_forces(csv: Path) -> np.ndarray | None:
    if not csv.is_file():
        return None
    dem = pd.read_csv(csv)
    dem = dem[dem["source"] == "DEM"].sort_values("sinkage_m")
    z = 1e-3 * np.asarray(WHEEL_DEPTHS_MM)
    return np.where(z <= dem["sinkage_m"].max(), np.interp(z, dem["sinkage_m"], dem["force_N"]), np.nan)


def wheels(out: Path, cmu_sand: bool) -> dict:
    from wheelsoil.soillab.measured import load_wheel_curves, mean_curve

    result = {}
    z = 1e-3 * np.asarray(WHEEL_DEPTHS_MM)
    for wheel in ("grouser", "smooth"):
        forces = {}
        for seed in SEEDS:
            csv = out / f"wheel-{wheel}-seed{seed}" / "wheel.csv"
            if seed == 0 and cmu_sand:
                csv = CMU_SAND_WHEELS / f"wheel-{wheel}" / "wheel.csv"
            f = wheel_forces(csv)
            if f is not None:
                forces[seed] = f
        mean, sd, count = mean_curve([c for c in load_wheel_curves() if c.wheel == wheel], z)
        entry = {"depth_mm": list(WHEEL_DEPTHS_MM), "measured_N": mean.tolist(), "measured_sd_N": sd.tolist(),
                 "measured_trials": count.tolist(), "seeds": sorted(forces)}
        if forces:
            f = np.array([forces[s] for s in sorted(forces)])
            entry["force_N"] = {s: forces[s].tolist() for s in sorted(forces)}
            reached = np.isfinite(f)  # a depth no seed reached stays NaN (no warning of an empty mean)
            total = np.where(reached, f, 0.0).sum(0)
            entry["mean_N"] = np.where(reached.any(0), total / np.maximum(reached.sum(0), 1), np.nan).tolist()
            entry["sd_N"] = [float(np.std(col[np.isfinite(col)], ddof=1)) if np.isfinite(col).sum() > 1 else np.nan
                             for col in f.T]
            entry["log_mse"] = {}
            for s in sorted(forces):
                ok = np.isfinite(forces[s]) & (forces[s] > 0) & (mean > 0)
                entry["log_mse"][s] = float(np.mean(np.log(forces[s][ok] / mean[ok]) ** 2))
        result[wheel] = entry
    return result


def scale(out: Path, plate_seeds: dict[int, dict[str, list[float]]], row: dict) -> dict:
    """The 100 mm plate's extrapolation to zero particle size (``docs/soillab_scale.py``'s line through every seed's
    pressure against the mean diameter), its x1 points the scale runs' own and the plate replicas of seeds 1 and 2."""
    sys.path.insert(0, str(DOCS))
    from soillab_scale import SINKAGES, extrapolate

    from wheelsoil.parameters import soil_lab

    rows = [json.loads(p.read_text()) for p in sorted((out / "scale" / "runs").glob("*.json"))]
    if not rows:
        return {"missing": "scale"}
    sinkages = [round(z, 6) for z in row["plates"]["0.1"]["sinkage_m"]]
    d_lab = 0.5 * (soil_lab.DIAMETER_MIN + soil_lab.DIAMETER_MAX)
    replicas = [{"scale": 1.0, "seed": seed, "mean_diameter_m": d_lab,
                 "pressure_Pa": [plate_seeds[seed]["0.1"][sinkages.index(round(z, 6))] for z in SINKAGES]}
                for seed in SEEDS[1:] if seed in plate_seeds]
    points = rows + replicas
    return {"runs": [{k: r[k] for k in ("scale", "seed", "mean_diameter_m", "pressure_Pa") if k in r}
                     | {"particles": r.get("particles"), "wall_seconds": r.get("wall_seconds")} for r in rows],
            "replica_points": replicas, "extrapolation": extrapolate(points),
            "scales_run": sorted({r["scale"] for r in rows}, reverse=True)}


def _section(lines: list[str], title: str, check: dict) -> bool:
    """Append the check's heading (and "Not run yet." when it is missing); whether it has results to show."""
    lines += [f"## {title}", ""]
    if "missing" in check:
        lines += ["Not run yet.", ""]
    return "missing" not in check


def markdown(report: dict) -> str:
    c = report["choice"]
    lines = [f"# Issue 33's checks on the calibration's choice: sliding {c['friction']:g}, rolling "
             f"{c['rolling_friction']:g}, density {c['density']:g} kg/m³ ({c['rolling_model']})", "",
             f"Generated by `python docs/soillab_choice_checks.py` from the runs of `docs/soillab/choice-checks/run.sh` "
             f"(rules fixed there before any of them ran). The choice: `{c['path']}`"
             + (" (cmu_sand's own particles)." if c["cmu_sand"] else " (not cmu_sand's particles)."), ""]
    r = report["repose"]
    if _section(lines, "Repose (draw-down, seeds 0–2)", r):
        lines += [f"{' / '.join(f'{a:.1f}' for a in r['angles_deg'])}°: **{r['mean_deg']:.1f} ± {r['sd_deg']:.1f}°** "
                  f"(mean ± sd; the sand 29°). Seed 0 against the calibration's own draw-down "
                  f"({r['calibration_seed0_deg']:.2f}°): {r['seed0_change_deg']:+.2f}°.", ""]
    s = report["shear_speed"]
    if _section(lines, "The shear box at half its speed", s):
        lines += ["| normal stress [kPa] | peak at 20 mm/s [kPa] | at 10 mm/s [kPa] | change |", "|---|---|---|---|"]
        lines += [f"| {1e-3 * n:g} | {1e-3 * a:.2f} | {1e-3 * b:.2f} | {100 * ch:+.1f} % |"
                  for n, a, b, ch in zip(s["normal_stresses_Pa"], s["peak_20mms_Pa"], s["peak_10mms_Pa"], s["change"])]
        lines += ["", f"Peak friction angle {s['peak_angle_20mms_deg']:.1f}° at 20 mm/s, {s['peak_angle_10mms_deg']:.1f}° "
                  f"at 10 mm/s. **{'Quasi-static' if s['quasi_static'] else 'Not quasi-static'}** by the rule (every "
                  f"peak within {100 * SHEAR_TOLERANCE:g} %).", ""]
    p = report["plates"]
    lines += ["## The plates over seeds (wide box 0.6 × 0.6 × 0.12 m)", ""]
    if len(p["seeds"]) < 2:
        lines += [f"Seeds run: {p['seeds']}; the replicas have not run yet.", ""]
    else:
        for d, t in p["table"].items():
            lines += [f"**{1e3 * float(d):g} mm plate**, seeds {', '.join(map(str, p['seeds']))}:", "",
                      "| sinkage [mm] | DEM mean ± sd [kPa] | sand mean ± sd [kPa] | DEM / sand |", "|---|---|---|---|"]
            for z, m, sd, mm, msd in zip(t["sinkage_m"], t["mean_Pa"], t["sd_Pa"], t["measured_Pa"],
                                        t["measured_sd_Pa"]):
                ratio = f"{m / mm:.2f}" if np.isfinite(mm) else "–"
                sand = f"{1e-3 * mm:.1f} ± {1e-3 * msd:.1f}" if np.isfinite(mm) else "not measured"
                lines.append(f"| {1e3 * z:g} | {1e-3 * m:.1f} ± {1e-3 * sd:.1f} | {sand} | {ratio} |")
            lines.append("")
        per = p["per_seed"]
        lines += ["| seed | plates' log-MSE | objective |", "|---|---|---|"]
        lines += [f"| {s} | {per[s]['plate_log_mse']:.3f} | {per[s]['objective']:.3f} |" for s in p["seeds"]]
        ru = report["runner_up"]
        lines += ["", f"Objective over the seeds {p['objective_mean']:.3f} ± {p['objective_sd']:.3f} (sd"
                  + ("; each seed's own repose" if p["repose_of_each_seed"] else "; seed 0's repose for every seed")
                  + f"). The calibration's runner-up (sliding {ru['friction']:g}, rolling {ru['rolling_friction']:g}) "
                  f"scored {ru['objective']:.3f} on seed 0, {ru['gap']:+.3f} from the choice: "
                  + ("more than two seed standard deviations, so the choice is not the draw of the packing."
                     if ru["gap"] > 2 * p["objective_sd"] else
                     "within two seed standard deviations, so the choice between them is not resolved by one seed."),
                  ""]
    w = report["wheels"]
    lines += ["## The held-out wheel check over seeds (x0.8 particles)", ""]
    for wheel, e in w.items():
        if not e["seeds"]:
            lines += [f"**{wheel} wheel**: not run yet.", ""]
            continue
        lines += [f"**{wheel} wheel**, seeds {', '.join(map(str, e['seeds']))}:", "",
                  "| sinkage [mm] | DEM mean ± sd [N] | measured mean ± sd [N] (trials) | DEM / measured |",
                  "|---|---|---|---|"]
        for k, z in enumerate(e["depth_mm"]):
            m, sd = e["mean_N"][k], e["sd_N"][k]
            dem = "not reached" if not np.isfinite(m) else f"{m:.1f} ± {sd:.1f}" if np.isfinite(sd) else f"{m:.1f}"
            ratio = f"{m / e['measured_N'][k]:.2f}" if np.isfinite(m) else "–"
            lines.append(f"| {z:g} | {dem} | {e['measured_N'][k]:.1f} ± {e['measured_sd_N'][k]:.1f} "
                         f"({e['measured_trials'][k]}) | {ratio} |")
        lines += ["", "Log-force error per seed: " + ", ".join(f"seed {s} {v:.3f}" for s, v in e["log_mse"].items())
                  + ".", ""]
    sc = report["scale"]
    if _section(lines, "Particle scale of the 100 mm plate (wide box)", sc):
        lines += [f"Scales run: {', '.join(f'×{x:g}' for x in sc['scales_run'])} (seed 0), with the ×1 replicas "
                  f"(seeds {', '.join(str(r['seed']) for r in sc['replica_points'])}) as further points. The scale "
                  "error of a size is the line's change from p0 there, relative to p0 (×0.8 is the CMU twin's "
                  "particles); converged where it lies within 10 % at two standard errors. The quadratic's p0 "
                  "through the sizes' means (three sizes) shows the line's curvature.", "",
                  "| sinkage [mm] | points | p0 [kPa] | the lab's particles [kPa] | scale error ×1 | converged ×1 | "
                  "scale error ×0.8 | converged ×0.8 | p0, quadratic [kPa] |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for e in sc["extrapolation"]:
            if "p0_Pa" not in e:
                lines.append(f"| {1e3 * e['sinkage_m']:g} | {e['points']} | – | – | – | too few points | – | – | – |")
                continue
            twin = e.get("by_scale", {}).get("0.8")
            twin_cells = (f"{100 * twin['scale_error']:+.0f} ± {100 * twin['scale_error_se']:.0f} % | "
                          f"{'yes' if twin['converged'] else 'no'}") if twin else "– | –"
            quad = f"{1e-3 * e['p0_quadratic_Pa']:.1f}" if "p0_quadratic_Pa" in e else "–"
            lines.append(f"| {1e3 * e['sinkage_m']:g} | {e['points']} | {1e-3 * e['p0_Pa']:.1f} ± "
                         f"{1e-3 * e['p0_se_Pa']:.1f} | {1e-3 * e['default_Pa']:.1f} | {100 * e['scale_error']:+.0f} ± "
                         f"{100 * e['scale_error_se']:.0f} % | {'yes' if e['converged'] else 'no'} | {twin_cells} | "
                         f"{quad} |")
        lines.append("")
    return "\n".join(lines)


def build(out: Path) -> dict:
    path, row = chosen_candidate()
    cmu_sand = is_cmu_sand(row)
    rep = repose(out, row)
    angles = rep.get("angles_deg")
    plate = plates(out, row, cmu_sand, angles if angles and len(angles) == len(SEEDS) else None)
    shown = path.relative_to(DOCS.parent) if path.is_relative_to(DOCS.parent) else path
    return {"choice": {"path": str(shown), "friction": row["friction"],
                       "rolling_friction": row["rolling_friction"], "density": row["density"],
                       "rolling_model": row["rolling_model"], "cmu_sand": cmu_sand},
            "repose": rep, "shear_speed": shear_speed(out), "plates": plate, "runner_up": runner_up(row),
            "wheels": wheels(out, cmu_sand),
            "scale": scale(out, {s: v["pressure_Pa"] for s, v in plate["per_seed"].items()}, row)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=DOCS / "soillab" / "choice-checks")
    args = parser.parse_args(argv)
    report = build(args.out)
    text = markdown(report)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "summary.md").write_text(text + "\n")
    (args.out / "summary.json").write_text(json.dumps(report, indent=1, default=float))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
