"""Why the traction coefficient moves at 1/6 g at equal mass, term by term (issue 35 item 4; docs/gravity-terms).

The smoke case at 1g (W = 3000 N) and at 1/6 g (W = 500 N: the same mass) differ, once lengths and masses are kept,
in three dimensionless groups besides gravity itself (wheelsoil.cases.similarity): the Froude number v^2 / (g r) (the
rig's speeds are the same at both gravities), the grains' stiffness E / (rho g r) and the wheel's E I / (W r^2) (the
same materials under a sixth of the load). The variants below are the 1g case carried to 1/6 g by the similarity
transform with some of its scalings left out; each step from one to the next changes one group:

    moon (the smoke-moon-steer replicas)  -- time scaled -->  froude  -- soil modulus / 6 -->  soil-stiffness
        -- wheel modulus / 6 -->  similar (every group of the 1g case: must give the 1g case's coefficients)

and, as a check of the conclusion the first runs pointed to, the rigid wheel of the same surface at both gravities
(rigid-earth, rigid-moon: a wheel that cannot deflect has no stiffness group).

Commands (resumable; each run kept under RUNS/gravity-terms/<variant>/cases/<hash>, a lock beside it so that a second
runner started with --variants skips a case the first is running; each finished run's values are recorded in
docs/gravity-terms/runs.json by the report):

    python docs/gravity_terms.py run --runs RUNS --seeds 0 1 2      # seed 0 of every variant, then seed 1, ...
    python docs/gravity_terms.py report --runs RUNS --out docs/gravity-terms

The reading rule is fixed in docs/gravity-terms/README.md before any run.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
BASE_CASE = "smoke-1g-steer"
TARGET_GRAVITY = "moon"
#: the baselines: the stored replica sets of the two smoke cases (docs/replicas.md)
BASELINES = {"earth": ROOT / "docs/replicas/smoke-1g-steer/replicas.json",
             "moon": ROOT / "docs/replicas/smoke-moon-steer/replicas.json"}
#: the coefficients compared: quantity -> (name, divided by W, or by W r, or by r)
COEFFICIENTS = {"drawbar_pull": ("DP / W", "W"), "lateral_force": ("F_y / W", "W"), "torque": ("T / (W r)", "Wr"),
                "sinkage": ("z / r", "r")}
#: a term is named where it moves a coefficient by more than this many combined standard errors
NAMED_SIGMAS = 2.0
#: the DEM step [s] the similar case runs at (2.6348e-4 s, its stable estimate), divided by tau = sqrt(6): the
#: diagnostic variant earth-step runs the 1g case at it
SIMILAR_STEP_AT_1G = 1.0756e-4


@dataclass(frozen=True)
class Variant:
    """A run of the study: the 1g case carried to 1/6 g keeping the keys ``keep`` (``preset`` None), or a preset with
    ``overrides`` as it is (the rigid-wheel check)."""

    name: str
    keep: tuple[str, ...]
    meaning: str
    preset: str | None = None
    overrides: tuple[str, ...] = ()


VARIANTS = (
    Variant("similar", (), "every group of the 1g case (time, soil and wheel moduli scaled)"),
    Variant("froude", ("soil.youngs_modulus", "wheel.youngs_modulus"),
            "the 1g case's Froude number; grains and wheel as stiff as at 1/6 g"),
    Variant("soil-stiffness", ("wheel.youngs_modulus",),
            "the 1g case's Froude number and grain stiffness; the wheel as stiff as at 1/6 g"),
    # added on 2026-11-30 (00:31) after the first three runs, before running them: the conclusion they point to (the
    # wheel's stiffness is the term) checked on a wheel that cannot deflect, at both gravities at equal mass
    Variant("rigid-earth", (), "the rigid wheel of the same surface, 1g, W = 3000 N", BASE_CASE, ("wheel.rigid=true",)),
    Variant("rigid-moon", (), "the rigid wheel of the same surface, 1/6 g, W = 500 N", "smoke-moon-steer",
            ("wheel.rigid=true",)),
    # added on 2026-12-07 after all fifteen runs, before its own: a diagnostic of the similarity check's one failure
    # (similar sinks 1.9 mm deeper than the 1g replicas). The similar case's DEM step is its stable estimate's Hertz
    # limit at the unscaled 1 m/s floor, 2.6348e-4 s, where tau times the 1g case's would be 2.6813e-4; this is the
    # 1g case at the step the similar case takes, carried back (2.6348e-4 / tau = 1.0756e-4 s, 1.75 % shorter than
    # its own 1.0947e-4). Read by the two diagnostic steps in STEPS, not by the chain.
    Variant("earth-step", (), "the 1g case at the similar case's DEM step carried back (1.75 % shorter)", BASE_CASE,
            (f"soil.time_step={SIMILAR_STEP_AT_1G!r}",)),
)


def variant_case(variant: Variant):
    from wheelsoil.cases.schema import load_case
    from wheelsoil.cases.similarity import similar_case

    if variant.preset is not None:
        return load_case(variant.preset, list(variant.overrides), name=f"gravity-{variant.name}")
    return similar_case(load_case(BASE_CASE), TARGET_GRAVITY, keep=variant.keep, name=f"gravity-{variant.name}")


def variant_runs(variant: Variant, runs: Path, seeds) -> list:
    """The variant's run on each seed (a replica set under RUNS/gravity-terms/<variant>: ``wheelsoil replicate
    --report-only`` reads it)."""
    from wheelsoil.cases.replicas import replica

    base = variant_case(variant)
    return [replica(base, seed, runs / "gravity-terms" / variant.name) for seed in seeds]


def cmd_run(args) -> int:
    import fcntl

    from wheelsoil.cases.sweep import Sweep, run_sweep

    runs = Path(args.runs)
    seeds = [int(s) for s in args.seeds]
    chosen = [v for v in VARIANTS if not args.variants or v.name in args.variants]
    unknown = set(args.variants or ()) - {v.name for v in VARIANTS}
    if unknown:
        raise SystemExit(f"--variants {sorted(unknown)}: not variants of the study ({[v.name for v in VARIANTS]})")
    every = {v.name: variant_runs(v, runs, seeds) for v in chosen}  # every case validated before any runs
    record_path = Path(args.recorded)
    recorded = json.loads(record_path.read_text()) if record_path.is_file() else {}
    for k, seed in enumerate(seeds):  # every variant's first seed before any second: the terms first, the spread after
        for v in chosen:
            case = every[v.name][k]
            if case.finished:
                print(f"{v.name}, seed {seed}: finished before ({case.folder})", flush=True)
                continue
            if recorded.get(v.name, {}).get(str(seed), {}).get("case_hash") == case.folder.name:
                # finished on a machine before this one: its record is what lasts, so it is not run twice
                print(f"{v.name}, seed {seed}: recorded in {record_path} (its files are not here); skipped", flush=True)
                continue
            case.folder.parent.mkdir(parents=True, exist_ok=True)
            with open(case.folder.parent / f"{case.folder.name}.lock", "w") as lock:
                try:  # another runner of the study (a second job started by hand) may hold this case
                    fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except BlockingIOError:
                    print(f"{v.name}, seed {seed}: running in another job; skipped here", flush=True)
                    continue
                print(f"{v.name}, seed {seed}: running ({case.folder})", flush=True)
                run_sweep(Sweep(name=f"gravity-{v.name}", cases=[case], out=case.folder.parent.parent,
                                swept_keys=["case.seed"]), workers=1)
    return 0


def _coefficient(quantity: str, value: float, case) -> float:
    """``value`` of ``quantity`` (forces [N], torque [N m], sinkage [m] as the summaries store them) over the load W,
    W r or r of ``case`` (its tread radius r)."""
    from wheelsoil.cases import build

    load, radius = case.test.load, build.wheel_geometry(case).radius
    return value / {"W": load, "Wr": load * radius, "r": radius}[COEFFICIENTS[quantity][1]]


@dataclass(frozen=True)
class Condition:
    """One condition's steady runs, each as {quantity: coefficient}."""

    name: str
    runs: list[dict]
    source: str
    #: runs that found no steady window by the end of their drive: their last window, for information only
    unsteady: tuple[dict, ...] = ()

    def mean(self, q: str) -> float:
        return float(np.mean([r[q] for r in self.runs]))

    def n(self) -> int:
        return len(self.runs)

    def spread(self, q: str) -> float:
        return float(np.std([r[q] for r in self.runs], ddof=1)) if self.n() > 1 else math.nan


