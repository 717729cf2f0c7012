"""Example validation reports (issue 6), written to docs/validation/<example>/ (report.md, findings.json,
plots) and summarised in docs/validation/README.md.

Each example is one ``wheelsoil validate`` call, so every number in the reports is reproducible from the
command printed in it. Usage (from the repository root; about half an hour on 2 cores, most of it the three
cross-validations)::

    python docs/validation_examples.py
    python docs/validation_examples.py --tables-only   # rewrite README.md (and crossval.md) from the saved JSON
    python docs/validation_examples.py --only cmu-random-holdout cmu-large-steering   # rerun these, keep the rest

The cross-validations resume (``--resume``): their finished folds are kept in ``<example>/folds``.
"""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent
MEASURED = Path("..") / "shared" / "data" / "measured"  # relative to the repository root, as in the commands

#: example -> (DATA, extra arguments, what it asks)
EXAMPLES = {
    "cmu-large-steering": (str(MEASURED / "cmu_3d_terramechanics"), ["--holdout", "slip_angle=60"],
                           "calibrated on the other steering angles (0-45, 75 and 90 deg), does the model carry to "
                           "60 deg?"),
    "cmu-random-holdout": (str(MEASURED / "cmu_3d_terramechanics"), ["--seed", "0"],
                           "both wheels, all angles, a random 30 % held out: what does the model miss?"),
    "digitised-ding2011": (str(MEASURED / "digitised_single_wheel" / "single_wheel_experiments.csv"),
                           ["--group", "ding2011"], "Ding et al. 2011, smooth and lugged wheel, DP/sinkage/torque"),
    "cmu-smooth-to-grouser": (str(MEASURED / "cmu_3d_terramechanics" / "smooth_wheel_trials.csv"),
                              ["--test", str(MEASURED / "cmu_3d_terramechanics" / "grouser_wheel_trials.csv")],
                              "fitted on the smooth wheel, tested on the grousered one: what carries over?"),
    "synthetic-hidden": ("synthetic", ["--seed", "5"], "a mechanism hidden in synthetic data, drawn at random"),
    "dem-smoke-figures": ("docs/sweeps/smoke-figures/summary.csv", [],
                          "the 18 DEM-FEM runs of the smoke-figures sweep as data: what does the classical model "
                          "miss of the simulation?"),
}

#: leave-one-steering-angle-out cross-validation on the CMU data: each wheel, and both together
CV_EXAMPLES = {
    "cmu-cv-steering-both": (str(MEASURED / "cmu_3d_terramechanics"), "both wheels"),
    "cmu-cv-steering-smooth": (str(MEASURED / "cmu_3d_terramechanics" / "smooth_wheel_trials.csv"), "smooth wheel"),
    "cmu-cv-steering-grouser": (str(MEASURED / "cmu_3d_terramechanics" / "grouser_wheel_trials.csv"),
                                "grousered wheel"),
}

#: periodic examples: drawbar-pull series with a hidden periodic mechanism (``wheelsoil validate synthetic-periodic``)
PERIODIC_EXAMPLES = {
    "synthetic-periodic-density-wave": (["--hidden", "density_wave", "--seed", "1"],
                                        "seed 002's slip-dependent density wave hidden in red noise"),
    "synthetic-periodic-spoke-radius": (["--hidden", "spoke_radius", "--seed", "1"],
                                        "seed 000's spoke-stiffness surrogate radius hidden in red noise"),
    "synthetic-periodic-nothing": (["--hidden", "none", "--seed", "1"], "red noise only: nothing may be found"),
}


#: The commit from which the CMU loader reads the rig's slip along the heading (docs/validation/slip-convention).
HEADING_SLIP_COMMIT = "80e220b"
#: The commit from which the model covers every measured row (braking, dragged, 90 deg) and the loader keeps them.
WHOLE_DOMAIN_COMMIT = "2b598e7"


def _predates(out: Path, commit: str) -> bool:
    """Whether the saved run in ``out`` was made before ``commit`` (its provenance's commit is not a descendant)."""
    saved = out / "findings.json" if (out / "findings.json").is_file() else out / "crossval.json"
    rev = json.loads(saved.read_text()).get("provenance", {}).get("git_rev", "")
    rev = rev.split("-")[0].split("+")[0]
    done = subprocess.run(["git", "merge-base", "--is-ancestor", commit, rev], capture_output=True)
    return done.returncode != 0


