"""DEM--FEM results as *the model*: measured and simulated single-wheel tests compared condition by condition.

``wheelsoil validate DATA --model SWEEP`` holds a batch of wheelsoil runs (a sweep folder or its
``summary.csv``, read by :func:`~wheelsoil.validation.measured.load_sweep_summary`) against measured data.
Each measured row is paired with the simulated run at the same conditions -- slip, slip angle, load,
gravity, pass number -- on the same wheel (radius, width, grouser height); rows without a partner are
listed, not guessed. For each response the report gives the paired values, the residual simulated -
measured, its size in combined standard deviations (the measured and the simulated scatter, where known),
the bias and RMS error normalised by the measured spread (over every measured row), and the Spearman trend of the residual against
each condition that varies: the same diagnostics the semi-empirical model gets, so a systematic error of
the simulation (e.g. growing with the steering angle) is named the same way. Where a test was repeated (a rig's
repeats, each at its own measured load) and every repeat has its own run (replicas: other seeds), the spread of
the measured means and of the simulated ones stand side by side (:func:`repeat_spreads`).
"""

from dataclasses import dataclass

import numpy as np
from scipy.stats import spearmanr

from wheelsoil.errors import WheelsoilInputError

from .calibration import response_scales
from .measured import Measurements
from .report import UNITS
from .residuals import CONDITIONS

#: Tolerances within which a measured and a simulated condition are the same test.
MATCH = {"slip": ("abs", 0.01), "slip_angle": ("abs", 0.5), "load": ("rel", 0.01), "gravity": ("rel", 0.01),
         "passes": ("abs", 0.01), "radius": ("rel", 0.02), "width": ("rel", 0.02), "grouser_height": ("abs", 1e-4)}
#: Conditions the residual trends are computed against: those the workflow's own trends use (the grouser height is
#: the wheel, where both are paired).
TREND_CONDITIONS = CONDITIONS
#: Trend p-value below which a residual trend is reported as systematic.
TREND_P = 0.01


def _same(key: str, a: np.ndarray, b: float) -> np.ndarray:
    kind, tol = MATCH[key]
    if kind == "abs":
        return np.abs(a - b) <= tol
    return np.abs(a - b) <= tol * np.maximum(np.abs(b), 1e-300)


@dataclass
class Comparison:
    """Pairs (measured row, simulated row), per-response statistics and trends."""

    pairs: np.ndarray  # (P, 2) row indices into (data, simulated)
    unmatched: np.ndarray  # measured rows without a simulated partner
    responses: dict  # name -> {"n", "bias", "rmse", "spread", "nbias", "nrmse", "within_2sigma"}
    trends: list  # {"response", "condition", "spearman", "p_value"}, strongest first

    @property
    def systematic(self) -> list:
        return [t for t in self.trends if t["p_value"] < TREND_P]


def same_conditions(ref: Measurements, other: Measurements, j: int, ignore: tuple[str, ...] = ()) -> np.ndarray:
    """The rows of ``ref`` at the conditions of row ``j`` of ``other``: every :data:`MATCH` key within its tolerance
    (those in ``ignore`` aside), and the travel slip (the rig's) within the slip's where both sets give it. At 90 deg
    the heading slip is +-1 whatever the wheel's speed (``wheelsoil.slip``), so there only the travel slip tells one
    slip from another."""
    ok = np.ones(len(ref), bool)
    for key in MATCH:
        if key in ignore:
            continue
        ok &= _same(key, np.asarray(getattr(ref, key), float), float(getattr(other, key)[j]))
    if ref.travel_slip is not None and other.travel_slip is not None:
        ok &= np.abs(np.asarray(ref.travel_slip, float) - float(other.travel_slip[j])) <= MATCH["slip"][1]
    return ok


def match_conditions(data: Measurements, simulated: Measurements) -> tuple[np.ndarray, np.ndarray]:
    """(pairs, unmatched): each measured row paired with the first simulated row at its conditions
    (:func:`same_conditions`)."""
    pairs, unmatched = [], []
    for k in range(len(data)):
        hit = np.flatnonzero(same_conditions(simulated, data, k))
        if hit.size:
            pairs.append((k, int(hit[0])))
        else:
            unmatched.append(k)
    return np.array(pairs, int).reshape(-1, 2), np.array(unmatched, int)