def baseline(name: str, path: Path) -> Condition:
    """A stored replica set (``wheelsoil replicate``'s replicas.json) as a condition, each run's coefficients taken
    against its case's load and wheel."""
    from wheelsoil.cases.schema import load_case

    data = json.loads(path.read_text())
    case = load_case(data["case"])
    qs = data["quantities"]
    n = len(qs["drawbar_pull"]["values"])
    runs = [{q: _coefficient(q, qs[q]["values"][k], case) for q in COEFFICIENTS} for k in range(n)]
    return Condition(name, runs, str(path.relative_to(ROOT)))


def variant_records(variant: Variant, runs: Path, seeds, recorded: dict) -> dict:
    """{seed: record} of the variant's finished runs: read from their result files under RUNS where they are, else kept
    from ``recorded`` (the study's ``runs.json`` in the repository: a machine replaced between sessions takes the runs'
    files with it, not their records). A record holds the case hash, the verdict, the window, the reasons, the raw
    steady means (forces [N], torque [N m], sinkage [m]) and the coefficients."""
    from wheelsoil.cases.results import load_result

    out = {}
    for c in variant_runs(variant, runs, seeds):
        seed = c.values["case.seed"]
        path = c.folder / "result.h5"
        if path.is_file():
            summary = load_result(path).summary
            means = {q: summary.quantity(q).mean for q in (*COEFFICIENTS, "tread_sinkage", "vertical_force")}
            out[str(seed)] = {"case_hash": c.folder.name, "steady": bool(summary.steady),
                              "window": list(summary.window), "reasons": list(summary.reasons), "means": means,
                              "coefficients": {q: _coefficient(q, means[q], c.case) for q in COEFFICIENTS}}
        elif str(seed) in recorded and recorded[str(seed)]["case_hash"] == c.folder.name:
            out[str(seed)] = dict(recorded[str(seed)], recorded="earlier")
    return out


