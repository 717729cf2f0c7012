"""How often the steady-state detector is wrong: a campaign of synthetic runs, written to docs/steady-detector.md.

Each synthetic run is built like a smoke run of the testbed (``docs/coupling-trends.md``): the tread turns at
1 rad/s with grousers every 30 deg, samples every 5 ms, the drive is held at t = 1.5 s and the detector is
asked -- as :class:`wheelsoil.coupling.testbed.Testbed` asks it -- first one pitch plus ``average_time`` (1 s)
after the hold and then once per pitch, until it has called the run steady ``steady_checks`` times in a row or
the drive ends at 8 s. Two quantities
are checked together, with the floors and tolerance of the testbed at W = 3000 N:

* a *value*, like the drawbar pull: 900 N settling from 600 N with a 0.4 s time constant;
* a *zero*, like the lateral force of a straight run: 0 N.

Both carry a grouser component (50 N at the pitch frequency) and red noise (AR(1), 50 ms correlation time)
scaled so that their pitch means scatter by SIGMA_VALUE and SIGMA_ZERO: the smoke runs' own scatter (pitch means
of the straight runs at 1g, W = 3000 N: drawbar pull 20--36 N, lateral force 30--44 N, by the mean square
successive difference). Scenarios:

* stationary: nothing drifts after the settling -- every "not steady" verdict by 8 s is a false one; also with
  the value's pitch means scattered by 90 N, as much as the drift allowed (the mini runs' drawbar pull scatters
  by about 4 N against 2 N allowed);
* the value drifts linearly from the hold on, at a rate of 2--20 % of 900 N per second (the detector allows a
  change of 10 % of the mean between the window's first and last pitch centres, 1.05 s apart at 3 pitches);
* the zero trends linearly from the hold on at a given rate [N/s].

The detector runs with its default (``zero_within = 2``: a quantity indistinguishable from zero must not trend
beyond 2 standard errors; ``steady_checks = 2``: two steady verdicts in a row, one pitch apart, end the run;
``truncation_search = 0.5``: MSER looks for the transient's end in the first half of the pitches), with one
check only, and as wheelsoil had it before: MSER searching up to the shortest window (``truncation_search =
1``) with the zero rule and two checks, and the first detector -- that search, the tolerance alone
(``zero_within = 0``: every quantity must hold tolerance x max(|mean|, floor), the floor of a force being 5 %
of W: +-15 N for the zero) and one check.

Usage (from the repository root; a few minutes on 2 CPU cores)::

    python docs/steady_campaign.py [--seeds 200]
"""

import argparse
import math
import time
from pathlib import Path

import numpy as np

from wheelsoil.coupling.steady import confirm_steady, detect_steady_state

ROOT = Path(__file__).resolve().parent
DT = 0.005  # sample interval [s]
OMEGA = 1.0  # tread spin [rad/s]
RADIUS = 0.6  # [m]
PITCH = math.radians(30.0)
T_HOLD, T_END, AVERAGE_TIME = 1.5, 8.0 + 0.56, 1.0  # the drive ends 8 s after the wind-up starts (0.56 s)
LOAD = 3000.0
FLOORS = {"value": 0.05 * LOAD, "zero": 0.05 * LOAD}
TOLERANCE = 0.1
VALUE, VALUE_START, SETTLE = 900.0, 600.0, 0.4
SIGMA_VALUE, SIGMA_ZERO = 30.0, 40.0  # scatter of the pitch means [N]
CORRELATION = 0.05  # AR(1) correlation time [s]
GROUSER = 50.0  # amplitude of the grouser component [N]


def red_noise(rng, n: int, sigma_pitch: float, *, dt: float = DT, pitch_time: float = PITCH / OMEGA,
              correlation: float = CORRELATION) -> np.ndarray:
    """AR(1) noise (correlation time ``correlation`` [s], samples ``dt`` apart) whose means over one pitch
    (``pitch_time`` [s]) scatter by ``sigma_pitch``: with unit variance and lag-one correlation phi, a mean of N
    samples has variance ((1 + phi) / (1 - phi) - 2 phi (1 - phi^N) / (N (1 - phi)^2)) / N."""
    phi = math.exp(-dt / correlation)
    e = rng.normal(0.0, math.sqrt(1.0 - phi * phi), n)
    x = np.empty(n)
    x[0] = rng.normal()
    for k in range(1, n):
        x[k] = phi * x[k - 1] + e[k]
    n_pitch = pitch_time / dt
    var_mean = ((1.0 + phi) / (1.0 - phi) - 2.0 * phi * (1.0 - phi ** n_pitch) / (n_pitch * (1.0 - phi) ** 2)) / n_pitch
    return x * sigma_pitch / math.sqrt(var_mean)