def main(argv=None) -> int:
    import os

    from wheelsoil.cases.cli import main as validate_cli
    from wheelsoil.validation.crossval import carry_verdicts

    args = sys.argv[1:] if argv is None else argv
    tables_only = "--tables-only" in args
    only = set(args[args.index("--only") + 1:]) if "--only" in args else None

    def cli(argv, name):
        """Run the example; with ``--tables-only`` keep its saved run and write its tables again; with ``--only``,
        leave the examples it does not name as they are."""
        if only is not None and name not in only:
            return 0
        if tables_only:
            return _rewrite_crossval(argv)
        return validate_cli(argv)

    os.chdir(ROOT.parent)  # the repository root: the commands in the reports are relative to it
    rows = ["# Validation examples", "", "Generated by `python docs/validation_examples.py`; each folder holds "
            "`report.md`, `findings.json`, `model.json` and the plots of one `wheelsoil validate` run. The "
            "workflow calibrates the classical model, then selects mechanisms forward (see the reports); *partial* "
            "means accepted by the selection but not named, because the model still leaves a systematic residual "
            "where the mechanism acts. Rates over many synthetic draws: [campaigns.md](campaigns.md).", "",
            "| example | question | held-out RMSE, classical → final | found | partial | unexplained |",
            "|---|---|---|---|---|---|"]
    for name, (data, extra, question) in EXAMPLES.items():
        out = ROOT / "validation" / name
        argv = ["validate", data, "--report", str(out.relative_to(ROOT.parent)), *extra]
        print("wheelsoil", " ".join(argv), flush=True)
        if cli(argv, name) != 0:
            return 1
        f = json.loads((out / "findings.json").read_text())
        found = ", ".join(f"{c['name']} ({c['gain']:+.3f} ± {c['gain_std']:.3f}, ΔBIC {c['delta_bic']:+.1f})"
                          for c in f["accepted"]) or "nothing"
        partial = ", ".join(c["name"] for c in f["partial"]) or "–"
        unexplained = "; ".join(u["text"] for u in f["unexplained"]) or "–"
        test = (f"; on the test set {f['test']['classical_nrmse']:.3f} → {f['test']['final_nrmse']:.3f}"
                if "test" in f else "")
        rows.append(f"| [{name}]({name}/report.md) | {question} | {f['baseline']['heldout_rmse']:.3f} → "
                    f"{f['final']['heldout_rmse']:.3f}{test} | {found} | {partial} | {unexplained} |")
    rows += ["", "## Leave one steering angle out", "",
             "Each steering angle of the CMU data held out in turn; the workflow runs on the other angles and predicts "
             "the held-out one (`--cv slip_angle`). Gains per held-out angle are in each `crossval.md`.", "",
             "| example | data | found in how many folds | carried to the angle held out (folds with a gain above "
             "two bootstrap sd, of those with it in the model) | a residual trend left unexplained, folds | gain per "
             "held-out angle |", "|---|---|---|---|---|---|"]
    for name, (data, what) in CV_EXAMPLES.items():
        out = ROOT / "validation" / name
        argv = ["validate", data, "--cv", "slip_angle", "--report", str(out.relative_to(ROOT.parent)), "--resume"]
        print("wheelsoil", " ".join(argv), flush=True)
        if cli(argv, name) != 0:
            return 1
        cv = json.loads((out / "crossval.json").read_text())
        n = len(cv["folds"])
        found = ", ".join(f"{k} {v}/{n}" for k, v in cv["found_in"].items()) or f"nothing in {n} folds"
        partial = [f"{f['level']:g}°: {', '.join(f['partial'])}" for f in cv["folds"] if f.get("partial")]
        if partial:
            found += "; partial (accepted, not named) " + "; ".join(partial)
        gains = ", ".join(f"{f['level']:g}°: {f['gain']:+.3f} ± {f['gain_std']:.3f}" for f in cv["folds"])
        unexplained = sum(1 for f in cv["folds"] if f["unexplained"])
        carried = ", ".join(f"{v['mechanism']} {len(v['carried'])}/{len(v['carried']) + len(v['not_carried'])}"
                            for v in carry_verdicts(cv)) or "–"
        rows.append(f"| [{name}]({name}/crossval.md) | {what} | {found} | {carried} | {unexplained}/{n} | {gains} |")
    rows += ["", "## Periodic effects in time series", "",
             "| example | question | frequency law | amplitude mechanism | parameter (hidden) | held-out gain in log "
             "amplitude |", "|---|---|---|---|---|---|"]
    for name, (extra, question) in PERIODIC_EXAMPLES.items():
        out = ROOT / "validation" / name
        argv = ["validate", "synthetic-periodic", "--report", str(out.relative_to(ROOT.parent)), *extra]
        print("wheelsoil", " ".join(argv), flush=True)
        if cli(argv, name) != 0:
            return 1
        f = json.loads((out / "findings.json").read_text())
        law = f["frequency_law"]["found"] or "nothing"
        if f["found"]:
            m = f["amplitude"]["models"][f["found"]]
            truth = ", ".join(f"{k} = {v:.4g}" for k, v in f["hidden"]["parameters"].items())
            rows.append(f"| [{name}]({name}/report.md) | {question} | {law} | {f['found']} | {m['parameter']} = "
                        f"{m['value']:.4g} ({truth}) | {m['gain']:+.3f} ± {m['gain_se']:.3f} |")
        else:
            rows.append(f"| [{name}]({name}/report.md) | {question} | {law} | nothing | – | – |")
    cmu = [n for n, (data, *_) in {**EXAMPLES, **CV_EXAMPLES}.items() if "cmu_3d_terramechanics" in data]
    stale = [n for n in cmu if _predates(ROOT / "validation" / n, HEADING_SLIP_COMMIT)]
    if stale:
        rows[1:1] = ["", f"**Note:** {', '.join(stale)} predate the CMU loader's reading of the rig's slip along the "
                     "heading ([slip-convention](slip-convention/README.md)): they fitted the model at the wrong slips "
                     "above 0 deg and are to be run again (`--only NAME`)."]
    driving_only = [n for n in cmu if n not in stale and _predates(ROOT / "validation" / n, WHOLE_DOMAIN_COMMIT)]
    if driving_only:
        rows[1:1] = ["", f"**Note:** {', '.join(driving_only)} predate the model over the whole measured domain: they "
                     "used the driving rows below 90 deg only (148 of 297), not the braking, dragged and 90 deg rows, "
                     "and are to be run again (`--only NAME`)."]
    (ROOT / "validation" / "README.md").write_text("\n".join(rows) + "\n")
    return 0


