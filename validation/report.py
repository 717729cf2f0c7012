"""The validation report: markdown with plots, and a JSON of the findings, for one discovery run.

One truth: the findings dict (:meth:`Discovery.to_dict` plus the run's metadata) is built once, and the terminal
summary (:func:`verdict_lines`), ``report.md``, ``findings.json`` and the plots' titles are all written from it, so
they name the same accepted mechanisms, ambiguities and unexplained trends.
"""

from pathlib import Path

import numpy as np

from wheelsoil.plotting import pyplot
from wheelsoil.provenance import atomic_output, provenance, write_markdown_and_json

from .discovery import (
    AMBIGUITY_MARGIN,
    BIC_MARGIN,
    GAIN_SIGMAS,
    MIN_EXPLAINED,
    PAIR_POOL,
    RIVAL_MARGIN,
    Discovery,
    model_responses,
)
from .measured import Measurements
from .residuals import group_table, residuals_by_group
from .selection import PREDICTION_NOT_WORSE, rule_digest

UNITS = {"drawbar_pull": ("N", 1.0), "lateral_force": ("N", 1.0), "sinkage": ("mm", 1e3), "torque": ("N m", 1.0)}


def _save(fig, path: Path) -> None:
    import matplotlib.pyplot as plt

    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def verdict_lines(findings: dict) -> list[str]:
    """What the run concluded, in plain lines: accepted mechanisms with their parameters, ambiguities,
    unexplained trends, flagged baseline parameters. The terminal, ``report.md`` and the plots use these."""
    lines = []
    for c in findings["accepted"]:
        params = ", ".join(f"{k} = {v['value']:.4g} ± {v['std_error']:.2g}" for k, v in c["parameters"].items())
        lines.append(f"found: {c['name']} ({params}; step {c['step'] + 1}, ΔBIC {c['delta_bic']:+.1f}, held-out gain "
                     f"{c['gain']:+.4f} ± {c['gain_std']:.4f}, removes {100 * c['explained']:.0f} % of the systematic "
                     f"residual) — {c['source']}")
        close = [r for r in findings["steps"][c["step"]].get("rivals", [])
                 if r.get("against", c["name"]) == c["name"] and r["bic_vs_accepted"] < AMBIGUITY_MARGIN]
        if close:
            lines.append("  but a generic drift fits about as well in its place: "
                         + "; ".join(f"{r['description']} in place of {r['replaces']} (ΔBIC {r['bic_vs_accepted']:+.1f} "
                                     "against it)" for r in close)
                         + f"; named because no drift fits better by more than {RIVAL_MARGIN:g}")
    for c in findings["partial"]:
        lines.append(f"partial: {c['name']} was accepted by the selection (ΔBIC {c['delta_bic']:+.1f}, removes "
                     f"{100 * c['explained']:.0f} % of the systematic residual) but is not named as the cause: with it "
                     f"the model still leaves {'; '.join(c['partial_because'])}")
    if not findings["accepted"]:
        lines.append("found: nothing")
    for step in findings["steps"]:
        for group in step.get("deferred", []):
            lines.append(f"deferred at step {step['step'] + 1}: {group[0]} passes but does not beat "
                         f"{' or '.join(group[1:])} on that model; it was tried again with another mechanism in the "
                         "model (at the next step, or in a pair)")
        group = step["ambiguity"]
        if not group:
            continue
        rivals = {}
        for r in step.get("rivals", []):  # sorted best first: a drift fitted in place of two members keeps its best
            if r.get("against", group[0]) == group[0]:
                rivals.setdefault(r["name"], r)
        generic = [rivals[n] for n in group if n in rivals]
        if generic:
            alternatives = "; ".join(f"{r['name']} in place of {r['replaces']}: {r['description']}, ΔBIC "
                                     f"{r['bic_vs_accepted']:+.1f} against it" for r in generic)
            lines.append(f"ambiguous: {group[0]} passes every check but is not named, because a generic drift explains "
                         f"the same residual better ({alternatives}); the data prefer another form to the "
                         "mechanism's")
        else:
            lines.append(f"ambiguous: {' or '.join(group)} explain the same residual about equally well (ΔBIC within "
                         f"{BIC_MARGIN:g}); the data cannot tell them apart, so neither is named")
    for u in findings["unexplained"]:
        trend = f", Spearman {u['spearman']:+.2f}" if u["spearman"] is not None else ""
        lines.append(f"unexplained: {u['text']} (shares of its systematic residual{trend}, lack-of-fit "
                     f"p = {u['p_value']:.1g})")
    base = findings["baseline"]
    if base["unidentified"]:
        lines.append(f"not identified by these data (classical model): {', '.join(base['unidentified'])}")
    if base["at_bounds"]:
        lines.append("at a bound (classical model): " + ", ".join(f"{k} ({v})" for k, v in base["at_bounds"].items()))
    return lines


