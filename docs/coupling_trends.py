"""Trends of the coupled wheel--soil runs at smoke scale (issue 4), written to docs/coupling-trends.md.

Runs the smoke testbed (lunar-rover wheel r = 0.6 m, b = 0.5 m, coarse mesh; 2.0 x 0.9 x 0.2 m bed of
25--37.5 mm particles) at the conditions below, each with ``wheelsoil testbed`` in its own process, then
plots what seed 004 (and seed 001 for the rigid wheel) report:

* drawbar pull and sinkage against slip (straight driving, 1g, W = 3000 N);
* drawbar pull and lateral force against steering angle (slip 0.3);
* 1g with W = 3000 N against 1/6 g with W = 500 N (equal wheel mass): differences in sinkage, drawbar pull
  and lateral force beside seed 004's 12.35 %, 76.60 % and 83.23 %;
* flexible against rigid wheel of the same surface: the drawbar-pull ratio (seed 001: about 2x).

Every run uses the testbed's protocol: wind-up, then drive until the steady state is detected (up to
``DRIVE_TIME``, 8 s; the rigid wheel 16 s), averaged over whole pitches of the tread; the report gives the tread slip
each run saw and says which runs were not steady (their numbers are shown but not read as trends).

Usage (from the repository root; about 40 minutes on 2 CPU cores, finished runs are reused)::

    python docs/coupling_trends.py                 # run what is missing, write figures and the report
    python docs/coupling_trends.py --report-only   # rebuild figures and report from finished runs

Runs go to ``wheelsoil-output/trends/<run>/`` (series.csv, summary.json, series.png).
"""

import argparse
import csv
import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
from steady_replay import replay  # docs/steady_replay.py, beside this script

ROOT = Path(__file__).resolve().parent
#: Seed 004 abstract: mean differences between 1g/W = 3000 N and 1/6 g/W = 500 N.
SEED004_GRAVITY_DIFFERENCE = {"sinkage": 12.35, "drawbar_pull": 76.60, "lateral_force": 83.23}

#: name -> (preset, overrides); every run at angular velocity 1 rad/s (r omega = 0.6 m/s).
RUNS = {
    "1g-W3000-i0.1-b0": ("smoke-1g-steer", {"slip": 0.1, "slip_angle": 0.0}),
    "1g-W3000-i0.3-b0": ("smoke-1g-steer", {"slip": 0.3, "slip_angle": 0.0}),
    "1g-W3000-i0.5-b0": ("smoke-1g-steer", {"slip": 0.5, "slip_angle": 0.0}),
    "1g-W3000-i0.3-b10": ("smoke-1g-steer", {"slip": 0.3, "slip_angle": 10.0}),
    "1g-W3000-i0.3-b20": ("smoke-1g-steer", {"slip": 0.3, "slip_angle": 20.0}),
    "moon-W500-i0.3-b10": ("smoke-moon-steer", {"slip": 0.3, "slip_angle": 10.0}),
    "1g-W3000-i0.3-b0-rigid": ("smoke-1g-steer", {"slip": 0.3, "slip_angle": 0.0, "rigid": True,
                                                  "drive_time": 16.0}),
}
QUANTITIES = ("drawbar_pull", "lateral_force", "vertical_force", "torque", "sinkage", "tread_sinkage")


#: Longest drive of every run [s] (``test.drive_time``) unless its overrides name one; a run stops earlier once
#: it is steady. At the presets' 4 s, four of the seven runs ended "within its own noise: a longer window would
#: tell" (2026-11-24). The rigid wheel's drawbar pull scatters by about 12 % of its mean from pitch to pitch (63 N
#: on 500 N), so over 15 pitches its drift's standard error (+-53 N) is as large as the 10 % allowance: it gets 16 s.
DRIVE_TIME = 8.0


