"""The validation report: markdown with plots, and a JSON of the findings, for one discovery run."""

from pathlib import Path

import numpy as np

from wheelsoil.provenance import atomic_output, provenance, write_markdown_and_json

from .discovery import Discovery, model_responses
from .measured import Measurements

UNITS = {"drawbar_pull": ("N", 1.0), "lateral_force": ("N", 1.0), "sinkage": ("mm", 1e3), "torque": ("N m", 1.0)}


def _save(fig, path: Path) -> None:
    import matplotlib.pyplot as plt

    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def plot_fits(d: Discovery, data: Measurements, heldout: np.ndarray, path: Path) -> None:
    """Predicted against measured, baseline and best extension, training and held-out rows."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    models = [("classical", d.baseline.soil)]
    if d.candidates:
        best = d.found or d.candidates[0]
        models.append((f"+ {best.extension.name}", best.fit.soil))
    preds = [(label, model_responses(soil, data)) for label, soil in models]
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
    fig.tight_layout()
    _save(fig, path)


def plot_residuals(d: Discovery, data: Measurements, path: Path) -> None:
    """Classical-model residuals against the condition with the strongest trend, per response."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pred = model_responses(d.baseline.soil, data)
    fig, axes = plt.subplots(1, len(d.responses), figsize=(4.2 * len(d.responses), 3.6), squeeze=False)
    for ax, q in zip(axes[0], d.responses):
        trend = next((t for t in d.trends if t["response"] == q), None)
        cond = trend["condition"] if trend else "slip"
        x = np.asarray(getattr(data, cond), float)
        unit, k = UNITS[q]
        groups = np.unique(data.group)
        for g in groups:
            rows = data.group == g
            ax.scatter(x[rows], k * (pred[q][rows] - data.responses[q][rows]), s=14, label=str(g))
        ax.axhline(0, color="0.5", lw=0.8)
        ax.set_xlabel(cond.replace("_", " "))
        ax.set_ylabel(f"model - measured, {q.replace('_', ' ')} [{unit}]")
        if trend:
            ax.set_title(f"Spearman {trend['spearman']:+.2f} (p = {trend['p_value']:.1g})", fontsize=9)
    if len(np.unique(data.group)) > 1:
        axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    _save(fig, path)


def plot_candidates(d: Discovery, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.6))
    names = [c.extension.name for c in d.candidates]
    gains = [c.gain for c in d.candidates]
    errs = [c.gain_std for c in d.candidates]
    colors = ["C2" if c.found else "0.6" for c in d.candidates]
    ax.bar(range(len(names)), gains, yerr=errs, capsize=3, color=colors)
    ax.axhline(0, color="0.4", lw=0.8)
    ax.set_xticks(range(len(names)), names, rotation=25, ha="right")
    ax.set_ylabel("held-out RMSE gain (normalised)")
    ax.set_title("Candidate mechanisms (green: found)")
    fig.tight_layout()
    _save(fig, path)


def write_report(d: Discovery, data: Measurements, heldout: np.ndarray, out: str | Path, *, title: str,
                 command: str = "", excluded: str = "") -> tuple[Path, Path, dict]:
    """Write ``report.md``, ``findings.json`` and the figures to ``out``; returns the two paths and the
    findings (the JSON's content)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    plot_fits(d, data, heldout, out / "fits.png")
    plot_residuals(d, data, out / "residuals.png")
    if d.candidates:
        plot_candidates(d, out / "candidates.png")
    f = d.found
    findings = {"title": title, "data": data.name, "rows": len(data), "notes": data.notes, "command": command,
                "excluded": excluded, **d.to_dict(), "provenance": provenance()}
    lines = [f"# {title}", "", f"Data: `{data.name}` ({len(data)} conditions; {data.notes}).",
             f"Fitted responses: {', '.join(d.responses)}; {d.n_train} training and {d.n_heldout} held-out "
             "conditions.", ""]
    if excluded:
        lines += [f"Excluded: {excluded}", ""]
    if command:
        lines += ["Reproduce: `" + command + "`", ""]
    lines += ["## What the classical model gets wrong", "",
              f"Classical model (Wong–Reece, Janosi–Hanamoto, lateral shear; {', '.join(d.baseline.free)} "
              f"fitted): normalised RMSE {d.baseline.rmse:.3f} on training, {d.baseline_heldout_rmse:.3f} held out.",
              "", "Strongest residual trends (Spearman rank correlation with a condition):", "",
              "| response | condition | Spearman | p |", "|---|---|---|---|"]
    lines += [f"| {t['response']} | {t['condition']} | {t['spearman']:+.2f} | {t['p_value']:.2g} |" for t in d.trends[:6]]
    lines += ["", "![](residuals.png)", "", "## Candidate causes", "",
              "| mechanism | source | parameters | held-out gain | ΔBIC | effect | found |", "|---|---|---|---|---|---|---|"]
    for c in d.candidates:
        params = ", ".join(f"{k} = {v:.3g}" for k, v in c.to_dict()["parameters"].items())
        source = c.extension.source.replace("|", "\\|")  # a pipe would split the table cell
        lines.append(f"| {c.extension.name} | {source} | {params} | {c.gain:+.4f} ± {c.gain_std:.4f} | "
                     f"{c.delta_bic:+.1f} | {c.effect:.3f} | {'**yes**' if c.found else 'no'} |")
    at_bound = [f"{c.extension.name}: {p.name} = {c.fit.free[p.name]:.3g}" for c in d.candidates for p in c.extension.parameters
                if min(abs(c.fit.free[p.name] - p.lower), abs(c.fit.free[p.name] - p.upper)) < 1e-6 * (p.upper - p.lower)
                and c.effect > 1e-6]
    if at_bound:
        lines += ["", "At a bound of their range (the mechanism takes all it may; the misfit it addresses may be larger "
                  "than it can explain): " + "; ".join(at_bound)]
    if d.skipped:
        lines += ["", "Not tried (the data cannot show them): " + ", ".join(f"{k} ({v})" for k, v in d.skipped.items())]
    lines += ["", "![](candidates.png)" if d.candidates else "", "", "## Finding", ""]
    if f:
        gain_pct = 100.0 * f.gain / d.baseline_heldout_rmse
        lines += [f"**{f.extension.name}**: {f.extension.mechanism} ({f.extension.source}). Held-out RMSE "
                  f"{d.baseline_heldout_rmse:.3f} → {f.heldout_rmse:.3f} ({gain_pct:.0f} % lower, gain "
                  f"{f.gain:.4f} ± {f.gain_std:.4f}); ΔBIC {f.delta_bic:+.1f}."]
    else:
        lines += ["No mechanism earns its parameters here: none lowers BIC by more than 10 with a held-out gain "
                  "beyond two bootstrap standard deviations."]
    lines += ["", "![](fits.png)", ""]
    md, js = out / "report.md", out / "findings.json"
    write_markdown_and_json(md, "\n".join(lines), js, findings, default=float)
    return md, js, findings
