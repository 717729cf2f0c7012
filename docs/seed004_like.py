"""Seed 004 like for like (issue 35 item 4): the `seed004-like` sweep's runs compared in the seed's own terms.

Seed 004 reports percentages, each averaged over its slips 10-60 % (its sections on Figs. 6-8 and its conclusions):

* **steering**, from 5 to 20 deg at each of its three conditions: the drawbar pull falls by 36.9 / 28.1 / 26.3 % on
  average (1g, W = 3000 N / 1g, W = 500 N / 1/6 g, W = 500 N), the lateral force rises by 301.0 / 221.8 / 211.7 %, the
  sinkage by 26.7 / 19.1 / 18.1 %;
* **gravity**, 1g with W = 3000 N against 1/6 g with W = 500 N (the same mass), the "average difference" at each
  steering angle (5, 10, 20 deg): drawbar pull 80.7, 83.4, 61.3 %; lateral force 80.4, 84.1, 84.7 %; sinkage 12.6,
  16.2, 7.1 %;
* **load**, 1g with W = 3000 N against 1g with W = 500 N: drawbar pull 63.1, 55.6, 21.9 %; lateral force 77.9, 81.8,
  82.3 %; sinkage 87.6, 87.4, 85.8 %.

Read here (fixed on 2026-11-28 before any run of the sweep): a change from A to B at one slip is
100 (|q_B| - |q_A|) / |q_A| (the lateral force by its magnitude, which the steering raises), a difference between two
conditions 100 |q_A - q_B| / |q_A| with A the 1g, W = 3000 N run; each averaged over the slips at which both runs are
steady, and reported only where at least four of the six are. Its error: each run's standard error widened by the
smoke replicas' inflation at its gravity (``docs/replicas/smoke-{1g,moon}-steer/replicas.json``, ``ReplicaSpread``),
carried through the ratio to first order and through the average over slips; the interval is two of those errors.
The seed's figure *agrees* where it lies inside that interval, goes *the same way* where the two have the same sign and
it does not, and *disagrees* otherwise. The scale's own error (``docs/error_budget.py``: 3-42 % on each absolute value
at smoke scale) is not in the interval: a change between two runs at one scale carries it only as far as it differs
between the two conditions, which nothing here measures, and the report says so.

Usage (from the repository root; seconds)::

    python docs/seed004_like.py --runs RUNS/seed004-like --out docs/sweeps/seed004-like
"""

import argparse
import math
import sys
from pathlib import Path

import numpy as np

#: The three conditions: (gravity, load [N]).
EARTH_3000, EARTH_500, MOON_500 = ("earth", 3000.0), ("earth", 500.0), ("moon", 500.0)
QUANTITIES = ("drawbar_pull", "lateral_force", "sinkage")
SLIPS = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6)
#: Fewest slips with both runs steady for an average to be reported.
MIN_SLIPS = 4
#: Seed 004's reported percentages (see the module docstring).
SEED004 = {
    "steering": {EARTH_3000: {"drawbar_pull": -36.9, "lateral_force": 301.0, "sinkage": 26.7},
                 EARTH_500: {"drawbar_pull": -28.1, "lateral_force": 221.8, "sinkage": 19.1},
                 MOON_500: {"drawbar_pull": -26.3, "lateral_force": 211.7, "sinkage": 18.1}},
    "gravity": {"drawbar_pull": {5: 80.7, 10: 83.4, 20: 61.3}, "lateral_force": {5: 80.4, 10: 84.1, 20: 84.7},
                "sinkage": {5: 12.6, 10: 16.2, 20: 7.1}},
    "load": {"drawbar_pull": {5: 63.1, 10: 55.6, 20: 21.9}, "lateral_force": {5: 77.9, 10: 81.8, 20: 82.3},
             "sinkage": {5: 87.6, 10: 87.4, 20: 85.8}},
}
REPLICAS = {"earth": Path("docs/replicas/smoke-1g-steer/replicas.json"),
            "moon": Path("docs/replicas/smoke-moon-steer/replicas.json")}


def read_runs(folder: Path) -> dict:
    """(gravity, load, steering angle, slip) -> {"steady": bool, q: (mean, sem)} of every finished case, read as typed
    results (``wheelsoil.cases.load_result``: the case it ran and its summary)."""
    from wheelsoil.cases.results import load_result
    from wheelsoil.cases.run import RESULT_NAME

    runs = {}
    for path in sorted((folder / "cases").glob(f"*/{RESULT_NAME}")):
        result = load_result(path)
        test, s = result.case.test, result.summary
        key = (result.case.soil.gravity, float(test.load), float(test.slip_angle), round(float(test.slip), 6))
        runs[key] = {"steady": bool(s.steady), **{q: (s.quantity(q).mean, s.quantity(q).sem) for q in QUANTITIES}}
    return runs