def synthetic_run(seed: int, value_rate: float = 0.0, zero_rate: float = 0.0, value_sigma: float = SIGMA_VALUE):
    """Samples t, the two quantities and the tread angle; value_rate: the value's drift [1/s, fraction of VALUE],
    zero_rate: the zero's trend [N/s]; value_sigma: the scatter of the value's pitch means [N]."""
    rng = np.random.default_rng(seed)
    t = np.arange(1, int(T_END / DT) + 1) * DT
    grouser = GROUSER * np.sin(2 * np.pi * OMEGA * t / PITCH + rng.uniform(0, 2 * np.pi))
    after = np.clip(t - T_HOLD, 0.0, None)
    value = (VALUE + (VALUE_START - VALUE) * np.exp(-t / SETTLE) + grouser + red_noise(rng, t.size, value_sigma)
             + value_rate * VALUE * after)
    zero = grouser * 0.5 + red_noise(rng, t.size, SIGMA_ZERO) + zero_rate * after
    return t, {"value": value, "zero": zero}, OMEGA * t


def first_verdict(t, series, angle, zero_within: float, checks: int, truncation_search: float, *, t_hold: float = T_HOLD,
                  pitch: float = PITCH, omega: float = OMEGA, radius: float = RADIUS, average_time: float = AVERAGE_TIME,
                  floors: dict = FLOORS, dt: float = DT, period_pitches: int = 1, drift_confidence: float = 0.0):
    """Ask the detector as the testbed does, ``checks`` steady verdicts in a row ending the run; the verdict
    that ended it (or the last one at the drive's end). The keywords describe the run (defaults: the smoke run's)."""
    start = t_hold + pitch / omega
    check = start + average_time
    speed = np.full(t.size, (1.0 - 0.3) * radius * omega)
    state, in_a_row = None, 0
    for k in range(t.size):
        if t[k] < check - 1e-12:
            continue
        check = t[k] + pitch / omega
        n = k + 1
        state = detect_steady_state(
            t[:n], {q: y[:n] for q, y in series.items()}, tread_angle=angle[:n], travel_speed=speed[:n],
            radius=radius, pitch=pitch, start=start, min_pitches=int(math.ceil(average_time * omega / pitch)),
            tolerance=TOLERANCE, floors=floors, slip_target=None, slip_tolerance=0.03, sample_interval=dt,
            zero_within=zero_within, truncation_search=truncation_search, period_pitches=period_pitches,
            drift_confidence=drift_confidence)
        state, in_a_row = confirm_steady(state, in_a_row, checks)
        if state.steady:
            break
    return state


#: (name, zero_within, steady_checks, truncation_search): the default, its parts, and the detectors before it.
DETECTORS = [("default: zero within noise, 2 checks, MSER first half", 2.0, 2, 0.5),
             ("zero within noise, 1 check, MSER first half", 2.0, 1, 0.5),
             ("zero within noise, 2 checks, MSER to the end (before)", 2.0, 2, 1.0),
             ("tolerance only, 1 check, MSER to the end (first)", 0.0, 1, 1.0)]

SCENARIOS = [("stationary", {}), ("stationary, value scatter 90 N", {"value_sigma": 90.0}), *[(f"value drifts {100 * r:g} %/s", {"value_rate": r})
                                   for r in (0.02, 0.05, 0.1, 0.2)],
             *[(f"zero trends {r:g} N/s", {"zero_rate": r}) for r in (10.0, 20.0, 40.0, 80.0)]]


def campaign(seeds: int) -> list[dict]:
    rows = []
    for name, kw in SCENARIOS:
        for rule, zero_within, checks, search in DETECTORS:
            steady, stop, err_value, err_zero, cover_value, cover_zero, noise_ratio, zero_flag, pitches = ([] for _ in range(9))
            cover_value_t, cover_zero_t, dof = [], [], []
            for seed in range(seeds):
                t, series, angle = synthetic_run(10_000 + seed, **kw)
                st = first_verdict(t, series, angle, zero_within, checks, search)
                steady.append(st.steady)
                if not st.steady:
                    continue
                stop.append(st.window[1])
                pitches.append(st.pitches)
                k0, k1 = st.k0, st.k1
                # the truth over the window: the noise-free signal's mean
                tt = t[k0:k1]
                after = np.clip(tt - T_HOLD, 0.0, None)
                true_value = np.mean(VALUE + (VALUE_START - VALUE) * np.exp(-tt / SETTLE)
                                     + kw.get("value_rate", 0.0) * VALUE * after)
                true_end = VALUE + kw.get("value_rate", 0.0) * VALUE * (tt[-1] - T_HOLD)
                sv, sz = st.stats["value"], st.stats["zero"]
                err_value.append(abs(sv["mean"] - true_end) / true_end)
                cover_value.append(abs(sv["mean"] - true_value) <= 2 * sv["sem"])
                cover_value_t.append(abs(sv["mean"] - true_value) <= sv["ci95"])
                dof.append(sv["dof"])
                true_zero = np.mean(kw.get("zero_rate", 0.0) * after)
                err_zero.append(abs(sz["mean"] - kw.get("zero_rate", 0.0) * (tt[-1] - T_HOLD)))
                cover_zero.append(abs(sz["mean"] - true_zero) <= 2 * sz["sem"])
                cover_zero_t.append(abs(sz["mean"] - true_zero) <= sz["ci95"])
                noise_ratio.append(sz["noise"] / SIGMA_ZERO)
                zero_flag.append(sz["zero_within_noise"])
            rows.append({"scenario": name, "detector": rule, "seeds": seeds,
                         "steady": float(np.mean(steady)),
                         "stop_median": float(np.median(stop)) if stop else math.nan,
                         "pitches_median": float(np.median(pitches)) if pitches else math.nan,
                         "value_error_p95": float(np.percentile(err_value, 95)) if err_value else math.nan,
                         "zero_error_p95": float(np.percentile(err_zero, 95)) if err_zero else math.nan,
                         "cover_value": float(np.mean(cover_value)) if cover_value else math.nan,
                         "cover_zero": float(np.mean(cover_zero)) if cover_zero else math.nan,
                         "cover_value_t": float(np.mean(cover_value_t)) if cover_value_t else math.nan,
                         "cover_zero_t": float(np.mean(cover_zero_t)) if cover_zero_t else math.nan,
                         "dof_median": float(np.median(dof)) if dof else math.nan,
                         "noise_ratio": float(np.median(noise_ratio)) if noise_ratio else math.nan,
                         "zero_flag": float(np.mean(zero_flag)) if zero_flag else math.nan})
            print(rows[-1], flush=True)
    return rows


