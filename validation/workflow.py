"""``wheelsoil validate``: measured (or synthetic) data in, a report of what the classical model gets wrong,
the named cause and the measured gain out."""

import re
import sys
from pathlib import Path

import numpy as np

from wheelsoil.errors import WheelsoilInputError

from .calibration import normalised_residuals
from .crossval import cross_validate, levels, write_cross_validation
from .discovery import RESPONSES, discover, holdout_mask
from .measured import DOMAINS, Measurements, load_measurements, row_counts, save_measurements
from .terramechanics import SoilParameters
from .model_file import load_model, save_model, write_predictions
from .report import verdict_lines, write_report
from .synthetic import HIDDEN_RANGES, draw_hidden_effect, synthetic_measurements

#: ``--domain driving``'s steering-angle limit: the classical subset, validated before the kinematics were written in
#: velocity components (its lateral shear displacement went as tan(beta)).
MAX_SLIP_ANGLE = 80.0


def prepare(data: Measurements, domain: str = "all") -> tuple[Measurements, tuple, str]:
    """Rows the model can describe, the responses to fit, and a note of what was used, left out and why.

    ``domain`` (:data:`~.measured.DOMAINS`): "all" (every row with a load, braking, dragged and 90 deg included) or
    "driving" (the classical subset: driving slip 0 <= i < 1 along the heading, |slip angle| <= MAX_SLIP_ANGLE)."""
    if domain not in DOMAINS:
        raise WheelsoilInputError(f"--domain {domain!r}: choose one of {list(DOMAINS)}")
    notes = []
    inside = data.load > 0
    if domain == "driving":
        inside &= (data.slip >= 0.0) & (data.slip < 1.0) & (np.abs(data.slip_angle) <= MAX_SLIP_ANGLE)
    measured = np.any([np.isfinite(v) for v in data.responses.values()], axis=0)
    if (~inside).any():
        notes.append(f"left out {int((~inside).sum())} rows outside the domain "
                     + ("(load > 0)" if domain == "all" else
                        f"'driving' (driving slip 0 <= i < 1, |slip angle| <= {MAX_SLIP_ANGLE:g} deg, load > 0)"))
    if (inside & ~measured).any():
        notes.append(f"left out {int((inside & ~measured).sum())} rows with no measured response (empty or NaN)")
    keep = inside & measured
    if not keep.any():
        raise WheelsoilInputError(
            f"{data.name}: no row to fit in the domain {domain!r}: {int((~inside).sum())} of {len(data)} rows lie "
            f"outside it (load > 0: {int((data.load > 0).sum())} rows; driving slip 0 <= i < 1: "
            f"{int(((data.slip >= 0) & (data.slip < 1)).sum())}; |slip angle| <= {MAX_SLIP_ANGLE:g} deg: "
            f"{int((np.abs(data.slip_angle) <= MAX_SLIP_ANGLE).sum())}), {int((~measured).sum())} have no measured "
            "response")
    data = data.select(keep)
    notes.insert(0, f"used {row_counts(data)}")
    responses = [q for q in RESPONSES if np.isfinite(data.responses[q]).any()]
    if data.sinkage_relative and "sinkage" in responses:
        responses.remove("sinkage")
        notes.append("sinkage not fitted (its zero is the wheel's start position, not the soil surface)")
    return data, tuple(responses), "; ".join(notes)


def parse_holdout(spec: str | None, data: Measurements, seed: int) -> np.ndarray:
    if spec is None:
        return holdout_mask(data, seed=seed)
    m = re.fullmatch(r"\s*(\w+)\s*=\s*([-+0-9.eE]+|\w+)\s*", spec)
    conditions = ("slip", "slip_angle", "load", "gravity", "passes", "grouser_height", "group")
    if not m or m.group(1) not in conditions:
        raise WheelsoilInputError(f"--holdout {spec!r}: expected CONDITION=VALUE with CONDITION one of {list(conditions)}")
    key, value = m.group(1), m.group(2)
    return holdout_mask(data, by=key, level=value if key == "group" else float(value))