def run_case(name: str, preset: str, overrides: dict, runs: Path) -> Path:
    """Run one case with the command line unless a finished run with the same settings exists.

    A finished run that was steady is reused whatever drive it was allowed, as long as that was no longer than
    its own (``overrides["drive_time"]``, else :data:`DRIVE_TIME`): it stopped when it became steady, and a
    longer allowance takes it through the same steps to the same stop (the runs are deterministic). A run is
    reused only if the installed detector, asked again about its stored series (``steady_replay.py``), gives the
    same verdict over the same window: a run that a changed detector would have stopped elsewhere is run again."""
    out = runs / name
    drive = overrides.get("drive_time", DRIVE_TIME)
    summary = out / "summary.json"
    if summary.exists():
        meta = json.loads(summary.read_text())
        tb = meta["testbed"]
        wanted = dict(overrides, stop_when_steady=True)
        wanted.pop("drive_time", None)
        same = all(tb.get(k) == v for k, v in wanted.items())
        if same and (tb.get("drive_time") == drive or (meta["summary"]["steady"] and tb["drive_time"] <= drive)):
            state, _, _ = replay(out)
            stored = meta["summary"]
            if state.steady == stored["steady"] and np.allclose(state.window, stored["window"], atol=1e-9):
                print(f"[{name}] reusing {summary} (the detector, asked again, gives the same window)")
                return out
            print(f"[{name}] the detector now gives another verdict or window on the stored series: running again")
    cmd = [sys.executable, "-m", "wheelsoil.cases.cli", "run", preset, "--slip", str(overrides["slip"]),
           "--slip-angle", str(overrides["slip_angle"]), "--set", f"test.drive_time={drive!r}", "--out", str(out)]
    if overrides.get("rigid"):
        cmd.append("--rigid")
    print(f"[{name}] {' '.join(cmd[1:])}", flush=True)
    subprocess.run(cmd, check=True)
    return out


def load_run(path: Path) -> dict:
    """The run's steady means, fluctuations and standard errors (batch means over whole pitches of the tread,
    as the run's own summary gives them), its tread slip and verdict."""
    meta = json.loads((path / "summary.json").read_text())
    s = meta["summary"]
    out = {"meta": meta, "path": path, "window": tuple(s["window"]), "steady": bool(s["steady"]), "reasons": s.get("reasons", []),
           "tread_slip": (float(s["tread_slip"]["mean"]), float(s["tread_slip"].get("sem", math.nan)))}
    for q in QUANTITIES:
        out[q] = (float(s[q]["mean"]), float(s[q]["std"]), float(s[q]["sem"]))
    out["zero_within_noise"] = [q for q in QUANTITIES if s[q].get("zero_within_noise")]
    m = re.search(r"packing fraction ([0-9.]+)", meta.get("bed", ""))
    out["packing_fraction"] = float(m.group(1)) if m else math.nan
    return out


def difference(a: float, b: float) -> float:
    """Relative change of the magnitude, (|b| - |a|) / |a| in per cent (a the 1g value)."""
    return 100.0 * (abs(b) - abs(a)) / abs(a)