def _change(a: tuple, b: tuple, fa: float, fb: float, *, difference: bool) -> tuple[float, float]:
    """100 (|b| - |a|) / |a| (or 100 |a - b| / |a| for a ``difference``) and its standard error from the runs' sems
    widened by ``fa`` and ``fb``."""
    (ma, sa), (mb, sb) = a, b
    value = 100.0 * (abs(ma - mb) if difference else abs(mb) - abs(ma)) / abs(ma)
    # both forms have the same partial derivatives in magnitude: 100 / |a| in b, 100 |b| / a^2 in a
    return value, 100.0 * math.hypot(fb * sb / abs(ma), abs(mb) * fa * sa / ma ** 2)


def averaged(runs: dict, factors: dict, a: tuple, b: tuple, quantity: str, *, difference: bool) -> dict:
    """The change from condition ``a`` to ``b`` ((gravity, load, angle) each) averaged over the slips at which both
    runs are steady: value, its error, the slips used."""
    values, errors, used = [], [], []
    for slip in SLIPS:
        ra, rb = runs.get((*a, slip)), runs.get((*b, slip))
        if ra is None or rb is None or not (ra["steady"] and rb["steady"]):
            continue
        v, e = _change(ra[quantity], rb[quantity], factors[a[0]][quantity], factors[b[0]][quantity],
                       difference=difference)
        values.append(v)
        errors.append(e)
        used.append(slip)
    if len(used) < MIN_SLIPS:
        return {"value": math.nan, "error": math.nan, "slips": used}
    return {"value": float(np.mean(values)), "error": float(math.sqrt(np.sum(np.square(errors))) / len(used)),
            "slips": used}


def verdict(seed: float, here: dict) -> str:
    if not math.isfinite(here["value"]):
        return f"not reported: {len(here['slips'])} of {len(SLIPS)} slips with both runs steady"
    if abs(seed - here["value"]) <= 2.0 * here["error"]:
        return "agrees"
    return "the same way" if np.sign(seed) == np.sign(here["value"]) else "disagrees"


def compare(runs: dict, factors: dict) -> list[dict]:
    """Every figure of :data:`SEED004` beside this sweep's."""
    rows = []
    for condition, figures in SEED004["steering"].items():
        for q, seed in figures.items():
            here = averaged(runs, factors, (*condition, 5.0), (*condition, 20.0), q, difference=False)
            rows.append({"comparison": "steering 5 -> 20 deg", "condition": f"{condition[0]}, W = {condition[1]:g} N",
                         "quantity": q, "seed004": seed, **here, "verdict": verdict(seed, here)})
    for name, other in (("gravity", MOON_500), ("load", EARTH_500)):
        for q, by_angle in SEED004[name].items():
            for angle, seed in by_angle.items():
                here = averaged(runs, factors, (*EARTH_3000, float(angle)), (*other, float(angle)), q, difference=True)
                rows.append({"comparison": f"{name}: earth, W = 3000 N against {other[0]}, W = {other[1]:g} N",
                             "condition": f"{angle} deg", "quantity": q, "seed004": seed, **here,
                             "verdict": verdict(seed, here)})
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", required=True, help="the seed004-like sweep's folder")
    ap.add_argument("--out", default="docs/sweeps/seed004-like")
    args = ap.parse_args(argv)

    from wheelsoil.cases.replicas import ReplicaSpread
    from wheelsoil.provenance import provenance, write_markdown_and_json

    factors = {g: ReplicaSpread.read(path).factors for g, path in REPLICAS.items()}
    runs = read_runs(Path(args.runs))
    rows = compare(runs, factors)
    steady = sum(r["steady"] for r in runs.values())
    lines = ["# Seed 004 like for like at smoke scale (issue 35 item 4)", "",
             f"Generated by `python docs/seed004_like.py --runs RUNS/seed004-like --out {args.out}` "
             f"(`docs/seed004_like.py` says how each figure is read); {len(runs)} of 54 runs finished, {steady} "
             "steady. Percentages averaged over the slips at which both runs are steady; ± two standard errors from "
             "the runs' own errors widened by the smoke replicas' inflation; the scale's error is not included.", "",
             "| comparison | condition | quantity | seed 004 [%] | here [%] | slips | verdict |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        here = "–" if not math.isfinite(r["value"]) else f"{r['value']:+.1f} ± {2 * r['error']:.1f}"
        lines.append(f"| {r['comparison']} | {r['condition']} | {r['quantity']} | {r['seed004']:+.1f} | {here} | "
                     f"{', '.join(f'{s:g}' for s in r['slips']) or '–'} | {r['verdict']} |")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_markdown_and_json(out / "comparison.md", "\n".join(lines) + "\n", out / "comparison.json",
                            {"rows": rows, "provenance": provenance()}, default=float)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
