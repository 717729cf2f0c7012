"""The semi-empirical model with its soil taken from the virtual soil lab, against the CMU trials (issue 34, the
second of its three models): no parameter is fitted to any wheel data.

What the lab gives (``wheelsoil.parameters.cmu_sand``'s stored calibration candidate):

* the friction angle and cohesion: the direct shear box's peak envelope (5 / 10 / 20 kPa);
* Reece's pressure moduli k'_c, k'_phi and the exponent n: Reece's law p = (c k'_c + rho g b k'_phi)(z / b)^n
  (seed 003 eq. 7, seed 000 eq. 3) fitted to the lab's two DEM plates (60 and 100 mm, b their radius, Bekker's
  smaller dimension of a circular plate) in log pressure, with c from the shear box; the wheel then uses b = its
  width, as the model does;
* the bulk density: the sand's 1330 kg/m^3 (the lab's bed packs to it by construction).

What the lab does not measure takes the classical model's own default (seed 003 Table III's dry sand, stated in
the output): the shear deformation modulus K and the stress distribution's a1 (theta_m = a1 theta_f), c3 = 0;
every mechanism off. Beside it, for scale, the classical model fitted to all the trials (the calibration
``wheelsoil validate`` starts from, on every row): the gap between the two is what the lab's parameters miss.

With ``--twin SWEEP`` (a ``wheelsoil batch`` folder of the CMU rig presets, e.g. ``cmu-trials-subset``) the third
model joins them: the DEM--FEM twin on the lab's particles, its steady runs paired with the measured trials at the
same wheel, steering angle, slip and load (``validation.compare.match_conditions``). The three are then scored on
the paired trials only, the same rows for each, and the twin's points are drawn in the figure.

Usage (from the repository root; a few minutes on 2 cores)::

    python docs/validation_lab_model.py --out docs/validation/lab-parameters [--twin SWEEP [SWEEP ...]]
"""

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy import optimize

MEASURED = Path("..") / "shared" / "data" / "measured" / "cmu_3d_terramechanics"
RESPONSES = ("drawbar_pull", "lateral_force")


def reece_fit(plates: dict, cohesion: float, density: float, gravity: float = 9.81) -> dict:
    """k'_c, k'_phi, n of Reece's law fitted to plate points {diameter [m] (str): {"sinkage_m", "simulated_Pa"}}, in
    log pressure, b = the plate's radius, c and rho given."""
    z, p, b = [], [], []
    for d, plate in plates.items():
        zz, pp = np.asarray(plate["sinkage_m"], float), np.asarray(plate["simulated_Pa"], float)
        ok = np.isfinite(pp) & (pp > 0)
        z.append(zz[ok])
        p.append(pp[ok])
        b.append(np.full(int(ok.sum()), 0.5 * float(d)))
    z, p, b = np.concatenate(z), np.concatenate(p), np.concatenate(b)

    def residual(x):
        kc, log_kphi, n = x
        k = cohesion * kc + density * gravity * b * np.exp(log_kphi)
        return np.log(np.clip(k, 1e-9, None) * (z / b) ** n) - np.log(p)

    fit = optimize.least_squares(residual, x0=[10.0, np.log(500.0), 1.0], bounds=([0.0, 0.0, 0.05], [2e3, 15.0, 3.0]))
    kc, log_kphi, n = fit.x
    return {"kc_prime": float(kc), "kphi_prime": float(np.exp(log_kphi)), "n0": float(n),
            "log_rms": float(np.sqrt(np.mean(fit.fun ** 2))), "points": int(z.size)}


def lab_soil(candidate: dict):
    """The classical model's soil from the lab's candidate record (module docstring)."""
    from wheelsoil.validation.extensions import BASELINE_OFF
    from wheelsoil.validation.terramechanics import SoilParameters

    shear = candidate["shear"]
    density = 1330.0
    cohesion = float(shear["peak_cohesion_Pa"])
    reece = reece_fit(candidate["plates"], cohesion, density)
    soil = replace(SoilParameters(), **BASELINE_OFF, density=density, cohesion=cohesion,
                   friction_angle=float(shear["peak_friction_angle_deg"]), kc_prime=reece["kc_prime"],
                   kphi_prime=reece["kphi_prime"], n0=reece["n0"])
    return soil, reece


