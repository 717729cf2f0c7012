"""Figure of the rolling-law check (issue 33): the 100 mm plate's pressure against sinkage under the CDT and EPSD
rolling resistance at three pressing speeds, beside the CMU sand's six measured 100 mm curves (their mean and
spread). Reads the runs of ``docs/soillab/rolling-law/run.sh`` and ``docs/soillab/speed/run.sh``.

Usage::

    python docs/soillab_rolling_law_figure.py [--out docs/soillab/rolling-law/curves.png]
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

RUNS = {  # label: (folder, colour, line style)
    "EPSD, 30 mm/s": ("docs/soillab/rolling-law/epsd-0.03", "tab:red", "-"),
    "EPSD, 15 mm/s": ("docs/soillab/rolling-law/epsd-0.015", "tab:red", "--"),
    "EPSD, 7.5 mm/s": ("docs/soillab/rolling-law/epsd-0.0075", "tab:red", ":"),
    "CDT, 30 mm/s": ("docs/soillab/speed/seed0-0.03", "tab:blue", "-"),
    "CDT, 15 mm/s": ("docs/soillab/speed/seed0-0.015", "tab:blue", "--"),
    "CDT, 7.5 mm/s": ("docs/soillab/speed/seed0-0.0075", "tab:blue", ":"),
}


def dem_curve(folder: str) -> tuple[np.ndarray, np.ndarray]:
    """Sinkage [m] and pressure [Pa] of the run's DEM curve (plate.csv)."""
    with open(Path(folder) / "plate.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["source"] == "DEM"]
    z = np.array([float(r["sinkage_m"]) for r in rows])
    force = np.array([float(r["force_N"]) for r in rows])
    area = np.pi * float(rows[0]["size_m"]) ** 2 / 4.0
    return z, force / area


def main(argv=None) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from wheelsoil.soillab.measured import load_plate_curves, mean_curve

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="docs/soillab/rolling-law/curves.png")
    args = parser.parse_args(argv)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    z = np.linspace(0.0, 0.025, 51)
    measured = [c for c in load_plate_curves() if c.size == 0.1]
    mean, sd, _ = mean_curve(measured, z)
    area = np.pi * 0.1**2 / 4.0
    ax.fill_between(1e3 * z, (mean - sd) / area / 1e3, (mean + sd) / area / 1e3, color="0.8", label="CMU sand, mean ± sd")
    ax.plot(1e3 * z, mean / area / 1e3, color="k", label=f"CMU sand, {len(measured)} trials")
    for label, (folder, colour, style) in RUNS.items():
        sz, p = dem_curve(folder)
        keep = sz >= 0.0
        ax.plot(1e3 * sz[keep], p[keep] / 1e3, color=colour, linestyle=style, label=label)
    ax.set_xlabel("sinkage [mm]")
    ax.set_ylabel("pressure [kPa]")
    ax.set_title("100 mm plate: sliding and rolling friction 0.5, seed 0")
    ax.set_xlim(0, 25)
    ax.legend(fontsize=8)
    fig.tight_layout()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