def select_group(data: Measurements, group: str | None) -> Measurements:
    """The rows whose group starts with ``group`` (all rows for None), named after it."""
    if group is None:
        return data
    rows = np.char.startswith(data.group.astype(str), group)
    if not rows.any():
        raise WheelsoilInputError(f"--group {group!r} matches no rows; groups are {sorted(set(map(str, data.group)))}")
    data = data.select(rows)
    data.name = f"{data.name} [{group}]"
    return data


def _load_prepared(data_arg: str, group: str | None, domain: str = "all") -> tuple[Measurements, tuple, str]:
    return prepare(select_group(load_measurements(data_arg), group), domain)


def test_errors(d, test: Measurements, *, seed: int = 0, bootstrap: int = 400) -> dict:
    """The classical and the final model of ``d`` on a separate test set: per-response and overall RMSE
    normalised by the training scales, and the final model's gain with its paired-bootstrap spread."""
    responses = [q for q in d.responses if np.isfinite(test.responses[q]).any()]
    if not responses:
        raise WheelsoilInputError(f"--test {test.name}: none of the fitted responses {list(d.responses)} is measured")
    base = normalised_residuals(d.baseline.soil, test, responses, d.scales, split=True)
    final = normalised_residuals(d.final.soil, test, responses, d.scales, split=True)
    rms = lambda e: float(np.sqrt(np.mean(e ** 2)))  # noqa: E731
    b, f = np.concatenate(list(base.values())), np.concatenate(list(final.values()))
    idx = np.random.default_rng(seed).integers(0, b.size, size=(bootstrap, b.size))
    diffs = np.sqrt(np.mean(b[idx] ** 2, axis=1)) - np.sqrt(np.mean(f[idx] ** 2, axis=1))
    return {"data": test.name, "rows": len(test), "responses": {q: {"classical_nrmse": rms(base[q]),
                                                                     "final_nrmse": rms(final[q])} for q in responses},
            "classical_nrmse": rms(b), "final_nrmse": rms(f), "gain": rms(b) - rms(f), "gain_std": float(np.std(diffs))}


def validate(data_arg: str, *, report: Path, holdout: str | None = None, responses=None, hidden: str | None = None,
             seed: int = 0, group: str | None = None, command: str = "", test: str | None = None,
             shear_form: str = "independent", domain: str = "all", progress=None) -> dict:
    """Load (or synthesise) the data, run discovery, write the report and ``model.json``; with ``test``, also
    predict that second dataset with the model fitted on the first. ``shear_form``: the model's shear form
    (:class:`~.terramechanics.SoilParameters`; "resultant" is the CMU lab's); ``domain``: the rows to use
    (:func:`prepare`); ``progress``: told what is being fitted (:func:`~.discovery.discover`). Returns the findings
    dict."""
    if domain not in DOMAINS:
        raise WheelsoilInputError(f"--domain {domain!r}: choose one of {list(DOMAINS)}")
    start = SoilParameters(shear_form=shear_form)  # refuses an unknown form before any work
    test_data = None
    if test is not None:  # read and check before any fitting
        if test in ("synthetic", "synthetic-periodic"):
            raise WheelsoilInputError(f"--test {test!r}: give a measured dataset (file or folder)")
        test_data, _, _ = _load_prepared(test, group, domain)
    if data_arg == "synthetic":
        rng = np.random.default_rng(seed)
        if hidden is None:
            name, params = draw_hidden_effect(rng, list(HIDDEN_RANGES) + [None])
        elif hidden == "none":
            name, params = None, {}
        elif hidden in HIDDEN_RANGES:
            name, params = draw_hidden_effect(rng, [hidden])
        else:
            raise WheelsoilInputError(f"--hidden {hidden!r}: choose 'none' or one of {sorted(HIDDEN_RANGES)}")
        data = synthetic_measurements(params, rng)
        report.mkdir(parents=True, exist_ok=True)
        save_measurements(data, report / "synthetic_data.csv")
        title = "Validation on synthetic data (the hidden mechanism is revealed at the end)"
        data = select_group(data, group)
        data, default_responses, excluded = prepare(data, domain)
    else:
        if hidden is not None:
            raise WheelsoilInputError("--hidden applies to 'synthetic' data only")
        data, default_responses, excluded = _load_prepared(data_arg, group, domain)
        title = f"Validation against {data.name}"
        name = params = None
    mask = parse_holdout(holdout, data, seed)
    d = discover(data, responses=responses or default_responses, heldout=mask, seed=seed, start=start,
                 progress=progress)
    extra = {"shear_form": shear_form, "domain": domain}
    if test_data is not None:
        extra["test"] = test_errors(d, test_data, seed=seed)
    md, _, findings = write_report(d, data, mask, report, title=title, command=command, excluded=excluded, extra=extra)
    save_model(report / "model.json", d, data.select(~mask), command=command)
    if data_arg == "synthetic":
        with open(md, "a") as fh:
            fh.write(f"\n## The hidden truth\n\nHidden: {name or 'nothing'} {params or ''}\n")
    findings["report"] = str(md)
    findings["model"] = str(report / "model.json")
    if data_arg == "synthetic":
        findings["hidden"] = {"name": name, "parameters": params}
    return findings


