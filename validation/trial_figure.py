"""One figure of single-wheel trials against models: drawbar pull and lateral force over slip, a panel per steering
angle, the measured points with their error bars, each model a line (or, for runs at some trials only, points)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .measured import Measurements

RESPONSES = ("drawbar_pull", "lateral_force")
#: Line styles of the models, in the order they are given.
STYLES = ("-", ":", "--", "-.")


@dataclass
class ModelPoints:
    """A model's values at some rows of the data only (e.g. the DEM--FEM runs): ``rows`` index the data;
    ``responses`` and ``std`` hold one value per row of ``rows``."""

    rows: np.ndarray
    responses: dict
    std: dict = field(default_factory=dict)


def plot_trials(data: Measurements, lines: dict[str, dict], path: str | Path, *,
                points: dict[str, ModelPoints] | None = None,
                responses=RESPONSES) -> Path:
    """Write the figure to ``path``: ``lines`` maps a model's name to its predictions over every row (response ->
    array), ``points`` a model's name to its :class:`ModelPoints`. Slip on the x axis is the rig's (against the
    travel speed), wheels by colour (the data's groups)."""
    from wheelsoil.plotting import pyplot

    plt = pyplot()
    slip = data.travel_slip if data.travel_slip is not None else data.slip
    angles = np.unique(data.slip_angle)
    fig, axes = plt.subplots(len(responses), len(angles), figsize=(2.6 * len(angles), 2.8 * len(responses)),
                             sharey="row", squeeze=False)
    for col, beta in enumerate(angles):
        for row, q in enumerate(responses):
            ax = axes[row, col]
            for w, wheel in enumerate(np.unique(data.group)):
                colour = f"C{w}"
                m = (data.slip_angle == beta) & (data.group == wheel)
                if not m.any():
                    continue
                order = np.argsort(slip[m])
                s = slip[m][order]
                std = data.std.get(q, np.zeros(len(data)))
                ax.errorbar(s, data.responses[q][m][order], yerr=std[m][order], fmt="o", ms=3, color=colour,
                            capsize=1.5, label=f"{wheel}, measured")
                for k, (name, pred) in enumerate(lines.items()):
                    ax.plot(s, pred[q][m][order], STYLES[k % len(STYLES)], color=colour, lw=1.2,
                            label=f"{wheel}, {name}")
                for name, p in (points or {}).items():
                    hit = m[p.rows]
                    if hit.any():
                        ax.errorbar(slip[p.rows[hit]], p.responses[q][hit],
                                    yerr=p.std[q][hit] if q in p.std else None, fmt="s", ms=5, mfc="none",
                                    color=colour, capsize=1.5, label=f"{wheel}, {name}")
            ax.set_title(f"{beta:g}°", fontsize=9)
            if row == len(responses) - 1:
                ax.set_xlabel("slip (rig's)")
            if col == 0:
                ax.set_ylabel(f"{q.replace('_', ' ')} [N]")
    axes[0, 0].legend(fontsize=6)
    fig.tight_layout()
    for row, q in enumerate(responses):
        _frame_on_data(axes[row], data, q, lines, points or {}, angles)
    path = Path(path)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def frame_limits(data: Measurements, q: str, points: dict) -> tuple[float, float] | None:
    """The y range of response ``q``'s panels: the measured points with their error bars and the models' points, 10 %
    beyond (None where there is nothing finite)."""
    std = np.nan_to_num(data.std.get(q, np.zeros(len(data))))
    values = [data.responses[q] - std, data.responses[q] + std]
    for p in points.values():
        err = np.nan_to_num(p.std[q]) if q in p.std else 0.0
        values += [p.responses[q] - err, p.responses[q] + err]
    values = np.concatenate([np.ravel(v) for v in values])
    values = values[np.isfinite(values)]
    if values.size == 0:
        return None
    lo, hi = float(values.min()), float(values.max())
    pad = 0.1 * max(hi - lo, 1e-9)
    return lo - pad, hi + pad


def _frame_on_data(row_axes, data: Measurements, q: str, lines: dict, points: dict, angles) -> None:
    """Scale one row of panels (one response, shared y) to :func:`frame_limits`; a model line that leaves the frame
    (e.g. a model that cannot carry the load sinks to its deepest and drags hundreds of newtons) is clipped, and its
    panel says how far it goes."""
    limits = frame_limits(data, q, points)
    if limits is None:
        return
    lo, hi = limits
    row_axes[0].set_ylim(lo, hi)
    for ax, beta in zip(row_axes, angles):
        m = data.slip_angle == beta
        model = np.concatenate([np.asarray(pred[q], float)[m] for pred in lines.values()]) if lines else np.zeros(0)
        model = model[np.isfinite(model)]
        if model.size and (model.min() < lo or model.max() > hi):
            far = model.min() if model.min() < lo else model.max()
            ax.text(0.03, 0.93, f"a model line leaves the frame (to {far:.0f} N)",
                    transform=ax.transAxes, fontsize=6, color="0.3")
