"""Plots of runs and sweeps (matplotlib, Agg backend: no display needed)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from wheelsoil.gravity import gravity_label
from wheelsoil.plotting import pyplot


def plot_series(result, path: str | Path, title: str) -> Path:
    """Forces, torque, sinkage and the slip the tread saw (with the wheel's wind-up) against time, the
    averaging window shaded.

    ``result``: a :class:`~wheelsoil.coupling.testbed_result.TestbedResult` or :class:`~wheelsoil.cases.results.Result`
    (anything with ``series`` and ``summary``; the load line is drawn from the ``load`` series).
    """
    from wheelsoil.provenance import atomic_output

    plt = pyplot()
    s, t = result.series, result.series["t"]
    fig, axes = plt.subplots(4, 1, figsize=(7, 9), sharex=True)
    for name in ("drawbar_pull", "lateral_force", "vertical_force"):
        axes[0].plot(t, s[name], label=name.replace("_", " "))
    load = float(np.max(s["load"])) if len(s["load"]) else 0.0
    if load > 0:
        axes[0].axhline(load, color="0.5", ls="--", lw=0.8, label="load W")
    axes[0].set_ylabel("force on the wheel [N]")
    axes[1].plot(t, s["torque"], color="C3")
    axes[1].set_ylabel("driving torque [N m]")
    axes[2].plot(t, 1e3 * s["sinkage"], color="C4", label="hub (with deflection)")
    axes[2].plot(t, 1e3 * s["tread_sinkage"], color="C5", label="tread")
    axes[2].set_ylabel("sinkage [mm]")
    axes[2].legend(fontsize=8)
    if "tread_slip" in s:
        axes[3].plot(t, s["slip"], color="0.4", ls="--", label="commanded (hub)")
        axes[3].plot(t, s["tread_slip"], color="C0", lw=0.8, label="seen by the tread")
        axes[3].set_ylim(-0.2, 1.0)
        axes[3].set_ylabel("slip i")
        twin = axes[3].twinx()
        twin.plot(t, np.degrees(s["wind_up"]), color="C1", lw=0.8, label="wind-up")
        twin.set_ylabel("wind-up [deg]", color="C1")
        axes[3].legend(fontsize=8, loc="upper left")
    axes[3].set_xlabel("time [s]")
    t0, t1 = result.summary.window
    for ax in axes:
        ax.axvspan(t0, t1, color="0.9", zorder=0)
    axes[0].legend(fontsize=8, ncol=2)
    axes[0].set_title(f"{title} (shaded: averaging window)")
    fig.tight_layout()
    path = Path(path)
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
    return path


#: Sweep figures (seed 004 Figs. 6--8): summary column, axis label, scale to the plotted unit.
SWEEP_FIGURES = {
    "sinkage": ("tread_sinkage", "tread sinkage [mm]", 1e3),
    "drawbar_pull": ("drawbar_pull", "drawbar pull [N]", 1.0),
    "lateral_force": ("lateral_force", "lateral force [N]", 1.0),
}


def plot_sweep(table, out: str | Path, title: str) -> list[Path]:
    """One figure per quantity against slip: a panel per steering angle, a line per gravity, load and wheel
    (flexible or rigid) (seed 004 Figs. 6--8), error bars one standard deviation of the steady window.
    Returns the paths."""
    from wheelsoil.provenance import atomic_output

    plt = pyplot()
    out = Path(out)
    angles = sorted(table["slip_angle_set"].unique())
    groups = sorted({(g, w, bool(r)) for g, w, r in zip(table["gravity"], table["load_set"], table["rigid"])},
                    key=lambda gwr: (-gwr[0], -gwr[1], gwr[2]))
    written = []
    for fig_name, (column, label, scale) in SWEEP_FIGURES.items():
        fig, axes = plt.subplots(1, len(angles), figsize=(3.4 * len(angles) + 0.6, 3.4), sharey=True, squeeze=False)
        for ax, beta in zip(axes[0], angles):
            for k, (g, w, rigid) in enumerate(groups):
                sel = table[(table["slip_angle_set"] == beta) & (table["gravity"] == g) & (table["load_set"] == w)
                            & (table["rigid"].astype(bool) == rigid)]
                sel = sel.sort_values("slip_set")
                if sel.empty:
                    continue
                gname = gravity_label(g)
                ax.errorbar(sel["slip_set"], scale * sel[f"{column}_mean"], yerr=scale * sel[f"{column}_std"],
                            marker="os^vD"[k % 5], capsize=2,
                            label=f"{gname}, W = {w:g} N{', rigid wheel' if rigid else ''}")
            ax.set_title(f"β = {beta:g}°")
            ax.set_xlabel("slip i")
            ax.grid(alpha=0.3)
        axes[0][0].set_ylabel(label)
        axes[0][-1].legend(fontsize=7)
        fig.suptitle(f"{title}: {label.split(' [')[0]} against slip")
        fig.tight_layout()
        path = out / f"figure_{fig_name}.png"
        with atomic_output(path) as tmp:
            fig.savefig(tmp, format="png", dpi=110)
        plt.close(fig)
        written.append(path)
    return written
