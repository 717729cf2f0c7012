"""Leave-one-condition-out cross-validation of the discovery workflow.

Each level of a condition (a steering angle, a load, a gravity level, a wheel) is held out in turn; the whole
workflow (classical calibration, forward selection) runs on the other levels, and the held-out level is predicted
by the classical and by the final model. The gain per held-out level shows whether a finding carries beyond the
conditions it was fitted on, and the mechanisms found per fold whether the finding itself is stable.

Each fold is independent (its bootstrap draws from its own seed, (seed, fold index)), so a cross-validation
resumes: with ``resume_dir`` every finished fold is written there as it ends and kept by a later run of the same
data, selection rule (:func:`~.selection.rule_digest`), responses, seed and starting soil (``wheelsoil validate --cv
... --resume``); a fold saved under another rule is computed again.
"""

import hashlib
import json
from pathlib import Path

import numpy as np

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.provenance import atomic_output, provenance, write_markdown_and_json

from .calibration import normalised_residuals
from .discovery import discover
from .measured import Measurements
from .selection import rule_digest

CV_CONDITIONS = ("slip", "slip_angle", "load", "gravity", "passes", "grouser_height", "group")

#: A fold's held-out gain carries when it exceeds this many of its bootstrap standard deviations (about a one-sided
#: 2.3 % chance of a gain that large from a final model no better than the classical one).
CARRY_SIGMAS = 2.0


def levels(data: Measurements, by: str) -> list:
    """The distinct levels of condition ``by`` in ``data`` (sorted)."""
    if by not in CV_CONDITIONS:
        raise WheelsoilInputError(f"--cv {by!r}: choose a condition from {list(CV_CONDITIONS)}")
    values = np.asarray(getattr(data, by))
    out = sorted(set(values.tolist()))
    if len(out) < 2:
        raise WheelsoilInputError(f"--cv {by}: the data hold a single level ({out[0]!r}); nothing to hold out")
    return out


def _data_digest(data: Measurements) -> str:
    """A digest of every condition and response of ``data`` (what a saved fold's data must match)."""
    digest = hashlib.sha256()
    for key in ("slip", "slip_angle", "load", "gravity", "passes", "radius", "width", "grouser_height",
                "grouser_count", "travel_slip"):
        digest.update(np.ascontiguousarray(getattr(data, key), float).tobytes())
    for q in sorted(data.responses):
        digest.update(q.encode() + np.ascontiguousarray(data.responses[q], float).tobytes())
    digest.update("|".join(map(str, data.group)).encode())
    return digest.hexdigest()[:20]


def _fold_key(digest: str, rule: str, by: str, level, responses, seed: int, bootstrap: int, start) -> dict:
    """What a saved fold must match to be kept: the data (:func:`_data_digest`), the selection rule
    (:func:`~.selection.rule_digest`), the held-out level, the responses, the seed, the bootstrap size and the
    starting soil."""
    return {"data": digest, "rule": rule, "condition": by,
            "level": level if isinstance(level, str) else float(level),
            "responses": list(responses), "seed": seed, "bootstrap": bootstrap,
            "start": None if start is None else start.to_dict()}


def cross_validate(data: Measurements, by: str, *, responses, seed: int = 0, bootstrap: int = 400,
                   progress=None, start=None, resume_dir: str | Path | None = None) -> dict:
    """Hold out each level of ``by`` in turn (see the module docstring). Returns a dict with one fold per level:
    the mechanisms found, the classical and final model's normalised RMSE on the held-out level, the gain and its
    bootstrap standard deviation. ``start``: the soil every fold starts from (:func:`.discovery.discover`), e.g.
    with the lab's ``shear_form``. A mechanism accepted on the rest but not named (``partial``: the model still
    leaves a systematic residual where it acts) is in the final model, so it can carry a gain. ``resume_dir``: keep
    finished folds there and reuse those that match (module docstring)."""
    values = np.asarray(getattr(data, by))
    folds = []
    digest = _data_digest(data) if resume_dir is not None else ""
    rule = rule_digest()
    for k, level in enumerate(levels(data, by)):
        mask = values == level
        saved = None
        if resume_dir is not None:
            key = _fold_key(digest, rule, by, level, responses, seed, bootstrap, start)
            saved = Path(resume_dir) / f"fold-{k}.json"
            if saved.is_file():
                kept = json.loads(saved.read_text())
                if kept.get("key") == key:
                    folds.append(kept["fold"])
                    if progress:
                        progress(folds[-1])
                    continue
        rng = np.random.default_rng([seed, k])
        d = discover(data, responses=responses, heldout=mask, seed=seed, bootstrap=bootstrap, start=start)
        test = data.select(mask)
        base = normalised_residuals(d.baseline.soil, test, d.responses, d.scales)
        final = normalised_residuals(d.final.soil, test, d.responses, d.scales)
        idx = rng.integers(0, base.size, size=(bootstrap, base.size))
        diffs = np.sqrt(np.mean(base[idx] ** 2, axis=1)) - np.sqrt(np.mean(final[idx] ** 2, axis=1))
        b, f = float(np.sqrt(np.mean(base ** 2))), float(np.sqrt(np.mean(final ** 2)))
        folds.append({"level": level if isinstance(level, str) else float(level), "rows": int(mask.sum()),
                      "found": d.found, "partial": [n for c in d.partial for n in c.names],
                      "ambiguities": d.ambiguities,
                      "unexplained": [u["text"] for u in d.unexplained], "classical_nrmse": b, "final_nrmse": f,
                      "gain": b - f, "gain_std": float(np.std(diffs))})
        if saved is not None:
            saved.parent.mkdir(parents=True, exist_ok=True)
            with atomic_output(saved) as tmp:
                tmp.write_text(json.dumps({"key": key, "fold": folds[-1]}, indent=1, default=float))
        if progress:
            progress(folds[-1])
    names = sorted({n for fold in folds for n in fold["found"]})
    return {"condition": by, "folds": folds, "found_in": {n: sum(n in f["found"] for f in folds) for n in names},
            "selection_rule": rule}