def unpaired_runs(data: Measurements, simulated: Measurements) -> np.ndarray:
    """The simulated rows that match no measured row at all (a replica of a measured condition is paired)."""
    return np.array([j for j in range(len(simulated)) if not same_conditions(data, simulated, j).any()], int)


def check_every_run_paired(data: Measurements, simulated: Measurements) -> None:
    """Refuse a simulated run that twins no measured condition, naming its conditions: a run meant to twin a trial
    at a slip, slip angle or load typed wrong would otherwise be left out without a word."""
    orphans = unpaired_runs(data, simulated)
    if orphans.size == 0:
        return
    shown = "; ".join(
        f"run {j}: slip {simulated.slip[j]:.4g}, slip_angle {simulated.slip_angle[j]:g} deg, load "
        f"{simulated.load[j]:.5g} N, gravity {simulated.gravity[j]:.4g} m/s^2, wheel r {simulated.radius[j]:g} m"
        for j in orphans[:5])
    raise WheelsoilInputError(
        f"{len(orphans)} of the {len(simulated)} runs in {simulated.name} twin no measured condition of {data.name} "
        f"(matched on {', '.join(MATCH)} within {', '.join(f'{k} {t:g}' for k, (_, t) in MATCH.items())}, and the "
        "travel slip where both give it): "
        f"{shown}{' ...' if orphans.size > 5 else ''}; fix the runs' conditions, or pass --allow-unpaired-runs to "
        "leave them out")


def _levels(values, digits: int) -> list:
    return sorted({round(float(v), digits) for v in values})


def compare(data: Measurements, simulated: Measurements, responses=None) -> Comparison:
    """Condition-by-condition comparison of ``simulated`` against ``data`` (see the module docstring)."""
    pairs, unmatched = match_conditions(data, simulated)
    if pairs.size == 0:
        wheels = lambda m: sorted({(float(r), float(w)) for r, w in zip(m.radius, m.width)})  # noqa: E731
        raise WheelsoilInputError(
            f"no measured condition of {data.name} has a simulated run in {simulated.name}: the simulation must "
            f"run the measured wheels {wheels(data)} (radius, width [m]) at their slip, slip angle, load and "
            f"gravity; it ran {wheels(simulated)} at slips {_levels(simulated.slip, 3)}, slip angles "
            f"{_levels(simulated.slip_angle, 2)} deg, loads {_levels(simulated.load, 1)} N")
    responses = responses or [q for q in ("drawbar_pull", "lateral_force", "sinkage", "torque")
                              if np.isfinite(data.responses[q][pairs[:, 0]]).any()
                              and np.isfinite(simulated.responses[q][pairs[:, 1]]).any()]
    stats, trends = {}, []
    for q in responses:
        y = data.responses[q][pairs[:, 0]]
        s = simulated.responses[q][pairs[:, 1]]
        ok = np.isfinite(y) & np.isfinite(s)
        if ok.sum() == 0:
            continue
        res = s[ok] - y[ok]
        # the measured spread over every row of the data, not only the paired ones: a sweep that ran a few trials
        # (one, even) is normalised as the semi-empirical model is
        spread = response_scales(data, [q])[q]
        # combined standard deviation, judged only where the measured one is known (the CMU trials give their
        # sinkage without one: a simulated fluctuation alone is no measure of agreement)
        measured_sd = data.std[q][pairs[ok, 0]] if q in data.std else np.full(ok.sum(), np.nan)
        sd = np.nan_to_num(measured_sd) ** 2
        if q in simulated.std:
            sd = sd + np.nan_to_num(simulated.std[q][pairs[ok, 1]]) ** 2
        sd = np.sqrt(sd)
        known = np.isfinite(measured_sd) & (measured_sd > 0)
        stats[q] = {
            "n": int(ok.sum()), "bias": float(np.mean(res)), "rmse": float(np.sqrt(np.mean(res ** 2))),
            "spread": spread, "nbias": float(np.mean(res) / spread), "nrmse": float(np.sqrt(np.mean(res ** 2)) / spread),
            "within_2sigma": (float(np.mean(np.abs(res[known]) <= 2 * sd[known])) if known.any() else None),
        }
        for c in TREND_CONDITIONS:
            x = np.asarray(getattr(data, c), float)[pairs[ok, 0]]
            if x.size < 4 or np.ptp(x) == 0 or np.ptp(res) == 0:
                continue
            rho, p = spearmanr(x, res)
            trends.append({"response": q, "condition": c, "spearman": float(rho), "p_value": float(p)})
    trends.sort(key=lambda t: t["p_value"])
    return Comparison(pairs, unmatched, stats, trends)


