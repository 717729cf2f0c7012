"""Can the CMU lab's side bulldozing supply the sideways force the heading-slip fit misses? (issue 36)

On the heading reading of the CMU trials the calibrated model misses the lateral force at 75 deg by 13-15 N RMS
(``docs/validation/slip-convention``). The lab's own model adds a bulldozing force on the wheel's side face
(``R_b.m``, Wong 2008; ``wheelsoil.validation.side_forces.side_bulldozing_force``). This script evaluates it for the
K10-mini wheel (r = 0.058 m, b = 0.05 m) with the lab's own soil values (``set_soil_params.m``: c = 1 kPa,
phi = 29 deg, 1330 kg/m^3), over the sinkages of the trials and exit angles from none to a full rear contact
(theta_r = 0, -0.3 and -1 theta_f), beside Schwanghart's sidewall resistance (seed 003 eq. 19), the catalogue's
side force. Closed-form evaluations only (seconds).

Usage::

    python docs/validation_side_bulldozing.py [--out docs/validation/side-bulldozing]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np


def main(argv=None) -> int:
    from wheelsoil.validation.side_forces import side_bulldozing_force, sidewall_force
    from wheelsoil.validation.terramechanics import RigidWheel, SoilParameters

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="docs/validation/side-bulldozing")
    args = parser.parse_args(argv)
    soil = SoilParameters(density=1330.0, cohesion=1000.0, friction_angle=29.0)
    wheel = RigidWheel(radius=0.058, width=0.05)
    betas = np.radians([30.0, 75.0, 90.0])
    rows = []
    for z in (0.005, 0.01, 0.02, 0.03):
        theta_f = float(np.arccos(1.0 - z / wheel.radius))
        side_wall = sidewall_force(soil, wheel, np.full(3, z), betas, 9.81)
        for ratio in (0.0, 0.3, 1.0):
            bulldozing = side_bulldozing_force(soil, wheel, np.full(3, theta_f), np.full(3, -ratio * theta_f), betas,
                                               9.81)
            rows.append({"sinkage_m": z, "theta_r_over_theta_f": -ratio if ratio else 0.0,
                         "side_bulldozing_N": dict(zip(("30", "75", "90"), np.round(bulldozing, 3).tolist())),
                         "schwanghart_sidewall_N": dict(zip(("30", "75", "90"), np.round(side_wall, 2).tolist()))})
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "forces.json").write_text(json.dumps(rows, indent=1))
    lines = ["| sinkage [mm] | theta_r / theta_f | lab's side bulldozing at 30 / 75 / 90 deg [N] | "
             "Schwanghart sidewall at 30 / 75 / 90 deg [N] |", "|---|---|---|---|"]
    for r in rows:
        b, s = r["side_bulldozing_N"], r["schwanghart_sidewall_N"]
        lines.append(f"| {1e3 * r['sinkage_m']:g} | {r['theta_r_over_theta_f']:g} | {b['30']:.2f} / {b['75']:.2f} / "
                     f"{b['90']:.2f} | {s['30']:.1f} / {s['75']:.1f} / {s['90']:.1f} |")
    (out / "forces.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
