"""What a calibrated model leaves in its residuals: trends against each condition, and how much of the misfit
is systematic rather than noise.

* :func:`residual_trends`: Spearman rank correlation of each response's residual with each condition that varies
  (monotone trends; what a plot of residual against condition shows).
* :func:`systematic_residual`: a lack-of-fit test that needs no replicate measurements. Each response's
  normalised residual is regressed on a full quadratic in the conditions that vary (linear, square and pairwise
  product terms of the standardised conditions). Under a model that is right up to independent noise the
  regression explains only noise: its F statistic follows F(p, n - p - 1) (the regression F-test; Draper & Smith,
  Applied Regression Analysis, sec. 2.8; Ramsey's RESET is the same idea with fitted values as regressors). The
  sum of squares the regression explains beyond its noise expectation p s^2 is the *systematic residual*: the part
  of the misfit a smooth function of the conditions would remove. A mechanism that is the cause of a misfit
  removes it; one that only resembles it leaves part of it (:mod:`.discovery` uses both).
* :func:`residuals_by_group`: bias and RMS of each response's residual within each kind of motion (driving,
  braking, dragged), each steering angle and, where the rows hold more than one, each wheel (by its grousers), with
  the trend against slip inside the group, so an error that lives in one branch is not averaged away by the others.
* :func:`unexplained_trends`: for each response whose lack of fit is significant, the conditions whose terms carry
  most of it (partial sums of squares), with their shares and the Spearman trend: "error trends with X".
"""

from itertools import combinations

import numpy as np
from scipy.stats import f as f_distribution
from scipy.stats import spearmanr

from .measured import Measurements

CONDITIONS = ("slip", "slip_angle", "load", "gravity", "passes", "grouser_height")
#: Significance of a response's lack of fit, before the Bonferroni division by the number of responses.
LACK_OF_FIT_ALPHA = 1e-3
#: An unexplained trend names every condition whose terms carry at least this share of the response's
#: systematic residual (shares overlap: a product term counts for both of its conditions).
NAMED_SHARE = 0.3


def residual_trends(residuals: dict[str, np.ndarray], data: Measurements, rows: dict[str, np.ndarray]) -> list[dict]:
    """Spearman rank correlation of each response's residual with each condition variable that varies.

    residuals: response -> residual at its measured rows; rows: response -> boolean mask of those rows."""
    out = []
    for q, res in residuals.items():
        ok = rows[q]
        for c in CONDITIONS:
            x = np.asarray(getattr(data, c), float)[ok]
            if x.size < 4 or np.ptp(x) == 0:
                continue
            rho, p = spearmanr(x, res)
            out.append({"response": q, "condition": c, "spearman": float(rho), "p_value": float(p)})
    return sorted(out, key=lambda r: r["p_value"])


def residuals_by_group(models: dict[str, dict[str, np.ndarray]], data: Measurements) -> list[dict]:
    """Each model's residual per response within each row group: the kinds of motion
    (:meth:`~.measured.Measurements.kinds`), the steering angles (rounded to 0.1 deg) and, where the rows hold more
    than one, the wheels (by grouser height: "smooth" or "<h> mm grousers").

    models: model name -> response -> residual over all rows (NaN where unmeasured). Returns one dict per (group,
    response): "by" ("motion", "slip_angle" or "wheel"), "group", "response", "rows", and per model "bias", "rms"
    and "slip_spearman" (the residual's rank correlation with the heading slip inside the group; None with fewer than
    4 rows, one slip or a constant residual)."""
    out = []
    groups = [("motion", k, data.kinds() == k) for k in ("driving", "braking", "dragged")]
    angles = np.round(np.asarray(data.slip_angle, float), 1)
    groups += [("slip_angle", f"{a:g}", angles == a) for a in np.unique(angles)]
    heights = np.round(1e3 * np.asarray(data.grouser_height, float), 2)  # [mm]
    if np.unique(heights).size > 1:
        groups += [("wheel", "smooth" if h == 0 else f"{h:g} mm grousers", heights == h) for h in np.unique(heights)]
    responses = next(iter(models.values())).keys() if models else ()
    for by, group, mask in groups:
        for q in responses:
            row = {"by": by, "group": group, "response": q}
            for name, res in models.items():
                r = res[q]
                ok = mask & np.isfinite(r)
                row["rows"] = int(ok.sum())
                if not ok.any():
                    break
                rho = None
                slip = np.asarray(data.slip, float)[ok]
                if ok.sum() >= 4 and np.ptp(slip) > 0 and np.ptp(r[ok]) > 0:
                    rho = float(spearmanr(slip, r[ok])[0])
                row[name] = {"bias": float(np.mean(r[ok])), "rms": float(np.sqrt(np.mean(r[ok] ** 2))),
                             "slip_spearman": rho}
            if row["rows"]:
                out.append(row)
    return out