def plot_fits(findings: dict, d: Discovery, data: Measurements, heldout: np.ndarray, predictions: dict,
              path: Path) -> None:
    """Predicted against measured, classical and final model (``predictions``: "classical" and "final", each
    response -> every row), training and held-out rows."""
    plt = pyplot()
    preds = [("classical", predictions["classical"])]
    if findings["final"]["mechanisms"]:
        preds.append(("+ " + " + ".join(findings["final"]["mechanisms"]), predictions["final"]))
    fig, axes = plt.subplots(1, len(d.responses), figsize=(4.2 * len(d.responses), 4), squeeze=False)
    for ax, q in zip(axes[0], d.responses):
        unit, k = UNITS[q]
        y = k * data.responses[q]
        for (label, pred), color in zip(preds, ("C0", "C3")):
            for rows, marker, tag in ((~heldout, "o", "train"), (heldout, "^", "held out")):
                ax.scatter(y[rows], k * pred[q][rows], s=14, marker=marker, color=color, alpha=0.7,
                           label=f"{label} ({tag})")
        lim = np.nanmin(y), np.nanmax(y)
        ax.plot(lim, lim, color="0.5", lw=0.8)
        ax.set_xlabel(f"measured {q.replace('_', ' ')} [{unit}]")
        ax.set_ylabel(f"model [{unit}]")
    axes[0][0].legend(fontsize=7)
    fig.suptitle("found: " + (", ".join(findings["found"]) or "nothing"), fontsize=10)
    fig.tight_layout()
    _save(fig, path)


def plot_residuals(findings: dict, d: Discovery, data: Measurements, pred: dict, path: Path) -> None:
    """Final-model residuals (``pred``: its predictions, response -> every row) against the condition that carries
    most of each response's remaining trend."""
    plt = pyplot()
    unexplained = {u["response"]: u for u in findings["unexplained"]}
    fig, axes = plt.subplots(1, len(d.responses), figsize=(4.2 * len(d.responses), 3.6), squeeze=False)
    for ax, q in zip(axes[0], d.responses):
        trend = next((t for t in d.trends if t["response"] == q), None)
        cond = unexplained[q]["condition"] if q in unexplained else (trend["condition"] if trend else "slip")
        x = np.asarray(getattr(data, cond), float)
        unit, k = UNITS[q]
        for g in np.unique(data.group):
            rows = data.group == g
            ax.scatter(x[rows], k * (pred[q][rows] - data.responses[q][rows]), s=14, label=str(g))
        ax.axhline(0, color="0.5", lw=0.8)
        ax.set_xlabel(cond.replace("_", " "))
        ax.set_ylabel(f"model - measured, {q.replace('_', ' ')} [{unit}]")
        ax.set_title(f"unexplained ({100 * unexplained[q]['share']:.0f} %)" if q in unexplained else "no systematic "
                     "residual left", fontsize=9)
    if len(np.unique(data.group)) > 1:
        axes[0][0].legend(fontsize=7)
    fig.suptitle("residuals of the final model (" + (" + ".join(["classical"] + findings["final"]["mechanisms"])) + ")",
                 fontsize=10)
    fig.tight_layout()
    _save(fig, path)


def plot_candidates(findings: dict, path: Path) -> None:
    """ΔBIC of every candidate at every selection step: green named, cyan accepted but partial, orange
    ambiguous, grey not passed."""
    plt = pyplot()
    steps = findings["steps"]
    fig, axes = plt.subplots(1, len(steps), figsize=(6.5 * len(steps), 3.8), squeeze=False)
    for ax, s in zip(axes[0], steps):
        names = [c["name"] for c in s["candidates"]]
        dbic = [c["delta_bic"] for c in s["candidates"]]
        colors = ["C2" if c["named"] else "C9" if c["accepted"] else "C1" if c["name"] in s["ambiguity"] else "0.6"
                  for c in s["candidates"]]
        ax.bar(range(len(names)), dbic, color=colors)
        ax.axhline(-BIC_MARGIN, color="0.4", lw=0.8, ls="--")
        ax.set_xticks(range(len(names)), names, rotation=30, ha="right", fontsize=7)
        ax.set_ylabel("ΔBIC against the current model")
        ax.set_title(f"step {s['step'] + 1}: on {' + '.join(['classical'] + s['model'])}", fontsize=9)
    fig.suptitle("found: " + (", ".join(findings["found"]) or "nothing")
                 + "".join(f"; ambiguous: {' or '.join(g)}" for g in findings["ambiguities"])
                 + (f"; unexplained: {len(findings['unexplained'])} trend(s)" if findings["unexplained"] else ""),
                 fontsize=10)
    fig.tight_layout()
    _save(fig, path)