def cross_validate_command(data_arg: str, by: str, *, report: Path, responses=None, group: str | None = None,
                           seed: int = 0, command: str = "", progress=None, shear_form: str = "independent",
                           domain: str = "all", resume: bool = False) -> dict:
    """``wheelsoil validate DATA --cv CONDITION``: leave each level of CONDITION out in turn (:mod:`.crossval`);
    with ``resume``, finished folds are kept in ``report/folds`` and reused by a later run."""
    start = SoilParameters(shear_form=shear_form)
    data, default_responses, _ = _load_prepared(data_arg, group, domain)
    levels(data, by)  # refuse a bad condition before any fitting
    cv = cross_validate(data, by, responses=responses or default_responses, seed=seed, progress=progress,
                        start=start, resume_dir=Path(report) / "folds" if resume else None)
    cv["shear_form"] = shear_form
    cv["domain"] = domain
    cv["report"] = str(write_cross_validation(cv, data, report, command=command))
    return cv


def predict_command(model_path: str, data_arg: str, *, out: Path, group: str | None = None) -> dict:
    """``wheelsoil predict MODEL DATA``: the saved model's predictions and errors on DATA."""
    model = load_model(model_path)
    data, _, _ = _load_prepared(data_arg, group)
    path, errors = write_predictions(model, data, out)
    return {"predictions": str(path), "errors": errors, "mechanisms": model.mechanisms, "named": model.named,
            "rows": len(data)}


def simulated_runs(model_args) -> Measurements:
    """The DEM--FEM runs of one or more sweep folders (or ``summary.csv`` files) as one dataset, in the order given;
    the steady runs of each (:func:`.measured.load_sweep_summary`), their notes joined."""
    from dataclasses import replace

    from .candidate_test import concat_runs
    from .measured import load_sweep_summary

    paths = [model_args] if isinstance(model_args, (str, Path)) else list(model_args)
    if "semi-empirical" in map(str, paths):
        raise WheelsoilInputError(f"--model {' '.join(map(str, paths))}: 'semi-empirical' is a model of its own; give "
                                  "it alone, or only sweep folders")
    parts = [load_sweep_summary(p) for p in paths]
    if len(parts) == 1:
        return parts[0]
    runs = concat_runs(" + ".join(p.name for p in parts), parts)
    return replace(runs, notes="; ".join(p.notes.rstrip(".") for p in parts if p.notes))


def validate_against_simulation(data_arg: str, model_arg, *, report: Path, responses=None, group: str | None = None,
                                command: str = "", allow_unpaired: bool = False) -> dict:
    """``wheelsoil validate DATA --model SWEEP [SWEEP ...]``: the DEM--FEM runs of one or more sweeps as the model
    (:func:`simulated_runs`), compared with the measured data condition by condition (:mod:`.compare`). A run that
    twins no measured condition is refused (:func:`.compare.check_every_run_paired`) unless ``allow_unpaired``."""
    from .compare import check_every_run_paired, compare, write_comparison_report

    if data_arg in ("synthetic", "synthetic-periodic"):
        raise WheelsoilInputError(f"--model {model_arg!r} compares simulations with measured data; DATA {data_arg!r} is "
                                  "not measured")
    data = load_measurements(data_arg)
    data = select_group(data, group)
    simulated = simulated_runs(model_arg)
    if not allow_unpaired:
        check_every_run_paired(data, simulated)
    return write_comparison_report(compare(data, simulated, responses), data, simulated, report, command=command)