def group_table(groups: list[dict], models: tuple[str, ...], *, count: str = "rows") -> list[str]:
    """Markdown table of :func:`residuals_by_group`'s rows: each model's bias and RMS (``a → b`` for several, in the
    order of ``models``) and the last model's trend with slip (– where it has none); ``count`` names the row count's
    column."""
    over = "" if len(models) == 1 else ", " + " → ".join(models)
    lines = [f"| group | response | {count} | bias{over} | RMS{over} | trend with slip |", "|---|---|---|---|---|---|"]
    for g in groups:
        rho = g[models[-1]]["slip_spearman"]
        label = f"{g['group']}°" if g["by"] == "slip_angle" else g["group"]
        bias = " → ".join(f"{g[m]['bias']:+.3f}" for m in models)
        rms = " → ".join(f"{g[m]['rms']:.3f}" for m in models)
        lines.append(f"| {label} | {g['response']} | {g['rows']} | {bias} | {rms} | "
                     f"{'–' if rho is None else f'{rho:+.2f}'} |")
    return lines


def _design(x: dict[str, np.ndarray]) -> tuple[np.ndarray, list[tuple[str, ...]]]:
    """Quadratic design (without intercept) over the standardised columns of ``x``: each term names the
    conditions it involves."""
    cols, terms = [], []
    z = {c: (v - v.mean()) / v.std() for c, v in x.items()}
    for c, v in z.items():
        cols.append(v)
        terms.append((c,))
        if np.unique(v).size > 2:  # a square of a two-level factor is the intercept again
            cols.append(v * v - np.mean(v * v))
            terms.append((c,))
    for a, b in combinations(z, 2):
        cols.append(z[a] * z[b] - np.mean(z[a] * z[b]))
        terms.append((a, b))
    return (np.column_stack(cols) if cols else np.zeros((len(next(iter(x.values()), [])), 0))), terms


def _regress(design: np.ndarray, y: np.ndarray) -> tuple[float, float, int]:
    """Sum of squares explained by ``design`` (centred y), residual sum of squares, rank."""
    yc = y - y.mean()
    if design.shape[1] == 0:
        return 0.0, float(yc @ yc), 0
    coef, _, rank, _ = np.linalg.lstsq(design - design.mean(axis=0), yc, rcond=1e-10)
    fitted = (design - design.mean(axis=0)) @ coef
    return float(fitted @ fitted), float((yc - fitted) @ (yc - fitted)), int(rank)


def systematic_residual(residuals: dict[str, np.ndarray], data: Measurements, rows: dict[str, np.ndarray]) -> dict:
    """Lack of fit per response (see the module docstring).

    Returns {"responses": {q: {"ss_explained", "ss_noise", "systematic", "f", "p_value", "terms", "rows",
    "by_condition": {c: partial systematic SS}}}, "systematic": total systematic SS (normalised units^2)}.
    """
    out, total = {}, 0.0
    for q, res in residuals.items():
        ok = rows[q]
        x = {c: np.asarray(getattr(data, c), float)[ok] for c in CONDITIONS}
        x = {c: v for c, v in x.items() if v.size > 1 and np.ptp(v) > 0}
        design, terms = _design(x)
        n = res.size
        while design.shape[1] and n - design.shape[1] - 1 < 10:  # too few rows for the quadratic: fewer terms
            design, terms = design[:, :-1], terms[:-1]
        ss_reg, ss_res, p = _regress(design, res)
        dof = max(n - p - 1, 1)
        s2 = ss_res / dof
        f = (ss_reg / p) / s2 if p and s2 > 0 else 0.0
        p_value = float(f_distribution.sf(f, p, dof)) if p else 1.0
        systematic = max(ss_reg - p * s2, 0.0)
        by_condition = {}
        for c in x:
            keep = [j for j, t in enumerate(terms) if c not in t]
            ss_without, _, p_without = _regress(design[:, keep], res)
            by_condition[c] = max(ss_reg - ss_without - (p - p_without) * s2, 0.0)
        out[q] = {"ss_explained": ss_reg, "ss_noise": p * s2, "systematic": systematic, "f": float(f),
                  "p_value": p_value, "terms": p, "rows": n, "noise_variance": s2, "by_condition": by_condition}
        total += systematic
    return {"responses": out, "systematic": total}


def unexplained_trends(lack: dict, trends: list[dict], *, alpha: float = LACK_OF_FIT_ALPHA) -> list[dict]:
    """Responses whose residual still holds a significant systematic part (p below ``alpha`` / number of
    responses): the condition carrying most of it, its share of that response's systematic residual, and the
    Spearman trend of the residual with it."""
    responses = lack["responses"]
    cutoff = alpha / max(len(responses), 1)
    out = []
    for q, r in responses.items():
        if r["p_value"] >= cutoff or r["systematic"] <= 0:
            continue
        parts = r["by_condition"]
        ranked = sorted(parts, key=parts.get, reverse=True)
        shares = {c: min(parts[c] / r["systematic"], 1.0) for c in ranked}
        named = [c for c in ranked if shares[c] >= NAMED_SHARE] or ranked[:1]
        cond = named[0] if named else None
        trend = next((t for t in trends if t["response"] == q and t["condition"] == cond), None)
        with_ = ", ".join(f"{c.replace('_', ' ')} ({100 * shares[c]:.0f} %)" for c in named)
        out.append({"response": q, "condition": cond, "conditions": {c: float(shares[c]) for c in named},
                    "share": float(shares[cond]) if cond else 0.0, "systematic": r["systematic"],
                    "p_value": r["p_value"], "spearman": trend["spearman"] if trend else None,
                    "text": f"error in {q.replace('_', ' ')} trends with {with_ or '?'}"})
    return sorted(out, key=lambda u: -u["systematic"])