def report(rows: list[dict], seeds: int, seconds: float) -> str:
    def pct(x):
        return "–" if math.isnan(x) else f"{100 * x:.0f} %"

    lines = [
        "# How often the steady-state detector is wrong",
        "",
        f"Generated by `python docs/steady_campaign.py --seeds {seeds}` ({seconds / 60:.0f} min); the synthetic runs and the",
        "questions asked are described in the script's docstring: smoke-run timing (30° grousers at 1 rad/s, 5 ms",
        "samples, drive held at 1.5 s, ends at 8 s), a *value* (900 N, settling from 600 N, pitch-mean scatter",
        f"{SIGMA_VALUE:g} N) and a *zero* (0 N, scatter {SIGMA_ZERO:g} N) checked together, tolerance 10 %, floors 150 N.",
        f"Each row: {seeds} seeds (10000 onward).",
        "",
        "Columns: *steady* — runs called steady by the end of the drive (every other run ended \"not steady\");",
        "*stop* — median end of the window the run stopped at [s]; *pitches* — median pitches in that window; *value error p95* — 95th percentile of |reported",
        "value − the value's true level at the window's end| / that level (what a drift the detector lets through",
        "costs, beside the noise); *zero error p95* — the same for the zero, in N; *value/zero covered* — the true mean over the window within ±2 reported",
        "standard errors (95 % if the standard errors were exact); the zero's is inflated by the detector itself, which",
        "calls a zero steady only when its mean lies within 2 standard errors of zero; *t covered* — the same within the",
        "reported 95 % interval (`ci95`: Student's t at the noise estimate's degrees of freedom); *dof* — their median;",
        "*noise ratio* — median estimated pitch-mean scatter of the zero over the true one; *zero flagged* — steady",
        "runs where the zero was judged zero within its noise.",
        "",
        "| scenario | detector | steady | stop [s] | pitches | value error p95 | zero error p95 | value covered | zero covered "
        "| value / zero t covered | dof | noise ratio | zero flagged |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r['scenario']} | {r['detector']} | {pct(r['steady'])} | {r['stop_median']:.2f} | {r['pitches_median']:.0f} | "
                     f"{100 * r['value_error_p95']:.1f} % | {r['zero_error_p95']:.0f} N | {pct(r['cover_value'])} | {pct(r['cover_zero'])} | "
                     f"{pct(r['cover_value_t'])} / {pct(r['cover_zero_t'])} | {r['dof_median']:.1f} | {r['noise_ratio']:.2f} | {pct(r['zero_flag'])} |")
    lines += ["", "These synthetic runs have independent pitch means on one bed. Real runs on other beds (other particle "
              "seeds) spread more than a run's own error bar says: see [replicas.md](replicas.md) for the measured "
              "spread, the factor that widens a single run's interval, and how often the widened interval holds."]
    return "\n".join(lines) + "\n"


def campaign_main(description: str, default_report: Path, run, write) -> None:
    """The command line of a synthetic-run campaign: ``--seeds`` and ``--report``; ``run(seeds)`` gives the rows,
    ``write(rows, seeds, seconds)`` the report's text."""
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--seeds", type=int, default=200)
    p.add_argument("--report", type=Path, default=default_report)
    args = p.parse_args()
    t0 = time.perf_counter()
    rows = run(args.seeds)
    args.report.write_text(write(rows, args.seeds, time.perf_counter() - t0))
    print(f"wrote {args.report}")


def main() -> None:
    campaign_main(__doc__.split("\n")[0], ROOT / "steady-detector.md", campaign, report)


if __name__ == "__main__":
    main()