def main_validate(args) -> int:
    from rich.console import Console

    console = Console()
    command = "wheelsoil " + " ".join(getattr(args, "argv", None) or sys.argv[1:])
    models = getattr(args, "model", ["semi-empirical"])
    models = [models] if isinstance(models, (str, Path)) else list(models)
    if models != ["semi-empirical"]:
        f = validate_against_simulation(args.data, models, report=args.report, responses=args.responses,
                                        group=args.group, command=command,
                                        allow_unpaired=getattr(args, "allow_unpaired_runs", False))
        console.print(f"{f['pairs']} measured conditions paired with a simulated run ({f['unmatched']} without)")
        for q, v in f["responses"].items():
            console.print(f"  {q:14s} bias/spread {v['nbias']:+.3f}  RMS/spread {v['nrmse']:.3f}")
        for t in f["systematic"]:
            console.print(f"  systematic: {t['response']} error vs {t['condition']} (Spearman {t['spearman']:+.2f}, "
                          f"p = {t['p_value']:.1g})")
        console.print(f"wrote {f['report']}")
        return 0
    if getattr(args, "cv", None):
        def show(fold):
            partial = f" (partial: {', '.join(fold['partial'])})" if fold["partial"] else ""
            console.print(f"  held out {args.cv} = {fold['level']}: found {', '.join(fold['found']) or 'nothing'}"
                          f"{partial}; "
                          f"classical {fold['classical_nrmse']:.3f} -> {fold['final_nrmse']:.3f} "
                          f"(gain {fold['gain']:+.3f} +- {fold['gain_std']:.3f})", markup=False)

        cv = cross_validate_command(args.data, args.cv, report=args.report, responses=args.responses,
                                    group=args.group, seed=args.seed, command=command, progress=show,
                                    shear_form=args.shear_form, domain=getattr(args, "domain", "all"),
                                    resume=getattr(args, "resume", False))
        console.print(f"wrote {cv['report']}")
        return 0
    with console.status("reading the data") as status:  # a status line: the fits' number is not known in advance
        findings = validate(args.data, report=args.report, holdout=args.holdout, responses=args.responses,
                            hidden=args.hidden, seed=args.seed, group=args.group, command=command,
                            test=getattr(args, "test", None), shear_form=getattr(args, "shear_form", "independent"),
                            domain=getattr(args, "domain", "all"), progress=status.update)
    base = findings["baseline"]
    console.print(f"classical model: RMSE {base['train_rmse']:.3f} (train), {base['heldout_rmse']:.3f} (held out); "
                  f"final model: {findings['final']['heldout_rmse']:.3f} (held out)")
    for s in findings["steps"]:
        console.print(f"step {s['step'] + 1} (on {' + '.join(['classical'] + s['model'])}):")
        deferred = [g[0] for g in s.get("deferred", [])]
        for c in s["candidates"]:
            tag = ("  ACCEPTED" if c["accepted"] else "  ambiguous" if c["name"] in s["ambiguity"]
                   else "  deferred" if c["name"] in deferred else "")
            console.print(f"  {c['name']:18s} gain {c['gain']:+.4f} +- {c['gain_std']:.4f}  dBIC {c['delta_bic']:+8.1f}"
                          f"  removes {100 * c['explained']:3.0f} %{tag}")
    for line in verdict_lines(findings):
        console.print(line, markup=False, highlight=False)
    if "test" in findings:
        t = findings["test"]
        console.print(f"test set {t['data']} ({t['rows']} rows): classical {t['classical_nrmse']:.3f} -> final "
                      f"{t['final_nrmse']:.3f} (gain {t['gain']:+.3f} +- {t['gain_std']:.3f})", markup=False)
    if "hidden" in findings:
        console.print(f"hidden: {findings['hidden']['name']} {findings['hidden']['parameters']}")
    console.print(f"wrote {findings['report']}, {Path(findings['report']).with_name('findings.json')} and "
                  f"{findings['model']}")
    return 0