def _unsupported(soil, data) -> np.ndarray:
    """Rows whose load the model cannot carry at any sinkage (``predict``'s ``supported`` false)."""
    from wheelsoil.validation.terramechanics import RigidWheel, predict

    out = np.zeros(len(data), bool)
    for h in np.unique(data.grouser_height):
        rows = data.grouser_height == h
        wheel = RigidWheel(radius=float(data.radius[rows][0]), width=float(data.width[rows][0]), grouser_height=float(h))
        pred = predict(soil, wheel, slip=data.slip[rows], slip_angle=data.slip_angle[rows], load=data.load[rows],
                       travel_slip=data.travel_slip[rows])
        out[rows] = ~pred["supported"]
    return out


def three_models(data, preds: dict, scales: dict, sweeps) -> tuple[dict, list[str]]:
    """The DEM--FEM twin's steady runs of ``sweeps`` (one folder or several, their runs one after another) paired
    with the measured rows, and the three models' bias and RMS error on those rows (normalised by the responses'
    measured spread), as Markdown lines."""
    from wheelsoil.validation.compare import compare
    from wheelsoil.validation.workflow import simulated_runs

    sweeps = [sweeps] if isinstance(sweeps, (str, Path)) else list(sweeps)
    simulated = simulated_runs(sweeps)
    sweep = " + ".join(str(s) for s in sweeps)
    paired = compare(data, simulated, RESPONSES)  # the pairs and the twin's share within two combined std
    rows, runs = paired.pairs[:, 0], paired.pairs[:, 1]
    twin = {"sweep": str(sweep), "notes": simulated.notes, "paired": int(len(rows)), "measured_rows": rows,
            "responses": {q: simulated.responses[q][runs] for q in RESPONSES},
            "std": {q: simulated.std[q][runs] for q in RESPONSES}}
    lines = [f"**The DEM-FEM twin** (`{sweep}`): {simulated.notes}. {len(rows)} measured trials have a twin run at "
             "their wheel, steering angle, slip and load; the three models on those trials (bias and RMS error over "
             "the measured spread; the within-2σ share counts the measured and the twin's standard deviations "
             "together):", "",
             "| response | DEM-FEM twin bias / RMS (within 2σ) | lab's soil bias / RMS | fitted to the trials bias / RMS |",
             "|---|---|---|---|"]
    scores = {}
    for q in RESPONSES:
        measured = data.responses[q][rows]
        row = {}
        for name, values in (("twin", twin["responses"][q]), ("lab", preds["lab"][q][rows]),
                             ("fitted", preds["fitted"][q][rows])):
            r = (values - measured) / scales[q]
            row[name] = {"bias": float(np.mean(r)), "rms": float(np.sqrt(np.mean(r ** 2)))}
        within = row["twin"]["within_2sigma"] = paired.responses[q]["within_2sigma"]
        scores[q] = row
        lines.append(f"| {q} | {row['twin']['bias']:+.3f} / {row['twin']['rms']:.3f} "
                     f"({'–' if within is None else f'{within:.0%}'}) | "
                     f"{row['lab']['bias']:+.3f} / {row['lab']['rms']:.3f} | "
                     f"{row['fitted']['bias']:+.3f} / {row['fitted']['rms']:.3f} |")
    twin["scores"] = scores
    twin["trials"] = [{"wheel": str(data.group[k]), "slip_angle": float(data.slip_angle[k]),
                       "travel_slip": float(data.travel_slip[k]),
                       **{f"{q}_measured": float(data.responses[q][k]) for q in RESPONSES},
                       **{f"{q}_twin": float(twin["responses"][q][i]) for q in RESPONSES}}
                      for i, k in enumerate(rows)]
    return twin, lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="docs/validation/lab-parameters")
    ap.add_argument("--data", default=str(MEASURED))
    ap.add_argument("--twin", nargs="+", default=None,
                    help="sweep folders of the CMU rig presets (their steady runs together): the DEM-FEM twin")
    args = ap.parse_args(argv)

    from wheelsoil.parameters import cmu_sand
    from wheelsoil.provenance import provenance, write_markdown_and_json
    from wheelsoil.validation.calibration import calibrate_baseline, model_responses, response_scales
    from wheelsoil.validation.extensions import BASELINE_OFF
    from wheelsoil.validation.measured import load_cmu_trials, row_counts
    from wheelsoil.validation.residuals import group_table, residuals_by_group
    from wheelsoil.validation.terramechanics import SoilParameters
    from wheelsoil.validation.trial_figure import ModelPoints, plot_trials

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    candidate = json.loads(Path(cmu_sand.CALIBRATION["candidate"]).read_text())
    soil, reece = lab_soil(candidate)
    data = load_cmu_trials(args.data)
    scales = response_scales(data, RESPONSES)
    start = replace(SoilParameters(), **BASELINE_OFF, density=soil.density)  # the sand's density, as the lab's
    fitted = calibrate_baseline(data, start, RESPONSES, scales).soil
    preds = {"lab": model_responses(soil, data), "fitted": model_responses(fitted, data)}
    res = {m: {q: (preds[m][q] - data.responses[q]) / scales[q] for q in RESPONSES} for m in preds}
    rms = {m: {q: float(np.sqrt(np.nanmean(res[m][q] ** 2))) for q in RESPONSES} for m in res}
    groups = residuals_by_group(res, data)
    unsupported = {m: _unsupported(model, data) for m, model in (("lab", soil), ("fitted", fitted))}

    lab_keys = ("density", "cohesion", "friction_angle", "kc_prime", "kphi_prime", "n0", "shear_modulus_x", "a1")
    lines = ["# The semi-empirical model with the virtual lab's soil, against the CMU trials (issue 34)", "",
             "Generated by `python docs/validation_lab_model.py --out docs/validation/lab-parameters` "
             "(`docs/validation_lab_model.py` says how each parameter is taken). No parameter is fitted to wheel "
             f"data. Data: {row_counts(data)}.", "",
             "| parameter | from the lab (`cmu_sand`) | classical model fitted to the trials |", "|---|---|---|"]
    for k in lab_keys:
        source = {"density": "the sand's bulk density", "cohesion": "shear box, peak envelope",
                  "friction_angle": "shear box, peak envelope", "kc_prime": "Reece fit to the DEM plates",
                  "kphi_prime": "Reece fit to the DEM plates", "n0": "Reece fit to the DEM plates",
                  "shear_modulus_x": "not measured by the lab: the model's default",
                  "a1": "not measured by the lab: the model's default"}[k]
        lines.append(f"| {k} | {getattr(soil, k):.4g} ({source}) | {getattr(fitted, k):.4g} |")
    lines += ["", f"Reece fit to the lab's plates: {reece['points']} points, RMS log-pressure error "
              f"{reece['log_rms']:.3f}.", "",
              "RMS error over every row, normalised by each response's measured spread "
              f"({', '.join(f'{q} {scales[q]:.2f} N' for q in RESPONSES)}):", "",
              "| response | lab's soil | fitted to the trials |", "|---|---|---|"]
    lines += [f"| {q} | {rms['lab'][q]:.3f} | {rms['fitted'][q]:.3f} |" for q in RESPONSES]
    twin = None
    if args.twin is not None:
        twin, twin_lines = three_models(data, preds, scales, args.twin)
        lines += ["", *twin_lines]
    kinds = data.kinds()
    lines += ["", "Rows where the model cannot carry the load at any sinkage up to 0.95 r (`predict`'s `supported` false; "
              "their forces are the model's at that sinkage): " + "; ".join(
                  f"{m}: {int(u.sum())} ({', '.join(f'{int((u & (kinds == k)).sum())} {k}' for k in ('driving', 'braking', 'dragged'))})"
                  for m, u in unsupported.items())]
    lines += ["", "By kind of motion and steering angle (bias and RMS, normalised as above; fitted → lab, the classical "
              "model fitted to the trials, then on the lab's soil; the trend is the lab model's residual's rank "
              "correlation with slip inside the group):", "", *group_table(groups, ("fitted", "lab"))]

    points = None
    if twin is not None:
        points = {"DEM-FEM twin": ModelPoints(twin["measured_rows"], twin["responses"], twin["std"])}
    plot_trials(data, {"lab's soil": preds["lab"], "fitted": preds["fitted"]}, out / "lab-vs-trials.png",
                points=points)
    lines += ["", "![](lab-vs-trials.png)", ""]
    twin_record = None if twin is None else {k: v for k, v in twin.items()
                                             if k not in ("responses", "std", "measured_rows")}
    findings = {"twin": twin_record, "unsupported": {m: int(u.sum()) for m, u in unsupported.items()},
                "lab_soil": soil.to_dict(), "fitted_soil": fitted.to_dict(), "reece_fit": reece, "rms": rms,
                "scales": scales, "residuals_by_group": groups, "provenance": provenance()}
    write_markdown_and_json(out / "README.md", "\n".join(lines), out / "findings.json", findings, default=float)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
