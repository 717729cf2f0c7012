"""The held-out check of ``wheelsoil.parameters.cmu_sand`` (issue 33): the CMU wheels pressed into the calibrated
soil (``docs/soillab/cmu-sand/run.sh``) against the sand's measured wheel-sinkage curves, which no calibration step
used. Prints a markdown table: the DEM's force at 5-30 mm against the measured trials' mean and standard deviation
(both boxes), the ratio and the DEM's distance from the mean in trial standard deviations; and the log-force error
over those depths, the plates' measure of the calibration.

Usage (from the repository root, after run.sh)::

    python docs/soillab_cmu_sand_check.py docs/soillab/cmu-sand
"""

import sys
from pathlib import Path

import numpy as np
import pandas as pd

DEPTHS_MM = (5.0, 10.0, 15.0, 20.0, 25.0, 30.0)


def check(folder: Path, wheel: str) -> list[str]:
    from wheelsoil.soillab.measured import load_wheel_curves, mean_curve

    dem = pd.read_csv(folder / f"wheel-{wheel}" / "wheel.csv")
    dem = dem[dem["source"] == "DEM"].sort_values("sinkage_m")
    z = 1e-3 * np.asarray(DEPTHS_MM)
    reached = z <= dem["sinkage_m"].max()
    simulated = np.where(reached, np.interp(z, dem["sinkage_m"], dem["force_N"]), np.nan)
    curves = [c for c in load_wheel_curves() if c.wheel == wheel]
    mean, std, count = mean_curve(curves, z)
    lines = [f"**{wheel} wheel** ({len(curves)} measured trials, both boxes):", "",
             "| sinkage [mm] | DEM [N] | measured mean ± sd [N] (trials) | DEM / measured | (DEM − mean) / sd |",
             "|---|---|---|---|---|"]
    for k, d in enumerate(DEPTHS_MM):
        measured = f"{mean[k]:.1f} ± {std[k]:.1f} ({count[k]})"
        if not reached[k]:
            lines.append(f"| {d:g} | not reached | {measured} | – | – |")
            continue
        lines.append(f"| {d:g} | {simulated[k]:.1f} | {measured} | {simulated[k] / mean[k]:.2f} | "
                     f"{(simulated[k] - mean[k]) / std[k]:+.1f} |")
    ok = np.isfinite(simulated) & np.isfinite(mean) & (mean > 0) & (simulated > 0)
    log_mse = float(np.mean(np.log(simulated[ok] / mean[ok]) ** 2))
    lines += ["", f"Log-force error over {int(ok.sum())} depths: mean squared {log_mse:.3f} "
              f"(the plates' at calibration: 0.591).", ""]
    return lines


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    folder = Path(args[0] if args else "docs/soillab/cmu-sand")
    lines = []
    for wheel in ("grouser", "smooth"):
        if (folder / f"wheel-{wheel}" / "wheel.csv").is_file():
            lines += check(folder, wheel)
        else:
            lines += [f"**{wheel} wheel**: not run yet (`bash {folder}/run.sh {wheel}`).", ""]
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