def make_figures(res: dict, figures: Path) -> dict:
    from wheelsoil.plotting import pyplot

    plt = pyplot()

    figures.mkdir(parents=True, exist_ok=True)
    found = {}

    def errbar(ax, x, names, q, scale=1.0, **kw):
        m = [scale * res[n][q][0] for n in names]
        e = [abs(scale) * res[n][q][2] for n in names]
        ax.errorbar(x, m, yerr=e, marker="o", capsize=3, **kw)
        return m

    slips = ["1g-W3000-i0.1-b0", "1g-W3000-i0.3-b0", "1g-W3000-i0.5-b0"]
    if all(n in res for n in slips):
        x = [res[n]["meta"]["testbed"]["slip"] for n in slips]
        fig, (a0, a1) = plt.subplots(1, 2, figsize=(9, 3.6))
        dp = errbar(a0, x, slips, "drawbar_pull", color="C0")
        a0.set_xlabel("slip i")
        a0.set_ylabel("drawbar pull [N]")
        a0.axhline(0, color="0.6", lw=0.7)
        errbar(a1, x, slips, "sinkage", scale=1e3, color="C4", label="hub (with the wheel's deflection)")
        errbar(a1, x, slips, "tread_sinkage", scale=1e3, color="C5", label="tread")
        a1.legend(fontsize=8)
        a1.set_xlabel("slip i")
        a1.set_ylabel("sinkage [mm]")
        fig.suptitle("Straight driving, 1g, W = 3000 N (smoke scale)")
        fig.tight_layout()
        fig.savefig(figures / "dp_vs_slip.png", dpi=110)
        plt.close(fig)
        found["dp_vs_slip"] = dict(zip(x, dp))

    betas = ["1g-W3000-i0.3-b0", "1g-W3000-i0.3-b10", "1g-W3000-i0.3-b20"]
    if all(n in res for n in betas):
        x = [res[n]["meta"]["testbed"]["slip_angle"] for n in betas]
        fig, ax = plt.subplots(figsize=(5.5, 3.8))
        dp = errbar(ax, x, betas, "drawbar_pull", color="C0", label="drawbar pull")
        fy = errbar(ax, x, betas, "lateral_force", scale=-1.0, color="C1", label="lateral force (-F_y)")
        ax.set_xlabel("steering angle beta [deg]")
        ax.set_ylabel("force on the wheel [N]")
        ax.axhline(0, color="0.6", lw=0.7)
        ax.legend()
        ax.set_title("Slip 0.3, 1g, W = 3000 N (smoke scale)")
        fig.tight_layout()
        fig.savefig(figures / "dp_fy_vs_steering.png", dpi=110)
        plt.close(fig)
        found["dp_vs_beta"] = dict(zip(x, dp))
        found["minus_fy_vs_beta"] = dict(zip(x, fy))

    pair = ["1g-W3000-i0.3-b10", "moon-W500-i0.3-b10"]
    if all(n in res for n in pair):
        qs = ("sinkage", "tread_sinkage", "drawbar_pull", "lateral_force")
        ours = {q: difference(res[pair[0]][q][0], res[pair[1]][q][0]) for q in qs}
        seed = dict(SEED004_GRAVITY_DIFFERENCE, tread_sinkage=SEED004_GRAVITY_DIFFERENCE["sinkage"])
        fig, ax = plt.subplots(figsize=(7, 3.8))
        xs = np.arange(len(qs))
        ax.bar(xs - 0.2, [abs(ours[q]) for q in qs], 0.4, label="wheelsoil (smoke scale, i 0.3, beta 10 deg)")
        ax.bar(xs + 0.2, [seed[q] for q in qs], 0.4, label="seed 004 (mean over conditions; one sinkage figure)")
        ax.set_xticks(xs, ["sinkage (hub)", "tread sinkage", "drawbar pull", "lateral force"])
        ax.set_ylabel("|difference| 1g/3000 N vs 1/6 g/500 N [%]")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(figures / "gravity_difference.png", dpi=110)
        plt.close(fig)
        found["gravity_difference_percent"] = ours

    flex = ["1g-W3000-i0.3-b0", "1g-W3000-i0.3-b0-rigid"]
    if all(n in res for n in flex):
        f, r = (res[n]["drawbar_pull"] for n in flex)
        ratio = f[0] / r[0]
        ratio_err = abs(ratio) * np.hypot(f[2] / f[0], r[2] / r[0])
        fig, ax = plt.subplots(figsize=(4.5, 3.6))
        ax.bar([0, 1], [f[0], r[0]], yerr=[f[2], r[2]], capsize=4, color=["C0", "C7"])
        ax.set_xticks([0, 1], ["flexible", "rigid"])
        ax.set_ylabel("drawbar pull [N]")
        ax.set_title(f"i 0.3, beta 0, 1g, W 3000 N: ratio {ratio:.2f}")
        fig.tight_layout()
        fig.savefig(figures / "flexible_vs_rigid.png", dpi=110)
        plt.close(fig)
        found["flexible_over_rigid_dp"] = (float(ratio), float(ratio_err))
    return found


#: Column of each reported quantity in a run's series.csv.
SERIES_COLUMNS = {"drawbar_pull": "drawbar_pull[N]", "lateral_force": "lateral_force[N]", "torque": "torque[N m]"}