def _group_lines(groups: list[dict]) -> list[str]:
    """The report's table of residuals by kind of motion, by steering angle and (both wheels in the data) by wheel."""
    if not groups:
        return []
    return ["### By kind of motion, steering angle and wheel", "",
            "Every row (training and held out), residual normalised as above: mean (bias) and RMS, classical → final, "
            "and the final residual's rank correlation with slip inside the group (– with fewer than 4 rows).", "",
            *group_table(groups, ("classical", "final")), ""]


def _parameter_rows(table: list[dict]) -> list[str]:
    out = ["| parameter | value | std. error | range | at a bound | identified |", "|---|---|---|---|---|---|"]
    for r in table:
        out.append(f"| {r['name']} | {r['value']:.4g} {r['unit'] if r['unit'] != '-' else ''} | {r['std_error']:.2g} | "
                   f"{r['lower']:g} – {r['upper']:g} | {r['at_bound'] or 'no'} | {'yes' if r['identified'] else '**no**'} |")
    return out


def write_report(d: Discovery, data: Measurements, heldout: np.ndarray, out: str | Path, *, title: str,
                 command: str = "", excluded: str = "", extra: dict | None = None) -> tuple[Path, Path, dict]:
    """Write ``report.md``, ``findings.json`` and the figures to ``out``; returns the two paths and the
    findings (the JSON's content). ``extra``: more findings (``test``: the model on a separate test set)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    findings = {"title": title, "data": data.name, "rows": len(data), "notes": data.notes, "command": command,
                "excluded": excluded, **d.to_dict(), **(extra or {}), "selection_rule": rule_digest(),
                "provenance": provenance()}
    preds = {"classical": model_responses(d.baseline.soil, data), "final": model_responses(d.final.soil, data)}
    findings["residuals_by_group"] = residuals_by_group(  # (model - measured) / training scale, every row
        {m: {q: (p[q] - data.responses[q]) / d.scales[q] for q in d.responses} for m, p in preds.items()}, data)
    plot_fits(findings, d, data, heldout, preds, out / "fits.png")
    plot_residuals(findings, d, data, preds["final"], out / "residuals.png")
    if findings["steps"]:
        plot_candidates(findings, out / "candidates.png")
    base = findings["baseline"]
    lines = [f"# {title}", "", f"Data: `{data.name}` ({len(data)} conditions; {data.notes}).",
             f"Fitted responses: {', '.join(d.responses)}; {d.n_train} training and {d.n_heldout} held-out "
             "conditions; residuals normalised by the training data's spread.", ""]
    if excluded:
        lines += [f"Rows and responses: {excluded}", ""]
    if findings.get("shear_form", "independent") != "independent":
        lines += [f"Shear form: {findings['shear_form']} (the classical model and every candidate share it; "
                  "`--shear-form`)", ""]
    if command:
        lines += ["Reproduce: `" + command + "`", ""]
    lines += ["## Verdict", ""] + [f"- {v}" for v in verdict_lines(findings)]
    lines += ["", f"Held-out RMSE (normalised): classical {base['heldout_rmse']:.3f}, final model "
              f"{findings['final']['heldout_rmse']:.3f}; the final model removes "
              f"{100 * findings['final']['explained_share']:.0f} % of the classical model's systematic residual.", "",
              "## The classical model, calibrated", "",
              f"Wong–Reece normal stress with Reece's gravity-explicit pressure, Janosi–Hanamoto shear along and across "
              f"the wheel, sinkage from vertical equilibrium; training RMSE {base['train_rmse']:.3f}. Standard errors "
              "from the Fisher information; *identified: no* means the data do not constrain the parameter "
              "(its ±2σ interval spans its whole range).", ""]
    lines += _parameter_rows(base["parameter_table"])
    lines += ["", "## What it gets wrong", "", "Strongest residual trends (Spearman rank correlation with a condition, "
              "training rows):", "", "| response | condition | Spearman | p |", "|---|---|---|---|"]
    lines += [f"| {t['response']} | {t['condition']} | {t['spearman']:+.2f} | {t['p_value']:.2g} |" for t in d.trends[:6]]
    lines += ["", "Lack of fit (quadratic regression of the residual on the conditions; p of its F-test), classical "
              "→ final model:", "", "| response | classical p | final p |", "|---|---|---|"]
    lof = findings["lack_of_fit"]
    lines += [f"| {q} | {lof['baseline'][q]['p_value']:.2g} | {lof['final'][q]['p_value']:.2g} |" for q in d.responses]
    lines += ["", "![](residuals.png)", ""] + _group_lines(findings["residuals_by_group"])
    lines += ["## Forward selection", "",
              f"A candidate passes when ΔBIC < −{BIC_MARGIN:g} against the current model, its held-out "
              + (f"error is not worse by more than {GAIN_SIGMAS:g} bootstrap standard deviation(s) of the gain"
                 if PREDICTION_NOT_WORSE else
                 f"gain is positive and exceeds {GAIN_SIGMAS:g} bootstrap standard deviation(s)")
              + ", its parameter is inside its "
              f"physical range and of the mechanism's sign, and it removes at least {100 * MIN_EXPLAINED:.0f} % of "
              "the systematic residual. When no single mechanism passes and a systematic residual remains, the "
              f"pairs among the {PAIR_POOL} best single fits are fitted together (a look-ahead step); a pair also "
              f"needs each member to lower BIC by {BIC_MARGIN:g} beyond the other alone. The best passing mechanism "
              "is named only if no generic drift of a classical parameter with a condition the data vary fits "
              f"better in its place (BIC lower by more than {RIVAL_MARGIN:g}).", ""]
    for s in findings["steps"]:
        kind = " (pairs, look-ahead)" if s.get("pairs") else ""
        lines += [f"### Step {s['step'] + 1}{kind}: on {' + '.join(['classical'] + s['model'])}", "",
                  "| mechanism | parameters | held-out gain | ΔBIC | removes | verdict |", "|---|---|---|---|---|---|"]
        deferred = [g[0] for g in s.get("deferred", [])]
        for c in s["candidates"]:
            params = ", ".join(f"{k} = {v['value']:.3g}" for k, v in c["parameters"].items())
            verdict = ("**named**" if c["named"] else "accepted, partial" if c["accepted"] else "ambiguous" if c["name"] in s["ambiguity"]
                       else "deferred" if c["name"] in deferred else "passes" if c["passes"] else "; ".join(c["why_not"]).replace("|", "\\|"))
            lines.append(f"| {c['name']} | {params} | {c['gain']:+.4f} ± {c['gain_std']:.4f} | {c['delta_bic']:+.1f} | "
                         f"{100 * c['explained']:.0f} % | {verdict} |")
        lines.append("")
        if s.get("rivals"):
            lines += [("Generic rivals of each passing mechanism checked (a classical parameter drifting linearly with "
                       f"a condition the data vary, fitted in its place; one lower than the mechanism by more than "
                       f"{RIVAL_MARGIN:g} in the last column, and the mechanism is not named at this step):"), "",
                      "| mechanism | rival | in place of | rate | ΔBIC | against the mechanism |",
                      "|---|---|---|---|---|---|"]
            lines += [f"| {r.get('against', '')} | {r['description']} | {r['replaces']} | {r['rate']:+.3g} | "
                      f"{r['delta_bic']:+.1f} | {r['bic_vs_accepted']:+.1f} |" for r in s["rivals"]] + [""]
    if findings["steps"]:
        lines += ["![](candidates.png)", ""]
    if d.skipped:
        lines += ["Not tried (the data cannot show them): " + ", ".join(f"{k} ({v})" for k, v in d.skipped.items()), ""]
    if "test" in findings:
        t = findings["test"]
        lines += [f"## On the test set `{t['data']}`", "",
                  f"The model fitted above predicts {t['rows']} rows it never saw (RMSE normalised by the training "
                  f"spread): classical {t['classical_nrmse']:.3f}, final {t['final_nrmse']:.3f}, gain "
                  f"{t['gain']:+.3f} ± {t['gain_std']:.3f}.", "", "| response | classical | final |", "|---|---|---|"]
        lines += [f"| {q} | {v['classical_nrmse']:.3f} | {v['final_nrmse']:.3f} |" for q, v in t["responses"].items()]
        lines.append("")
    if findings["final"]["mechanisms"]:
        lines += ["## The final model", "", f"Classical + {' + '.join(findings['final']['mechanisms'])}, calibrated "
                  "together:", ""]
        lines += _parameter_rows(findings["final"]["parameter_table"]) + [""]
    lines += ["![](fits.png)", "", "The calibrated model (every parameter, the training rows) is in `model.json`; "
              "`wheelsoil predict model.json DATA` predicts new data with it.", ""]
    md, js = out / "report.md", out / "findings.json"
    write_markdown_and_json(md, "\n".join(lines), js, findings, default=float)
    return md, js, findings