#: What may differ between a rig's repeats of one test: each repeat is run at its own measured load.
REPEAT_FREE = ("load",)


def repeat_spreads(c: Comparison, data: Measurements, simulated: Measurements) -> list[dict]:
    """The rig's repeats beside the simulation's replicas: measured rows paired in ``c`` that are the same test
    (:func:`same_conditions`, :data:`REPEAT_FREE` aside), two or more of them, each paired with its own run. For each
    such test and response, the standard deviation (ddof 1) of the measured means over the repeats and of the
    simulated means over their runs (the replicas: other seeds, each at its repeat's load), [response units]."""
    pairs = c.pairs
    left = list(range(len(pairs)))
    groups = []
    while left:
        first = left[0]
        same = same_conditions(data.select(pairs[left, 0]), data, int(pairs[first, 0]), ignore=REPEAT_FREE)
        members = [k for k, hit in zip(left, same) if hit]
        left = [k for k in left if k not in members]
        runs = pairs[members, 1]
        if len(members) < 2 or len(set(runs.tolist())) < len(members):
            continue
        rows = pairs[members, 0]
        spreads = {}
        for q in c.responses:
            y, s = data.responses[q][rows], simulated.responses[q][runs]
            ok = np.isfinite(y) & np.isfinite(s)
            if ok.sum() >= 2:
                spreads[q] = {"measured": float(np.std(y[ok], ddof=1)), "simulated": float(np.std(s[ok], ddof=1)),
                              "n": int(ok.sum())}
        groups.append({"slip_angle": float(data.slip_angle[rows[0]]), "travel_slip": float(data.travel_slip[rows[0]]),
                       "grouser_height": float(data.grouser_height[rows[0]]), "repeats": len(members),
                       "loads": [float(v) for v in data.load[rows]], "spreads": spreads})
    return groups


def _repeat_lines(c: Comparison, data: Measurements, simulated: Measurements, findings: dict) -> list[str]:
    """The report's table of :func:`repeat_spreads` (stored in ``findings["repeats"]``)."""
    groups = repeat_spreads(c, data, simulated)
    findings["repeats"] = groups
    if not groups:
        return ["", "No measured test is paired more than once (no repeats each with its own run): the simulation's "
                "run-to-run spread is not measured here."]
    lines = ["", "Repeats: measured rows of one test (each at its own load) paired each with its own run, so the rig's "
             "repeat-to-repeat spread of the means stands beside the simulation's run-to-run spread (replicas: other "
             "seeds). Standard deviations (ddof 1) of the means:", "",
             "| test | repeats | response | rig's repeats | simulation's runs |", "|---|---|---|---|---|"]
    for g in groups:
        wheel = "smooth" if g["grouser_height"] == 0 else f"{1e3 * g['grouser_height']:g} mm grousers"
        test = f"{wheel}, {g['slip_angle']:g}°, travel slip {g['travel_slip']:+.2f}"
        for q, v in g["spreads"].items():
            unit, k = UNITS[q]
            lines.append(f"| {test} | {v['n']} | {q} | {k * v['measured']:.3g} {unit} | {k * v['simulated']:.3g} {unit} |")
    return lines