def _rewrite_verdict(out: Path) -> None:
    """A report's verdict section written again from its ``findings.json`` (the run is not repeated): the verdict's
    wording is a function of the findings (:func:`wheelsoil.validation.report.verdict_lines`)."""
    from wheelsoil.validation.report import verdict_lines

    md = out / "report.md"
    lines = md.read_text().split("\n")
    start = lines.index("## Verdict") + 2
    end = next(k for k in range(start, len(lines)) if not lines[k].startswith("- "))
    lines[start:end] = [f"- {v}" for v in verdict_lines(json.loads((out / "findings.json").read_text()))]
    md.write_text("\n".join(lines))


def _rewrite_crossval(argv) -> int:
    """Stands in for the CLI with ``--tables-only``: a cross-validation's ``crossval.md`` is written again from
    its ``crossval.json`` (the folds are not rerun); a report's verdict from its ``findings.json``."""
    if "--cv" not in argv:
        if "--periodic" not in argv and argv[1] not in ("synthetic-periodic",):
            _rewrite_verdict(Path(argv[argv.index("--report") + 1]))
        return 0
    from wheelsoil.validation.crossval import write_cross_validation
    from wheelsoil.validation.measured import load_measurements

    out = Path(argv[argv.index("--report") + 1])
    cv = json.loads((out / "crossval.json").read_text())
    command = cv.pop("command", "")
    record = cv.pop("provenance", None)  # the run's own: the tables are new, the run is not
    write_cross_validation(cv, load_measurements(argv[1]), out, command=command, provenance_record=record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
