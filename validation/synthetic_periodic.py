"""``wheelsoil validate synthetic-periodic``: the periodic-effect chain (:mod:`.oscillation`) on synthetic
drawbar-pull series with a hidden periodic mechanism (:mod:`.synthetic`), with a report that reveals the truth
at its end. A workflow above both modules, so that neither imports the other's caller."""

from dataclasses import replace
from pathlib import Path

import numpy as np

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.provenance import atomic_output, write_markdown_and_json

from . import synthetic as syn
from .oscillation import oscillation_findings


def synthetic_periodic_report(hidden: str | None = None, *, seed: int = 0, report=None, command: str = "") -> dict:
    """``wheelsoil validate synthetic-periodic``: drawbar-pull series with a hidden periodic mechanism drawn at
    random (``hidden``: one of :data:`~wheelsoil.validation.synthetic.HIDDEN_OSCILLATIONS`, ``"none"``, or None
    for a random choice including nothing), run through :func:`oscillation_findings`; report.md (the hidden
    truth revealed at its end), findings.json and amplitudes.png in ``report``."""
    rng = np.random.default_rng(seed)
    names = list(syn.HIDDEN_OSCILLATIONS) + [None]
    if hidden is None:
        hidden = names[int(rng.integers(len(names)))]
    elif hidden == "none":
        hidden = None
    elif hidden not in syn.HIDDEN_OSCILLATIONS:
        raise WheelsoilInputError(f"--hidden {hidden!r}: choose 'none' or one of {sorted(syn.HIDDEN_OSCILLATIONS)}")
    params = {k: float(rng.uniform(*b)) for k, b in syn.HIDDEN_OSCILLATIONS.get(hidden, {}).items()}
    records = syn.synthetic_oscillation_series(hidden, params, rng)
    # the steady model as calibrated on the runs' means (here: the truth the series were made from)
    soil = replace(syn.TRUE_SOIL, radius_scale=1.5) if hidden == "spoke_radius" else syn.TRUE_SOIL
    found = oscillation_findings(records, soil, syn.SMOOTH_WHEEL, spokes=syn.SYNTHETIC_SPOKES)
    comps = found["components"]
    rows = [{"slip": r.slip, "load_N": r.load, "omega_rad_s": r.omega, "frequency_hz": c.frequency,
             "amplitude_N": c.amplitude, "p_value": c.p_value, "ar1": c.ar1, "significant": c.significant}
            for r, c in zip(records, comps)]
    out = {"data": "synthetic-periodic", "seed": seed, "runs": rows, "frequency_law": found["frequency"],
           "amplitude": found["amplitude"], "found": found["found"],
           "hidden": {"name": hidden, "parameters": params}}
    if report is None:
        return out
    report = Path(report)
    report.mkdir(parents=True, exist_ok=True)
    lines = ["# Periodic effects in synthetic drawbar-pull series (the hidden mechanism is revealed at the end)", ""]
    if command:
        lines += [f"Reproduce: `{command}`", ""]
    lines += [f"{len(records)} runs of a smooth wheel (r = {syn.SMOOTH_WHEEL.radius} m, b = {syn.SMOOTH_WHEEL.width} m, "
              f"{syn.SYNTHETIC_SPOKES} stiffness peaks per turn), slips {sorted({r.slip for r in records})} at loads "
              f"{sorted({r.load for r in records})} N; each series is checked for its dominant oscillation against "
              "red (AR(1)) noise, the frequencies are compared with the frequency laws, and the amplitudes with "
              "the amplitude mechanisms (held out one load at a time).", "",
              "| slip | load [N] | omega [rad/s] | f [Hz] | amplitude [N] | p | significant |", "|---|---|---|---|---|---|---|"]
    lines += [f"| {r['slip']:g} | {r['load_N']:g} | {r['omega_rad_s']:g} | {r['frequency_hz']:.2f} | "
              f"{r['amplitude_N']:.3g} | {r['p_value']:.1e} | {'yes' if r['significant'] else 'no'} |" for r in rows]
    law = found["frequency"]
    lines += ["", "## Frequency law", ""]
    if law["laws"]:
        lines += ["| law | rms relative error | BIC | parameters |", "|---|---|---|---|"]
        lines += [f"| {k} | {v['rms_relative_error']:.3f} | {v['bic']:.1f} | "
                  + ", ".join(f"{p} = {x:.3g}" for p, x in v["parameters"].items()) + " |" for k, v in law["laws"].items()]
    lines += ([""] if law["laws"] else []) + [f"Found: **{law['found']}**." if law["found"] else
                                              f"No law found ({law['significant_runs']} significant runs)"
                                              + (f": {law['note']}." if "note" in law else ".")]
    if "confound" in law:
        lines += ["", f"Confound: {law['confound']}."]
    if "unexplained" in law:
        lines += ["", f"Unexplained: {law['unexplained']}."]
    amp = found["amplitude"]
    lines += ["", "## Amplitude mechanism", ""]
    if amp is None:
        lines += ["Not examined: no frequency law with an amplitude mechanism was found."]
    else:
        lines += ["| model | parameter | value | rms log error | BIC | held-out rms log error | gain vs constant |",
                  "|---|---|---|---|---|---|---|"]
        for k, v in amp["models"].items():
            gain = f"{v['gain']:+.3f} ± {v['gain_se']:.3f}" if "gain" in v else "–"
            lines.append(f"| {k} | {v['parameter']} | {v['value']:.4g} | {v['rms_log_error']:.3f} | {v['bic']:.1f} | "
                         f"{v['held_out_rms_log_error']:.3f} | {gain} |")
        lines += ["", f"Found: **{amp['found']}**." if amp["found"] else "No mechanism earns its parameter."]
        _amplitude_plot(amp, report / "amplitudes.png")
        lines += ["", "![amplitudes](amplitudes.png)"]
    lines += ["", "## The hidden truth", "", f"Hidden: {hidden or 'nothing'} {params or ''}"]
    out["report"] = str(write_markdown_and_json(report / "report.md", "\n".join(lines) + "\n",
                                                report / "findings.json", out))
    return out


def _amplitude_plot(amp: dict, path) -> None:
    """Fitted against measured amplitudes, one series per model (from :func:`explain_amplitudes`)."""
    from wheelsoil.plotting import pyplot

    plt = pyplot()

    measured = np.asarray(amp["measured"], float)
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    for k, v in amp["models"].items():
        ax.loglog(measured, v["predicted"], "o", label=f"{k} ({v['parameter']} = {v['value']:.3g})")
    lim = [measured.min() / 1.5, measured.max() * 1.5]
    ax.plot(lim, lim, "k--", lw=1)
    ax.set_xlabel(f"measured {amp['quantity']} amplitude [N]")
    ax.set_ylabel("model amplitude [N]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