def variant_condition(variant: Variant, records: dict) -> Condition:
    """The variant's steady runs as coefficients, the others apart (for information)."""
    rows, unsteady = [], []
    for seed, rec in sorted(records.items(), key=lambda kv: int(kv[0])):
        if rec["steady"]:
            rows.append(dict(rec["coefficients"]))
        else:
            unsteady.append({"seed": int(seed), "window": rec["window"], "reasons": rec["reasons"],
                             **rec["coefficients"]})
    return Condition(variant.name, rows, f"RUNS/gravity-terms/{variant.name}", tuple(unsteady))


def pooled_spread(conditions: list[Condition], q: str) -> float:
    """The run-to-run standard deviation of a coefficient, pooled over every condition with two runs or more."""
    num = sum((c.n() - 1) * c.spread(q) ** 2 for c in conditions if c.n() > 1)
    dof = sum(c.n() - 1 for c in conditions if c.n() > 1)
    return math.sqrt(num / dof) if dof else math.nan


def term(a: Condition, b: Condition, q: str, spread: float) -> dict:
    """b - a in coefficient q, its standard error from the pooled run-to-run spread, and whether it is named."""
    if not a.n() or not b.n():
        return {"change": None, "se": None, "named": None}
    change = b.mean(q) - a.mean(q)
    se = spread * math.sqrt(1.0 / a.n() + 1.0 / b.n())
    return {"change": change, "se": se, "named": bool(abs(change) > NAMED_SIGMAS * se)}


#: the chain of single-group steps, then the check of the whole transform
STEPS = (("moon", "froude", "inertia (Froude number)"), ("froude", "soil-stiffness", "grain stiffness"),
         ("soil-stiffness", "similar", "wheel stiffness"), ("earth", "similar", "similarity check (must be 0)"),
         ("earth", "moon", "all of them: 1/6 g at equal mass"),
         ("rigid-earth", "rigid-moon", "1/6 g at equal mass, rigid wheel (the wheel's term removed)"),
         # the diagnostic of 2026-12-07: does the similar case's 1.75 % shorter step move the 1g case, and does the
         # similarity check hold at the same step
         ("earth", "earth-step", "diagnostic: the 1g case at the similar case's step"),
         ("earth-step", "similar", "diagnostic: the similarity check at the same step (must be 0)"))


def analyse(conditions: dict[str, Condition]) -> dict:
    spreads = {q: pooled_spread(list(conditions.values()), q) for q in COEFFICIENTS}
    steps = []
    for a, b, label in STEPS:
        ca, cb = (conditions.get(k, Condition(k, [], "no runs")) for k in (a, b))  # a condition not run: no change
        steps.append({"from": a, "to": b, "term": label, **{q: term(ca, cb, q, spreads[q]) for q in COEFFICIENTS}})
    return {"spreads": spreads, "steps": steps,
            "conditions": {k: {"runs": c.n(), "source": c.source,
                               "means": {q: (c.mean(q) if c.n() else None) for q in COEFFICIENTS},
                               "not_steady": list(c.unsteady)}
                           for k, c in conditions.items()}}


def _fmt(x, digits=4):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:+.{digits}f}"


