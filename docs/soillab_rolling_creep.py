"""Does the contact law's rolling resistance hold a sphere at rest? (issue 33, the plate's speed dependence)

One sphere of the soil lab (8 mm, 2469.6 kg/m^3, E = 50 MPa, rolling friction 0.5 against a rigid floor, sliding
friction 0.5) rests on the floor under gravity; a constant torque about a horizontal axis, a fraction of the
rolling resistance mu_r F_n R (the torque the law promises to hold), is applied for 0.2 s. A resistance that holds at
rest keeps the sphere still. The constant-directional-torque law with its anti-chatter cap (``granular/contact.py``:
|M_r| <= I* |omega_r| / dt) lets it roll at omega = M dt / I*, so the creep rate scales with the time step. The
elastic--plastic spring--dashpot law (``rolling_model = "epsd"``) holds it: the sphere turns by the spring's twist
M / k_r (k_r = S_t R^2) and stops, whatever dt.

Usage (seconds on 2 cores)::

    python docs/soillab_rolling_creep.py [--out docs/soillab/rolling]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np


def creep(fraction: float, dt_factor: float, model: str, duration: float = 0.2) -> dict:
    from wheelsoil.granular.scene import Interaction, Scene
    from wheelsoil.material import Material, PairProperties

    radius, density = 0.004, 2469.6
    material = Material("soil-lab sphere", youngs_modulus=50e6, poisson_ratio=0.3, density=density)
    pair = PairProperties(restitution=0.5, static_friction=0.5, rolling_friction=0.5, rolling_model=model)
    scene = Scene((-0.05, -0.05, 0.0), (0.05, 0.05, 0.05), gravity=(0.0, 0.0, -9.81), material=material, pair=pair)
    scene.add_wall((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), material=None, pair=pair)
    mass = density * 4.0 / 3.0 * math.pi * radius**3
    # rest on the floor at the static Hertz overlap (E* = E / (1 - nu^2) against a rigid wall, R* = R)
    e_star = 50e6 / (1.0 - 0.3**2)
    overlap = (3.0 * mass * 9.81 / (4.0 * e_star * math.sqrt(radius))) ** (2.0 / 3.0)
    scene.add_spheres(np.array([[0.0, 0.0, radius - overlap]]), np.array([radius]))
    scene.time_step = scene.time_step * dt_factor
    dt = scene.time_step
    torque = fraction * 0.5 * mass * 9.81 * radius  # mu_r F_n R*, R* = R against a wall

    class Torque(Interaction):
        def add_forces(self, scene, dt):
            state = scene.device_state()
            t = state.external_torque.to_numpy()
            t[0, 1] += torque
            state.external_torque.from_numpy(t)
            return 0

    scene.add_interaction(Torque())
    settle = int(0.02 / dt)  # let the contact seat before the clock starts
    scene.step(settle)
    x0, steps = scene.positions[0].copy(), int(duration / dt)
    scene.step(steps)
    omega = float(scene.angular_velocities[0, 1])
    inertia = 0.4 * mass * radius**2
    rolled = float(1e3 * (scene.positions[0, 0] - x0[0]))
    return {"rolling_model": model, "torque_fraction": fraction, "dt_s": dt, "omega_rad_s": omega, "rolled_mm": rolled,
            "predicted_creep_rad_s": torque * dt / inertia, "duration_s": duration}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="docs/soillab/rolling")
    args = parser.parse_args(argv)
    rows = [creep(f, k, model) for model in ("cdt", "epsd") for f in (0.25, 0.5, 0.9) for k in (1.0, 0.5)]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "creep.json").write_text(json.dumps(rows, indent=1))
    lines = ["| law | torque / (mu_r F_n R) | dt [s] | omega after 0.2 s [rad/s] | M dt / I [rad/s] | rolled [mm] |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {r['rolling_model']} | {r['torque_fraction']:g} | {r['dt_s']:.3g} | {r['omega_rad_s']:.3g} | {r['predicted_creep_rad_s']:.3g} | "
              f"{r['rolled_mm']:.3g} |" for r in rows]
    (out / "creep.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
