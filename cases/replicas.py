"""Replicas: one case run on beds of other particle seeds, and how far its own error bars can be trusted.

A run's summary gives each steady mean a standard error from its batch means (one per pitch of the tread). That
error sees the noise within the run's window, not the run-to-run spread of packings, and batch means that are
correlated over longer than a pitch make it too small. ``wheelsoil replicate CASE --seeds 0 1 2 3 4`` runs the case
on one bed per seed (a sweep over ``case.seed``: finished replicas are kept) and writes ``replicas.md`` and
``replicas.json``: for every reported quantity

* the replicas' mean and their standard deviation s (ddof 1) -- the run-to-run spread;
* the root mean square of the runs' own standard errors, and the **inflation factor** s / rms(sem) with its 95 %
  interval from the chi-square distribution of s^2 (n - 1 degrees of freedom): a factor above 1 beyond its
  interval says the runs' error bars are too small by that much;
* the **coverage**: how many runs' own 95 % intervals (``ci95``, Student's t) hold the mean of the other replicas,
  with the interval widened by sqrt(1 + 1 / (n - 1)) for that mean's own scatter; an honest interval holds it in
  about 95 % of runs;
* the **excess spread** sigma_x = sqrt(max(0, s^2 - mean(sem^2))): the part of the run-to-run spread that no error
  bar from within one run sees (a one-way random-effects model, method of moments). It holds the packing's share
  (another seed, another bed) and the trajectory's (the same bed run again diverges from round-off on: the smoke
  case's reruns at later commits scatter as much as its seeds); it is added in quadrature to each level's error by
  ``wheelsoil convergence --replicas``. And the **replicas' mean with its 95 % interval**, t(0.975, n - 1) s /
  sqrt(n): the error bar the replicas give a number;
* with factors from another replica set of n_f runs (``--widen-by REPLICAS_JSON``, :class:`ReplicaSpread`: per
  quantity f = max(1, its inflation)), the coverage of the runs' intervals widened to t(0.975, n_f - 1) f sem (never
  below the run's own ``ci95``): the check, on replicas not used to set the factors, that a widened single-run
  interval holds as often as it claims. Student's t at n_f - 1 degrees of freedom carries the factor's own scatter:
  f sem is an estimate of the spread from n_f runs, so a normal 1.96 f sem would hold only about 88 % of the time
  with n_f = 5 (tests/test_cases_replicas.py).

Only steady runs count; runs that are not steady are listed.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.stats import chi2

from wheelsoil.coupling.run_summary import RunSummary
from wheelsoil.coupling.steady import t_quantile
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.provenance import atomic_output

from .convergence import QUANTITIES
from .run import RESULT_NAME
from .schema import CaseFile, apply_overrides, validate_case
from .sweep import Sweep, SweepCase

def check_seeds(seeds) -> tuple[int, ...]:
    """At least two distinct non-negative integer seeds."""
    try:
        out = tuple(int(s) for s in seeds)
    except (TypeError, ValueError):
        raise WheelsoilInputError(f"--seeds {seeds!r}: give integers (e.g. --seeds 0 1 2 3 4)") from None
    if len(out) < 2 or len(set(out)) != len(out) or min(out) < 0 or any(int(s) != float(s) for s in seeds):
        raise WheelsoilInputError(f"--seeds {list(seeds)}: give at least two distinct integers >= 0 (a spread "
                                  "between runs needs two runs)")
    return out


def make_replicas(base: CaseFile, seeds, out: str | Path) -> Sweep:
    """The sweep of the base case over ``case.seed`` (every replica validated before anything runs)."""
    seeds = check_seeds(seeds)
    out = Path(out)
    return Sweep(name=f"replicas-{base.name}", cases=[replica(base, seed, out) for seed in seeds], out=out,
                 swept_keys=["case.seed"])


def replica(base: CaseFile, seed: int, out: str | Path) -> SweepCase:
    """The replica of ``base`` on seed ``seed``: its case (validated) and its folder in the replica set ``out``."""
    d = apply_overrides(base.model_dump(mode="json"), [(["case", "seed"], int(seed))])
    d["case"]["name"] = f"{base.name}-seed{seed}"
    case = validate_case(d, f"replica of {base.name}, seed {seed}")
    return SweepCase(values={"case.seed": int(seed)}, case=case, folder=Path(out) / "cases" / case.case_hash())


def _summaries(sweep: Sweep) -> list[tuple[int, RunSummary | None]]:
    from .results import load_result

    out = []
    for c in sweep.cases:
        path = c.folder / RESULT_NAME
        out.append((c.values["case.seed"], load_result(path).summary if path.is_file() else None))
    return out


@dataclass(frozen=True)
class ReplicaSpread:
    """What a replica set of ``replicas`` runs measured, read from its ``replicas.json`` (``source``): per quantity
    the factor f = max(1, inflation) (1 where it measured none), the excess spread sigma_x (0 where none) and the
    replicas' spread s (NaN where none; both in the quantity's units)."""

    factors: dict[str, float]
    excess: dict[str, float]
    spread: dict[str, float]
    replicas: int
    source: str

    @classmethod
    def read(cls, path: str | Path, option: str = "--widen-by") -> "ReplicaSpread":
        """The replica set of ``path``; a file that is not a ``replicas.json`` with at least two steady replicas is
        refused, naming the command-line ``option`` it came from."""
        path = Path(path)
        try:
            stats = json.loads(path.read_text())
            quantities, replicas = stats["quantities"], len(stats["steady"])
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise WheelsoilInputError(f"{option} {path}: not a replicas.json written by 'wheelsoil replicate' "
                                      f"({type(exc).__name__}: {exc})") from None
        if replicas < 2:
            raise WheelsoilInputError(f"{option} {path}: {replicas} steady replicas; a spread needs at least two")
        factors, excess, spread = {}, {}, {}
        for q in QUANTITIES:
            row = quantities.get(q, {})
            f = _finite(row.get("inflation"))
            factors[q] = max(1.0, f) if f is not None else 1.0
            excess[q] = _finite(row.get("excess_spread")) or 0.0
            s = _finite(row.get("spread"))
            spread[q] = s if s is not None else math.nan
        return cls(factors, excess, spread, replicas, str(path))

    def half_width(self, quantity: str, sem):
        """The widened 95 % half-width t(0.975, n_f - 1) f sem (units of ``sem``)."""
        return t_quantile(self.replicas - 1) * self.factors[quantity] * np.asarray(sem, float)


def _finite(value) -> float | None:
    try:
        value = float(value)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def replica_statistics(summaries: list[tuple[int, RunSummary | None]], widening: ReplicaSpread | None = None) -> dict:
    """The replicas' statistics (see the module docstring) from (seed, summary or None) pairs; ``widening``: the
    factors of another replica set whose widened intervals to check."""
    done = [(s, m) for s, m in summaries if m is not None]
    steady = [(s, m) for s, m in done if m.steady]
    result = {"seeds": [s for s, _ in summaries], "finished": [s for s, _ in done],
              "steady": [s for s, _ in steady], "quantities": {}}
    n = len(steady)
    for q in QUANTITIES:
        x = np.array([m.quantity(q).mean for _, m in steady], float)
        sem = np.array([m.quantity(q).sem for _, m in steady], float)
        ci = np.array([m.quantity(q).ci95 for _, m in steady], float)
        row = {"n": n, "values": x.tolist(), "sems": sem.tolist()}
        if n >= 2:
            sd = float(np.std(x, ddof=1))
            rms = float(np.sqrt(np.mean(sem ** 2))) if np.all(np.isfinite(sem)) else math.nan
            lo, hi = chi2.ppf(0.975, n - 1), chi2.ppf(0.025, n - 1)
            row.update(mean=float(x.mean()), spread=sd, rms_sem=rms,
                       inflation=sd / rms if rms > 0 else math.nan,
                       inflation_interval=[sd * math.sqrt((n - 1) / lo) / rms, sd * math.sqrt((n - 1) / hi) / rms]
                       if rms > 0 else [math.nan, math.nan])
            excess = math.sqrt(max(0.0, sd * sd - float(np.mean(sem ** 2)))) if math.isfinite(rms) else math.nan
            row.update(excess_spread=excess, mean_ci95=t_quantile(n - 1) * sd / math.sqrt(n))
            others = np.array([(x.sum() - x[k]) / (n - 1) for k in range(n)])
            reach = np.abs(x - others) / math.sqrt(1.0 + 1.0 / (n - 1))
            known = np.isfinite(ci)
            row.update(covered=int(np.sum((reach <= ci) & known)), coverage_runs=int(known.sum()))
            if widening is not None:
                # never narrower than the run's own interval (a factor of 1 at n_f - 1 dof above the run's own
                # would otherwise narrow it)
                widened = np.maximum(ci, widening.half_width(q, sem))
                row.update(factor=widening.factors[q], covered_widened=int(np.sum((reach <= widened) & known)))
        result["quantities"][q] = row
    return result


def write_report(sweep: Sweep, base: CaseFile, widen_by: str | Path | None = None) -> list[Path]:
    """replicas.json and replicas.md in the sweep folder (``widen_by``: a replicas.json whose factors to check)."""
    widening = ReplicaSpread.read(widen_by) if widen_by is not None else None
    stats = replica_statistics(_summaries(sweep), widening)
    if widening is not None:
        stats["widened_by"] = {"source": widening.source, "replicas": widening.replicas, "factors": widening.factors}
    sweep.out.mkdir(parents=True, exist_ok=True)
    with atomic_output(sweep.out / "replicas.json") as tmp:
        tmp.write_text(json.dumps({"case": base.name, **stats}, indent=2, default=float))
    with atomic_output(sweep.out / "replicas.md") as tmp:
        tmp.write_text(report_markdown(base.name, stats))
    return [sweep.out / "replicas.json", sweep.out / "replicas.md"]


def report_markdown(name: str, stats: dict) -> str:
    seeds, steady = stats["seeds"], stats["steady"]
    unsteady = sorted(set(stats["finished"]) - set(steady))
    lines = [f"# Replicas of {name}", "",
             f"Seeds {', '.join(map(str, seeds))}: {len(stats['finished'])} finished, {len(steady)} steady"
             + (f" (not steady, left out: {', '.join(map(str, unsteady))})" if unsteady else "") + ".", "",
             "Spread: the replicas' standard deviation (run to run). Own error: the root mean square of the runs' "
             "standard errors. Inflation: spread / own error with its 95 % interval (chi-square); above 1 the runs' "
             "error bars are too small. Coverage: runs whose own 95 % interval (widened by sqrt(1 + 1/(n-1))) holds "
             "the mean of the other replicas. Excess: the spread no error bar from within one run sees, "
             "sqrt(max(0, spread^2 - mean own error^2)). The replicas' mean is given with its 95 % interval, "
             "t(n-1) spread / sqrt(n)."
             + (f" Widened: the coverage with every run's 95 % interval widened to t(0.975, n_f - 1) f sem (never "
                f"below its own), f = max(1, inflation) as the {stats['widened_by']['replicas']} replicas of "
                f"{stats['widened_by']['source']} measured it." if "widened_by" in stats else ""), "",
             "| quantity | mean (95 %) | spread | own error | excess | inflation | coverage |"
             + (" factor | coverage widened |" if "widened_by" in stats else ""),
             "|---|---|---|---|---|---|---|" + ("---|---|" if "widened_by" in stats else "")]
    for q, (label, unit, scale) in QUANTITIES.items():
        r = stats["quantities"][q]
        if r["n"] < 2:
            empty = 5 + 2 * ("widened_by" in stats)
            lines.append(f"| {label} [{unit}] | fewer than two steady replicas |" + " |" * empty)
            continue
        lo, hi = r["inflation_interval"]
        widened = (f" {r['factor']:.2f} | {r['covered_widened']} of {r['coverage_runs']} |"
                   if "factor" in r else "")
        lines.append(f"| {label} [{unit}] | {scale * r['mean']:.4g} ± {scale * r['mean_ci95']:.2g} | "
                     f"{scale * r['spread']:.2g} | {scale * r['rms_sem']:.2g} | {scale * r['excess_spread']:.2g} | "
                     f"{r['inflation']:.2f} ({lo:.2f}–{hi:.2f}) | {r['covered']} of {r['coverage_runs']} |"
                     + widened)
    return "\n".join(lines) + "\n"