def markdown(result: dict) -> str:
    lines = ["| condition | runs | " + " | ".join(n for n, _ in COEFFICIENTS.values()) + " |",
             "|---|---|" + "---|" * len(COEFFICIENTS)]
    for k, c in result["conditions"].items():
        lines.append(f"| {k} | {c['runs']} | " + " | ".join(_fmt(c["means"][q]) for q in COEFFICIENTS) + " |")
    lines += ["", "Run-to-run spread (pooled standard deviation): " + ", ".join(
        f"{COEFFICIENTS[q][0]} {result['spreads'][q]:.4f}" for q in COEFFICIENTS), "",
        "| step | term | " + " | ".join(n for n, _ in COEFFICIENTS.values()) + " |",
        "|---|---|" + "---|" * len(COEFFICIENTS)]
    for s in result["steps"]:
        cells = []
        for q in COEFFICIENTS:
            t = s[q]
            cells.append("–" if t["change"] is None else
                         f"{_fmt(t['change'])} ± {t['se']:.4f}{' **named**' if t['named'] else ''}")
        lines.append(f"| {s['from']} → {s['to']} | {s['term']} | " + " | ".join(cells) + " |")
    unsteady = [(k, u) for k, c in result["conditions"].items() for u in c["not_steady"]]
    if unsteady:
        lines += ["", "Not steady by the end of their drive (their last window, for information only: not a number "
                  "by the rule, and not in the tables above):", "",
                  "| condition | seed | window [s] | " + " | ".join(n for n, _ in COEFFICIENTS.values()) + " | why |",
                  "|---|---|---|" + "---|" * len(COEFFICIENTS) + "---|"]
        for k, u in unsteady:
            lines.append(f"| {k} | {u['seed']} | {u['window'][0]:.2f}–{u['window'][1]:.2f} | "
                         + " | ".join(_fmt(u[q]) for q in COEFFICIENTS) + f" | {'; '.join(u['reasons'])} |")
    return "\n".join(lines) + "\n"


def figure(result: dict, path: Path) -> None:
    """One panel per coefficient: each condition's mean with one standard error (the pooled spread / sqrt(n)), the
    chain's order from 1/6 g at equal mass (left) to the similar case and the 1g replicas (right)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    order = ["moon", "froude", "soil-stiffness", "similar", "earth", "rigid-moon", "rigid-earth"]
    labels = ["1/6 g, 500 N", "+ Froude", "+ grain\nstiffness", "+ wheel\nstiffness\n(similar)", "1g, 3000 N",
              "rigid,\n1/6 g", "rigid,\n1g"]
    fig, axes = plt.subplots(1, len(COEFFICIENTS), figsize=(4.6 * len(COEFFICIENTS), 3.8))
    for ax, q in zip(axes, COEFFICIENTS):
        means = [result["conditions"][k]["means"][q] for k in order]
        runs = [result["conditions"][k]["runs"] for k in order]
        spread = result["spreads"][q]
        for x, (m, n) in enumerate(zip(means, runs)):
            if m is not None:
                color = "C3" if order[x] in ("earth", "rigid-earth") else "C0"
                ax.errorbar(x, m, yerr=spread / math.sqrt(n), fmt="s" if order[x].startswith("rigid") else "o",
                            color=color, capsize=3)
            for u in result["conditions"][order[x]]["not_steady"]:  # for information: hollow, no error bar
                ax.plot(x + 0.12, u[q], "o", mfc="none", color="0.5")
        ax.set_xticks(range(len(order)), labels, fontsize=7)
        ax.set_title(COEFFICIENTS[q][0])
        ax.grid(alpha=0.3)
    fig.suptitle("smoke case, slip 0.3, 10 deg: the groups of 1/6 g at equal mass restored one by one "
                 "(hollow: runs not steady, for information)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def cmd_report(args) -> int:
    runs, out = Path(args.runs), Path(args.out)
    seeds = [int(s) for s in args.seeds]
    conditions = {name: baseline(name, path) for name, path in BASELINES.items()}
    record_path = out / "runs.json"
    recorded = json.loads(record_path.read_text()) if record_path.is_file() else {}
    records = {v.name: variant_records(v, runs, seeds, recorded.get(v.name, {})) for v in VARIANTS}
    for v in VARIANTS:
        conditions[v.name] = variant_condition(v, records[v.name])
    result = analyse(conditions)
    out.mkdir(parents=True, exist_ok=True)
    record_path.write_text(json.dumps(records, indent=1) + "\n")
    (out / "terms.json").write_text(json.dumps(result, indent=1) + "\n")
    (out / "terms.md").write_text(markdown(result))
    figure(result, out / "terms.png")
    print(markdown(result))
    return 0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(required=True)
    r = sub.add_parser("run", help="run the variants, seed by seed (resumable)")
    r.add_argument("--runs", required=True)
    r.add_argument("--seeds", nargs="+", default=["0", "1"])
    r.add_argument("--variants", nargs="+", help="run only these variants (default: all, in the study's order)")
    r.add_argument("--recorded", default=str(ROOT / "docs" / "gravity-terms" / "runs.json"),
                   help="the study's record of finished runs (the report writes it): their cases are not run again")
    r.set_defaults(func=cmd_run)
    q = sub.add_parser("report", help="the terms table from the finished runs and the stored replicas")
    q.add_argument("--runs", required=True)
    q.add_argument("--seeds", nargs="+", default=["0", "1"])
    q.add_argument("--out", default=str(ROOT / "docs" / "gravity-terms"))
    q.set_defaults(func=cmd_report)
    args = p.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
