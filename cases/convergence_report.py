"""The convergence study's report: changes between neighbouring levels, the refined factors extrapolated to scale
0, the verdict, and convergence.md/.csv/.json/.png (:mod:`.convergence` documents the method and runs the study).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from wheelsoil.provenance import atomic_output

from . import build
from .convergence import QUANTITIES, ConvergenceStudy, Level
from .results import load_result
from .run import RESULT_NAME
from .schema import CaseFile


def relative_floors(case: CaseFile) -> dict:
    """Floors of the relative changes: 5 % of W for forces, 5 % of W r for torque, half a mean diameter for sinkage, 0.01
    for the tread slip (as the steady-state detector's)."""
    w = case.test.load
    r = build.wheel_geometry(case).radius
    d = 0.5 * (case.soil.diameter_min + case.soil.diameter_max)
    return {"drawbar_pull": 0.05 * w, "lateral_force": 0.05 * w, "vertical_force": 0.05 * w, "torque": 0.05 * w * r,
            "sinkage": 0.5 * d, "tread_slip": 0.01}


def with_excess(values: dict | None, excess: dict | None) -> dict | None:
    """A level's values (:func:`_level_values`) with each quantity's standard error and the excess spread that
    replicas measured (``excess``: per quantity, its units; :class:`~.replicas.ReplicaSpread`) added in quadrature:
    the run-to-run spread one run's error bar does not see. ``None`` in, ``None`` out; no excess: unchanged."""
    if values is None or not excess:
        return values
    return {**values, **{q: (values[q][0], math.hypot(values[q][1], excess.get(q, 0.0))) for q in QUANTITIES}}


def stored_levels(study: dict, factor: str) -> list[tuple[float, dict | None]]:
    """A factor's levels as (scale, values) from a stored ``convergence.json`` (``study``, as :func:`write_report`
    writes it), with each quantity's (mean, sem) as a tuple, as :func:`_level_values` gives them."""
    return [(lv["scale"], None if lv["values"] is None else
             {**lv["values"], **{q: tuple(lv["values"][q]) for q in QUANTITIES}}) for lv in study["levels"][factor]]


def _level_values(lv: Level) -> dict | None:
    if lv.folder is None or not (lv.folder / RESULT_NAME).is_file():
        return None
    r = load_result(lv.folder / RESULT_NAME)
    out = {"steady": r.summary.steady, "wall_seconds": float(r.info.get("wall_seconds", math.nan)),
           "particles": int(r.info.get("particles", 0)), "dem_time_step": float(r.info.get("dem_time_step", math.nan))}
    for q in QUANTITIES:
        st = r.summary.quantity(q)
        out[q] = (float(st.mean), float(st.sem))
    return out


def comparison_rows(study: ConvergenceStudy, excess: dict | None = None) -> list[dict]:
    """One row per factor, neighbouring pair of levels and quantity: the two means, their change, relative change
    and its standard error (``excess``: see :func:`with_excess`), and whether both runs were steady."""
    floors = relative_floors(study.base)
    rows = []
    for factor, levels in study.levels.items():
        values = [with_excess(_level_values(lv), excess) for lv in levels]
        for k in range(len(levels) - 1):
            a, b = values[k], values[k + 1]
            for q in QUANTITIES:
                row = {"factor": factor, "coarse_scale": levels[k].scale, "fine_scale": levels[k + 1].scale,
                       "quantity": q, "finished": a is not None and b is not None}
                if row["finished"]:
                    (ma, sa), (mb, sb) = a[q], b[q]
                    ref = max(abs(mb), floors[q])
                    delta = mb - ma
                    sigma = math.hypot(sa, sb) if math.isfinite(sa) and math.isfinite(sb) else math.nan
                    row.update(coarse_mean=ma, coarse_sem=sa, fine_mean=mb, fine_sem=sb, change=delta,
                               change_sem=sigma, relative_change=delta / ref, relative_change_sem=sigma / ref,
                               steady=a["steady"] and b["steady"])
                    row["converged"] = bool(row["steady"] and abs(row["relative_change"]) < study.threshold)
                rows.append(row)
    return rows


def coarsest_converged(study: ConvergenceStudy, rows: list[dict]) -> dict:
    """Per factor: the coarsest scale from which every quantity changes by less than the threshold to the next
    finer level (and on through the finer pairs), or None."""
    verdict = {}
    for factor, levels in study.levels.items():
        pairs = [[r for r in rows if r["factor"] == factor and r["coarse_scale"] == lv.scale] for lv in levels[:-1]]
        ok = [bool(p) and all(r.get("converged", False) for r in p) for p in pairs]
        found = None
        for k in range(len(ok)):
            if all(ok[k:]):
                found = levels[k].scale
                break
        verdict[factor] = found
    return verdict


#: Factors refined towards zero (scale < 1), whose series is extrapolated to scale 0 (the reference is scale 1).
REFINED_TOWARDS_ZERO = ("particle_size", "time_step", "mesh")


def extrapolation_rows(study: ConvergenceStudy, excess: dict | None = None) -> list[dict]:
    """Per refined factor (:data:`REFINED_TOWARDS_ZERO`) and quantity, :func:`extrapolate_levels` of the study's
    levels (``excess``: see :func:`with_excess`)."""
    floors = relative_floors(study.base)
    rows = []
    for factor in REFINED_TOWARDS_ZERO:
        levels = study.levels.get(factor, [])
        if len(levels) >= 2:
            rows += extrapolate_levels(factor, [(lv.scale, with_excess(_level_values(lv), excess)) for lv in levels],
                                       floors, study.threshold)
    return rows


def extrapolate_levels(factor: str, levels: list[tuple[float, dict | None]], floors: dict,
                       threshold: float) -> list[dict]:
    """One row per quantity: the steady levels' means (``levels``: (scale, values) with values as a result's
    summary gives them, ``None`` for a level not run) against their scale, extrapolated to scale 0
    (:func:`wheelsoil.scale_extrapolation.extrapolate_to_zero_size`, weighted by each run's standard error, the
    Birge ratio scaling them where the levels scatter beyond them), and the reference's (scale 1) error against
    it with its standard error. Converged (the project's definition): that error plus two standard errors
    within ``threshold`` times max(|extrapolated|, floor). Needs every level run and steady, with finite errors;
    else the row says why (``reason``)."""
    from wheelsoil.errors import WheelsoilInputError as _Input
    from wheelsoil.scale_extrapolation import extrapolate_to_zero_size

    done = [(s, v) for s, v in levels if v is not None]
    steady = [(s, v) for s, v in done if v["steady"]]
    rows = []
    for q in QUANTITIES:
        row = {"factor": factor, "quantity": q, "levels": [s for s, _ in steady]}
        if len(done) < len(levels):
            row["reason"] = f"{len(levels) - len(done)} of {len(levels)} levels have not run"
        elif len(steady) < len(done):
            row["reason"] = "not every level reached a steady state"
        else:
            try:
                fit = extrapolate_to_zero_size([s for s, _ in steady], [v[q][0] for _, v in steady],
                                               [v[q][1] for _, v in steady])
            except _Input as exc:
                row["reason"] = str(exc)
            else:
                ref = max(abs(fit.value), floors[q])
                error, error_se = fit.change(1.0)
                row.update(value=fit.value, value_se=fit.value_se, reference_error=error, reference_error_se=error_se,
                           relative_error=error / ref, relative_error_se=error_se / ref, birge=fit.birge, dof=fit.dof,
                           converged=bool(abs(error) + 2.0 * error_se <= threshold * ref))
        rows.append(row)
    return rows


def write_report(study: ConvergenceStudy, replicas=None) -> list[Path]:
    """convergence.csv, convergence.json, convergence.md and convergence.png in the study folder. ``replicas``
    (:class:`~.replicas.ReplicaSpread`): its excess spread is added to every level's standard error."""
    import pandas as pd

    excess = replicas.excess if replicas is not None else None
    rows = comparison_rows(study, excess)
    verdict = coarsest_converged(study, rows)
    extrapolated = extrapolation_rows(study, excess)
    study.out.mkdir(parents=True, exist_ok=True)
    table = pd.DataFrame(rows)
    written = []
    with atomic_output(study.out / "convergence.csv") as tmp:
        table.to_csv(tmp, index=False)
    written.append(study.out / "convergence.csv")
    levels = {f: [{"scale": lv.scale, "overrides": lv.overrides, "case_hash": lv.folder.name if lv.folder else None,
                   "values": _level_values(lv)} for lv in lvs] for f, lvs in study.levels.items()}
    with atomic_output(study.out / "convergence.json") as tmp:
        tmp.write_text(json.dumps({"base": study.base.name, "threshold": study.threshold, "coarsest_converged": verdict,
                                   "levels": levels, "comparisons": rows, "extrapolated": extrapolated,
                                   "excess_spread": None if replicas is None else
                                   {"source": replicas.source, "replicas": replicas.replicas, "excess": excess}},
                                  indent=2, default=float))
    written.append(study.out / "convergence.json")
    with atomic_output(study.out / "convergence.md") as tmp:
        tmp.write_text(report_markdown(study, rows, verdict, levels, extrapolated, replicas))
    written.append(study.out / "convergence.md")
    written.append(_plot(study, rows))
    return written


def report_markdown(study: ConvergenceStudy, rows: list[dict], verdict: dict, levels: dict,
                    extrapolated: list[dict] | None = None, replicas=None) -> str:
    pct = int(round(100 * study.threshold))
    spread = ("" if replicas is None else
              f" Every level's standard error has the run-to-run excess spread that the {replicas.replicas} replicas "
              f"of {replicas.source} measured added in quadrature ("
              + ", ".join(f"{QUANTITIES[q][0]} {QUANTITIES[q][2] * x:.2g} {QUANTITIES[q][1]}"
                          for q, x in replicas.excess.items()) + "); the Levels table shows each run's own.")
    lines = [f"# Convergence study: {study.base.name}", "",
             f"Each factor's levels against the reference; a change is the finer level's mean minus the coarser's, "
             f"relative to the finer mean (or the floor), ± one standard error (batch means over whole pitches). "
             f"Converged: every quantity changes by less than {pct} % and both runs were steady." + spread, "",
             "## Levels", "", "| factor | scale | changes | particles | DEM step [s] | steady | wall [s] | "
             + " | ".join(f"{v[0]} [{v[1]}]" for v in QUANTITIES.values()) + " |",
             "|" + "---|" * (7 + len(QUANTITIES))]
    for factor, lvs in levels.items():
        for lv in lvs:
            v = lv["values"]
            over = ", ".join(f"{k} = {x:.4g}" for k, x in lv["overrides"].items()) or "reference"
            if v is None:
                lines.append(f"| {factor} | {lv['scale']:g} | {over} | not run | | | | " + " | " * (len(QUANTITIES) - 1)
                             + " |")
                continue
            cells = [f"{s * v[q][0]:.4g} ± {s * v[q][1]:.2g}" for q, (_, _, s) in QUANTITIES.items()]
            lines.append(f"| {factor} | {lv['scale']:g} | {over} | {v['particles']} | {v['dem_time_step']:.3g} | "
                         f"{'yes' if v['steady'] else '**no**'} | {v['wall_seconds']:.0f} | " + " | ".join(cells) + " |")
    lines += ["", "## Changes between neighbouring levels", "",
              "| factor | levels | " + " | ".join(v[0] for v in QUANTITIES.values()) + " |",
              "|" + "---|" * (2 + len(QUANTITIES))]
    for factor, lvs in study.levels.items():
        for k in range(len(lvs) - 1):
            cells = []
            for q in QUANTITIES:
                r = next(r for r in rows if r["factor"] == factor and r["coarse_scale"] == lvs[k].scale
                         and r["quantity"] == q)
                if not r["finished"]:
                    cells.append("not run")
                    continue
                text = f"{100 * r['relative_change']:+.1f} ± {100 * r['relative_change_sem']:.1f} %"
                if not r["steady"]:
                    text += " (not steady)"
                elif not r["converged"]:
                    text = f"**{text}**"
                cells.append(text)
            lines.append(f"| {factor} | {lvs[k].scale:g} → {lvs[k + 1].scale:g} | " + " | ".join(cells) + " |")
    lines += _extrapolation_markdown(study, extrapolated or [])
    lines += ["", "## Verdict", ""]
    for factor, scale in verdict.items():
        mine = [r for r in rows if r["factor"] == factor]
        scales = ", ".join(f"{lv.scale:g}" for lv in study.levels[factor])
        ext = [r for r in (extrapolated or []) if r["factor"] == factor]
        neighbours = f" (neighbouring levels change by less than {pct} % from scale {scale:g} on)" if scale else ""
        if ext and all("value" in r for r in ext):
            bad = [QUANTITIES[r["quantity"]][0] for r in ext if not r["converged"]]
            if bad:
                lines.append(f"- {factor}: **not converged**: extrapolated to scale 0, the reference's error with two "
                             f"standard errors exceeds {pct} % for {', '.join(bad)}{neighbours}.")
            else:
                lines.append(f"- {factor}: converged: extrapolated to scale 0, the reference's error with two standard "
                             f"errors is within {pct} % for every quantity{neighbours}.")
        elif scale is not None and factor in REFINED_TOWARDS_ZERO:
            why = next((r["reason"] for r in ext if "reason" in r), "no extrapolation")
            lines.append(f"- {factor}: **undecided**: neighbouring levels change by less than {pct} % from scale "
                         f"{scale:g} on, but the series could not be extrapolated ({why}), and one refinement moving "
                         "little is not convergence.")
        elif scale is not None:
            lines.append(f"- {factor}: converged within {pct} % from scale {scale:g} on.")
        elif not all(r["finished"] for r in mine):
            lines.append(f"- {factor}: **undecided**: not every level ({scales}) has finished.")
        elif not all(r["steady"] for r in mine):
            unsteady = sorted({lv.scale for lv in study.levels[factor]
                               if (v := _level_values(lv)) is not None and not v["steady"]})
            big = [r for r in mine if r["steady"] and not r["converged"]]
            lines.append(f"- {factor}: **undecided**: the level(s) at scale {', '.join(f'{x:g}' for x in unsteady)} "
                         "did not reach a steady state, so their changes are not reportable"
                         + (f"; between steady levels {len(big)} change(s) exceed {pct} %" if big else "") + ".")
        else:
            lines.append(f"- {factor}: **not converged** within {pct} % over the levels run ({scales}); refine further.")
    lines.append("")
    return "\n".join(lines)


def _extrapolation_markdown(study: ConvergenceStudy, extrapolated: list[dict]) -> list[str]:
    """The extrapolated values and the reference's error against them, one line per refined factor."""
    if not extrapolated:
        return []
    pct = int(round(100 * study.threshold))
    lines = ["", "## Extrapolated to zero scale", "",
             "Each refined factor's steady levels against their scale, a line weighted by the runs' standard errors "
             "(scaled by the Birge ratio where the levels scatter beyond them), extrapolated to scale 0; below each "
             f"value, the reference's error against it. Converged: that error plus two standard errors within {pct} %.",
             "", "| factor | " + " | ".join(f"{v[0]} [{v[1]}]" for v in QUANTITIES.values()) + " |",
             "|" + "---|" * (1 + len(QUANTITIES))]
    for factor in dict.fromkeys(r["factor"] for r in extrapolated):
        cells = []
        for q, (_, _, scale) in QUANTITIES.items():
            r = next(r for r in extrapolated if r["factor"] == factor and r["quantity"] == q)
            if "value" not in r:
                cells.append(r["reason"])
                continue
            text = (f"{scale * r['value']:.4g} ± {scale * r['value_se']:.2g}; reference "
                    f"{100 * r['relative_error']:+.1f} ± {100 * r['relative_error_se']:.1f} %")
            cells.append(text if r["converged"] else f"**{text}**")
        lines.append(f"| {factor} | " + " | ".join(cells) + " |")
    return lines


def _plot(study: ConvergenceStudy, rows: list[dict]) -> Path:
    from wheelsoil.plotting import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(12, 6.5), sharey=True)
    pairs = [(f, lvs[k].scale, lvs[k + 1].scale) for f, lvs in study.levels.items() for k in range(len(lvs) - 1)]
    labels = [f"{f}\n{a:g}→{b:g}" for f, a, b in pairs]
    for ax, (q, (label, _, _)) in zip(axes.ravel(), QUANTITIES.items()):
        for k, (f, a, b) in enumerate(pairs):
            r = next(r for r in rows if r["factor"] == f and r["coarse_scale"] == a and r["quantity"] == q)
            if not r["finished"]:
                continue
            colour = "C0" if r["steady"] else "0.6"
            ax.errorbar([k], [100 * r["relative_change"]], yerr=[100 * r["relative_change_sem"]], marker="o",
                        color=colour, capsize=3)
        ax.axhspan(-100 * study.threshold, 100 * study.threshold, color="C2", alpha=0.12)
        ax.axhline(0, color="0.5", lw=0.6)
        ax.set_title(label)
        ax.set_xticks(range(len(pairs)))
        ax.set_xticklabels(labels, fontsize=7)
    for ax in axes[:, 0]:
        ax.set_ylabel("change under refinement [%]")
    fig.suptitle(f"{study.base.name}: change between levels (band: ±{100 * study.threshold:.0f} %; grey: a run "
                 "not steady)")
    fig.tight_layout()
    path = study.out / "convergence.png"
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
    return path