def _by_group_lines(c: Comparison, data: Measurements, simulated: Measurements, findings: dict) -> list[str]:
    """The residual (simulated - measured, over the response's measured spread) of the paired rows by kind of motion
    (driving, braking, dragged), by steering angle and by wheel (:func:`~.residuals.residuals_by_group`); stored in
    ``findings["residuals_by_group"]``."""
    from .residuals import group_table, residuals_by_group

    if not len(c.pairs):
        return []
    paired = data.select(c.pairs[:, 0])
    res = {q: (simulated.responses[q][c.pairs[:, 1]] - data.responses[q][c.pairs[:, 0]]) / v["spread"]
           for q, v in c.responses.items()}
    groups = residuals_by_group({"simulation": res}, paired)
    findings["residuals_by_group"] = groups
    return ["", "By kind of motion, steering angle and wheel (residual over the measured spread; the trend is the "
            "residual's rank correlation with slip inside the group, – with fewer than 4 pairs):", "",
            *group_table(groups, ("simulation",), count="pairs")]


def write_comparison_report(c: Comparison, data: Measurements, simulated: Measurements, out, *, command: str = "") -> dict:
    """report.md, findings.json and measured_vs_simulated.png in ``out``; returns the findings."""
    from pathlib import Path

    from wheelsoil.plotting import pyplot
    from wheelsoil.provenance import atomic_output, provenance, write_markdown_and_json

    plt = pyplot()

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    findings = {
        "data": data.name, "model": simulated.name, "pairs": int(len(c.pairs)), "unmatched": int(len(c.unmatched)),
        "responses": c.responses, "trends": c.trends, "systematic": c.systematic, "provenance": provenance(),
    }
    qs = list(c.responses)
    fig, axes = plt.subplots(1, len(qs), figsize=(4.2 * len(qs), 4), squeeze=False)
    for ax, q in zip(axes[0], qs):
        unit, k = UNITS[q]
        y = k * data.responses[q][c.pairs[:, 0]]
        s = k * simulated.responses[q][c.pairs[:, 1]]
        err = k * simulated.std[q][c.pairs[:, 1]] if q in simulated.std else None
        ax.errorbar(y, s, yerr=err, fmt="o", ms=4, capsize=2)
        lim = [np.nanmin(np.r_[y, s]), np.nanmax(np.r_[y, s])]
        ax.plot(lim, lim, color="0.5", lw=0.8)
        ax.set_xlabel(f"measured {q.replace('_', ' ')} [{unit}]")
        ax.set_ylabel(f"simulated [{unit}]")
    fig.tight_layout()
    with atomic_output(out / "measured_vs_simulated.png") as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
    lines = [f"# {simulated.name} (DEM-FEM) against {data.name}", ""]
    if command:
        lines += [f"Reproduce: `{command}`", ""]
    lines += [f"Simulated: {simulated.notes}.", "",
              f"{len(c.pairs)} measured conditions have a simulated run at the same slip, slip angle, load, gravity, "
              f"pass and wheel; {len(c.unmatched)} have none and are left out.", "",
              "| response | pairs | bias | RMS error | bias / spread | RMS / spread | within 2σ |", "|---|---|---|---|---|---|---|"]
    for q, v in c.responses.items():
        unit, k = UNITS[q]
        within = f"{v['within_2sigma']:.0%}" if v["within_2sigma"] is not None else "–"
        lines.append(f"| {q} | {v['n']} | {k * v['bias']:+.4g} {unit} | {k * v['rmse']:.4g} {unit} | {v['nbias']:+.3f} | "
                     f"{v['nrmse']:.3f} | {within} |")
    lines += ["", "Residual (simulated − measured) trends, Spearman, strongest first:", "",
              "| response | condition | ρ | p |", "|---|---|---|---|"]
    lines += [f"| {t['response']} | {t['condition']} | {t['spearman']:+.2f} | {t['p_value']:.1g} |" for t in c.trends[:10]]
    if c.systematic:
        lines += ["", "Systematic (p < %g): " % TREND_P + "; ".join(
            f"{t['response']} error {'grows' if t['spearman'] > 0 else 'falls'} with {t['condition']}" for t in c.systematic)
            + "."]
    else:
        lines += ["", f"No residual trend reaches p < {TREND_P:g}."]
    lines += _by_group_lines(c, data, simulated, findings)
    lines += _repeat_lines(c, data, simulated, findings)
    lines += ["", "![measured vs simulated](measured_vs_simulated.png)"]
    findings["report"] = str(write_markdown_and_json(out / "report.md", "\n".join(lines) + "\n",
                                                     out / "findings.json", findings))
    return findings