def second_means(path: Path, quantity: str, start: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """Means of ``quantity`` over consecutive whole seconds of the run from ``start`` [s] (series.csv)."""
    with open(path / "series.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["t[s]"]) for r in rows])
    y = np.array([float(r[SERIES_COLUMNS[quantity]]) for r in rows])
    edges = np.arange(start, math.floor(t[-1]) + 1e-9, 1.0)
    lows = edges[:-1]
    means = np.array([y[(t >= lo) & (t < lo + 1.0)].mean() for lo in lows])
    return lows, means


def wander(res: dict) -> list[str]:
    """For every run that is not steady: the failing quantities' means over whole seconds from 2 s on, and
    whether they trend with time (Spearman's rank correlation) or wander without a trend."""
    from scipy.stats import spearmanr

    out = []
    for name, r in res.items():
        if r["steady"]:
            continue
        failing = [q for q in SERIES_COLUMNS if any(reason.startswith(q) for reason in r["reasons"])]
        for q in failing:
            lows, means = second_means(r["path"], q)
            if len(means) < 4:
                continue
            rho, p = spearmanr(lows, means)
            out.append(f"* {name}, {q.replace('_', ' ')} over whole seconds from 2 s: "
                       + ", ".join(f"{m:.0f}" for m in means)
                       + f" N{' m' if q == 'torque' else ''} (range {means.max() - means.min():.0f}; "
                       f"rank correlation with time {rho:+.2f}, p = {p:.2f})")
    if not out:
        return []
    return ["What the runs that are not steady do over their whole drive (1-s means; a trend would show as a rank",
            "correlation near ±1 with a small p):", ""] + out + [
        "",
        "Where the correlation is weak these quantities wander rather than drift, by more than the detector's",
        "allowance (10 % of the mean) within a window; more driving does not remove such a wander.",
        ""]


def write_report(res: dict, found: dict, path: Path) -> None:
    lines = [
        "# Coupled wheel–soil trends at smoke scale",
        "",
        "Generated by `python docs/coupling_trends.py` (every number and figure below comes from the runs it",
        "makes). Each run winds the wheel up, then drives until its steady state is detected (up to "
        f"{DRIVE_TIME:g} s, the rigid wheel {RUNS['1g-W3000-i0.3-b0-rigid'][1]['drive_time']:g} s;",
        "`test.drive_time`) and averages over whole pitches of the tread (`coupling/steady.py`). Smoke scale: the",
        "seed-004 lunar-rover wheel (r = 0.6 m, b = 0.5 m, 188 kg) on a coarse mesh (3,456 elements) and a",
        "2.0 × 0.9 × 0.2 m periodic bed (moving soil patch) of 25–37.5 mm particles (≈ 12,000), ω = 1 rad/s.",
        "Particles are about 1.5× seed 004's and the bed shallower; how far the forces move under refinement is",
        "measured in [testbed-numbers.md](testbed-numbers.md) (convergence study). Means ± standard errors from",
        "the pitch means; the tread slip is the slip the tread saw (commanded: the run's name). Wall: each",
        "run's own wall time, measured while other runs shared the two cores (not a speed figure).",
        "",
        "Sinkage is the hub's drop below where the undeformed tread touches the surface, so it includes the",
        "wheel's deflection; tread sinkage is the depth of the lowest point of the tread below the surface.",
        "",
        "| run | steady | window [s] | tread slip | DP [N] | F_y [N] | F_z [N] | torque [N m] | sinkage [mm] "
        "| tread sinkage [mm] | wall [s] |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, r in res.items():
        cells = [f"{r[q][0]:.0f} ± {r[q][2]:.0f}{' (0)' if q in r['zero_within_noise'] else ''}"
                 for q in QUANTITIES[:4]]
        cells += [f"{1e3 * r[q][0]:.1f} ± {1e3 * r[q][2]:.1f}" for q in ("sinkage", "tread_sinkage")]
        lines.append(f"| {name} | {'yes' if r['steady'] else '**no**'} | {r['window'][0]:.2f}–{r['window'][1]:.2f} | "
                     f"{r['tread_slip'][0]:.3f} | " + " | ".join(cells) + f" | {r['meta']['run']['wall_seconds']:.0f} |")
    lines += ["", "(0): zero within its noise (|mean| < 2 standard errors): judged steady by not trending beyond 2 "
              "standard errors instead of by the tolerance (`coupling/steady.py`; how often that is wrong: "
              "[steady-detector.md](steady-detector.md)).", ""]
    for name, r in res.items():
        if not r["steady"]:
            lines.append(f"* {name} is **not steady**: {'; '.join(r['reasons'])}.")
    lines.append("")
    lines += wander(res)
    if "dp_vs_slip" in found:
        lines += ["## Drawbar pull rises with slip", "", "![](figures/dp_vs_slip.png)", "",
                  "DP at slip " + ", ".join(f"{k:g}: {v:.0f} N" for k, v in found["dp_vs_slip"].items()) + ".", ""]
    if "dp_vs_beta" in found:
        lines += ["## Steering: drawbar pull falls, lateral force rises", "", "![](figures/dp_fy_vs_steering.png)",
                  "", "DP at β " + ", ".join(f"{k:g}°: {v:.0f} N" for k, v in found["dp_vs_beta"].items())
                  + "; −F_y " + ", ".join(f"{k:g}°: {v:.0f} N" for k, v in found["minus_fy_vs_beta"].items()) + ".",
                  ""]
    if "gravity_difference_percent" in found:
        d = found["gravity_difference_percent"]
        lines += ["## Equal wheel mass at 1g and 1/6 g", "", "![](figures/gravity_difference.png)", "",
                  "Change at 1/6 g with W = 500 N relative to 1g with W = 3000 N (seed 004 gives the magnitude of",
                  "the difference, averaged over slips and steering angles):", "",
                  "| quantity | wheelsoil (i 0.3, β 10°) | seed 004 (mean magnitude) |", "|---|---|---|"]
        lines += [f"| {q.replace('_', ' ')} | {d[q]:+.1f} % | "
                  f"{SEED004_GRAVITY_DIFFERENCE.get(q, SEED004_GRAVITY_DIFFERENCE['sinkage']):.2f} % |" for q in d]
        lines.append("")
    if "flexible_over_rigid_dp" in found:
        ratio, err = found["flexible_over_rigid_dp"]
        lines += ["## Flexible against rigid wheel", "", "![](figures/flexible_vs_rigid.png)", "",
                  f"Drawbar-pull ratio flexible/rigid at i 0.3, β 0°: {ratio:.2f} ± {err:.2f} (seed 001: about 2).",
                  ""]
    lines += reading(res, found)
    path.write_text("\n".join(lines))
    (path.with_suffix(".json")).write_text(json.dumps(
        {"protocol": "drive until steady", "found": {k: ({str(a): b for a, b in v.items()} if isinstance(v, dict) else v)
                                             for k, v in found.items()},
         "runs": {n: {q: r[q] for q in QUANTITIES} | {"steady": r["steady"], "window": r["window"],
                                                     "tread_slip": r["tread_slip"],
                                                     "wall_seconds": r["meta"]["run"]["wall_seconds"]}
                  for n, r in res.items()}}, indent=1))


def reading(res: dict, found: dict) -> list[str]:
    """What the figures show beside the papers, with the numbers of these runs."""
    out = ["## Reading", ""]
    unsteady = [n for n, r in res.items() if not r["steady"]]
    if unsteady:
        out += [f"* Runs without a detected steady state ({', '.join(unsteady)}) are shown over their last window; "
                "a reading below that rests on one says so and is indicative only (reasons under the table).", ""]

    def caveat(names) -> str:
        bad = [n for n in names if n in res and not res[n]["steady"]]
        return f" *Indicative only: {', '.join(bad)} not steady.*" if bad else ""

    off = [n for n, r in res.items() if abs(r["tread_slip"][0] - r["meta"]["testbed"]["slip"]) > 0.03]
    if off:
        out += [f"* The tread slip of {', '.join(off)} differs from the commanded slip by more than 0.03.", ""]
    if "dp_vs_slip" in found:
        dp = list(found["dp_vs_slip"].values())
        ts = [1e3 * res[n]["tread_sinkage"][0] for n in ("1g-W3000-i0.1-b0", "1g-W3000-i0.3-b0", "1g-W3000-i0.5-b0")]
        out += [f"* **Slip.** Drawbar pull rises monotonically ({dp[0]:.0f} → {dp[-1]:.0f} N from i = 0.1 to 0.5) and "
                f"the tread sinks deeper ({ts[0]:.1f} → {ts[-1]:.1f} mm), as in seed 004 (Figs. 6–7)."
                + caveat(("1g-W3000-i0.1-b0", "1g-W3000-i0.3-b0", "1g-W3000-i0.5-b0")), ""]
    if "dp_vs_beta" in found:
        dp = list(found["dp_vs_beta"].values())
        fy = list(found["minus_fy_vs_beta"].values())
        straight = res["1g-W3000-i0.3-b0"]
        fy0 = (f"zero within its noise ({straight['lateral_force'][0]:+.0f} ± {straight['lateral_force'][2]:.0f} N)"
               if "lateral_force" in straight["zero_within_noise"] else f"{fy[0]:.0f}")
        out += [f"* **Steering.** From β = 0 to 20° drawbar pull falls by {100 * (1 - dp[-1] / dp[0]):.0f} % and the "
                f"lateral force grows from {fy0} to {fy[-1]:.0f} N (seed 004 at 1g, 3000 N: drawbar pull "
                "−36.9 % on average from 5 to 20°, lateral force +301 %)."
                + caveat(("1g-W3000-i0.3-b0", "1g-W3000-i0.3-b10", "1g-W3000-i0.3-b20")), ""]
    if "gravity_difference_percent" in found:
        d = found["gravity_difference_percent"]
        g1, gm = res["1g-W3000-i0.3-b10"], res["moon-W500-i0.3-b10"]
        defl = [1e3 * (r["sinkage"][0] - r["tread_sinkage"][0]) for r in (g1, gm)]
        out += [f"* **Gravity at equal wheel mass.** Drawbar pull ({d['drawbar_pull']:+.0f} %) and lateral force "
                f"({d['lateral_force']:+.0f} %) drop as strongly as seed 004 reports (76.6 %, 83.2 %). The tread "
                f"sinkage changes by {d['tread_sinkage']:+.0f} %, close to seed 004's 12 % (its largest differences "
                f"reach 25 %). The hub's drop ({d['sinkage']:+.0f} %) is dominated by the wheel's own deflection, "
                f"{defl[0]:.0f} mm under 3000 N against {defl[1]:.0f} mm under 500 N. Seed 004 does not say which it "
                "measures." + caveat(("1g-W3000-i0.3-b10", "moon-W500-i0.3-b10")), ""]
    if "flexible_over_rigid_dp" in found:
        ratio, err = found["flexible_over_rigid_dp"]
        f, r = res["1g-W3000-i0.3-b0"], res["1g-W3000-i0.3-b0-rigid"]
        out += [f"* **Flexible against rigid.** The flexible wheel pulls {ratio:.2f} ± {err:.2f} times the rigid one "
                f"(seed 001: about 2×) at tread slips {f['tread_slip'][0]:.3f} and {r['tread_slip'][0]:.3f}, so the "
                f"comparison is at the slip both treads saw; its tread sinks {1e3 * f['tread_sinkage'][0]:.0f} mm "
                f"against the rigid wheel's {1e3 * r['tread_sinkage'][0]:.0f} mm. Seed 001's factor is for loosely "
                "packed soil modelled as a continuum (Drucker–Prager cap), where the rigid wheel's extra sinkage costs "
                f"compaction resistance. Here the bed is dense (packing fraction {f['packing_fraction']:.2f}) and "
                "coarse: a 25–37.5 mm particle is as large as the grousers."
                + caveat(("1g-W3000-i0.3-b0", "1g-W3000-i0.3-b0-rigid")), ""]
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", type=Path, default=Path("wheelsoil-output/trends"), help="run folder")
    p.add_argument("--only", nargs="*", default=None, help="run only these names")
    p.add_argument("--report-only", action="store_true", help="do not run; report what is finished")
    p.add_argument("--report", type=Path, default=ROOT / "coupling-trends.md",
                   help="report file (default docs/coupling-trends.md; figures in its folder's figures/)")
    args = p.parse_args(argv)
    names = args.only or list(RUNS)
    unknown = sorted(set(names) - set(RUNS))
    if unknown:
        p.error(f"unknown runs {unknown}; choose from {list(RUNS)}")
    if not args.report_only:
        for name in names:
            preset, overrides = RUNS[name]
            run_case(name, preset, overrides, args.runs)
    res = {n: load_run(args.runs / n) for n in RUNS if (args.runs / n / "summary.json").exists()}
    found = make_figures(res, args.report.parent / "figures")
    write_report(res, found, args.report)
    print(json.dumps(found, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