def carry_verdicts(cv: dict) -> list[dict]:
    """Whether each mechanism carries to the levels held out: for every mechanism in any fold's final model (named, or
    accepted as partial), the levels where it was named and where partial, the held-out gain of each of those folds,
    the levels where that gain exceeds :data:`CARRY_SIGMAS` of its bootstrap standard deviation (``carried``) and
    where it does not (``not_carried``), and a verdict. The gain is the fold's final model's, with every mechanism it
    holds in that fold, so a mechanism is credited only with the gain of the models it is part of; named in fewer
    folds than there are, it is also not a stable finding of the data, and the verdict says so."""
    folds = cv["folds"]
    names = sorted({n for f in folds for n in (*f["found"], *f.get("partial", ()))})
    out = []
    for name in names:
        named = [f for f in folds if name in f["found"]]
        partial = [f for f in folds if name in f.get("partial", ()) and name not in f["found"]]
        in_model = [f for f in folds if name in f["found"] or name in f.get("partial", ())]
        carried = [f["level"] for f in in_model if f["gain"] > CARRY_SIGMAS * f["gain_std"]]
        not_carried = [f["level"] for f in in_model if f["level"] not in carried]
        if not not_carried:
            verdict = "carries to every level held out where it is in the model"
        elif not carried:
            verdict = "does not carry: no held-out gain where it is in the model"
        else:
            verdict = "carries to some levels held out, not to others"
        if named and len(named) < len(folds):
            verdict += f"; named in {len(named)} of {len(folds)} folds only: not a stable finding"
        out.append({"mechanism": name, "named": [f["level"] for f in named], "partial": [f["level"] for f in partial],
                    "gains": {str(f["level"]): (f["gain"], f["gain_std"]) for f in in_model},
                    "carried": carried, "not_carried": not_carried, "verdict": verdict})
    return out


def _carry_lines(cv: dict, by: str) -> list[str]:
    """The section of ``crossval.md`` that says whether each finding carries (:func:`carry_verdicts`)."""
    verdicts = carry_verdicts(cv)
    if not verdicts:
        return []

    def levels_text(values) -> str:
        return ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in values) or "–"

    lines = ["## Does each finding carry to the level held out?", "",
             f"A fold's gain counts as carried above {CARRY_SIGMAS:g} of its bootstrap standard deviations; the gain "
             "is the fold's final model's, with every mechanism it holds there.", "",
             f"| mechanism | named, held-out {by} | partial, held-out {by} | carried to | not carried to | verdict |",
             "|---|---|---|---|---|---|"]
    for v in verdicts:
        lines.append(f"| {v['mechanism']} | {levels_text(v['named'])} | {levels_text(v['partial'])} | "
                     f"{levels_text(v['carried'])} | {levels_text(v['not_carried'])} | {v['verdict']} |")
    return lines + [""]


def write_cross_validation(cv: dict, data: Measurements, out: str | Path, *, command: str = "",
                           provenance_record: dict | None = None) -> Path:
    """``crossval.md`` and ``crossval.json`` in ``out``; ``provenance_record``: the run's own, when the files are
    written again from a stored run (default: this process's)."""
    out = Path(out)
    by = cv["condition"]
    lines = [f"# Leave-one-{by.replace('_', '-')}-out cross-validation: {data.name}", "",
             f"Each level of {by.replace('_', ' ')} is held out in turn; the classical model is calibrated and the "
             "mechanisms are selected on the other levels, then both models predict the held-out level (RMSE "
             "normalised by the training data's spread).", ""]
    if command:
        lines += ["Reproduce: `" + command + "`", ""]
    lines += [f"| held-out {by} | rows | found on the rest | unexplained on the rest | classical | final | gain |",
              "|---|---|---|---|---|---|---|"]
    for f in cv["folds"]:
        found = ", ".join(f["found"]) or "nothing"
        if f.get("partial"):
            found += "; partial (accepted, not named): " + ", ".join(f["partial"])
        if f["ambiguities"]:
            found += "; ambiguous: " + "; ".join(" or ".join(g) for g in f["ambiguities"])
        unexplained = "; ".join(f["unexplained"]) or "–"
        lines.append(f"| {f['level']} | {f['rows']} | {found} | {unexplained} | {f['classical_nrmse']:.3f} | "
                     f"{f['final_nrmse']:.3f} | {f['gain']:+.3f} ± {f['gain_std']:.3f} |")
    n = len(cv["folds"])
    lines += ["", "Found in how many folds: " + (", ".join(f"{k} {v} of {n}" for k, v in cv["found_in"].items())
                                                 or "nothing in any fold"), ""]
    lines += _carry_lines(cv, by.replace("_", " "))
    md = out / "crossval.md"
    write_markdown_and_json(md, "\n".join(lines), out / "crossval.json", {
        **cv, "carry": carry_verdicts(cv), "command": command, "provenance": provenance_record or provenance()},
        default=float)
    return md
