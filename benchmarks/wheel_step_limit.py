"""What limits the wheel's stable step at smoke scale, and what mass scaling would cost to lift it.

The coupled step advances the wheel in two FE sub-steps per DEM step because the wheel's central-difference limit
(2 / omega_max of the assembled lumped-mass system, :func:`~wheelsoil.flexwheel.stability.assembled_critical_frequency`)
is below the soil's step. This reports, for a case's wheel (default ``smoke-1g-steer``):

* the assembled limit and the element bounds (Irons) per part of the wheel (tread, grousers, spokes), with the
  highest mode's split between translation and rotation (membrane modes translate);
* the limit after scaling every node's translational mass uniformly to reach one sub-step per DEM step (rotary
  inertia kept, then scaled too), and after element-wise mass scaling to that target step (LS-DYNA's ``DT2MS``
  idea: each element's corner masses raised by (target / dt_e)^2 where its own bound is below the target), with
  the mass each adds. Nothing here changes a run: it measures what the wheel's sub-steps would cost to remove.

Run:  python -m wheelsoil.benchmarks.wheel_step_limit [CASE] [--out benchmarks/results/wheel_step_limit.json]
"""

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from wheelsoil.cases import build
from wheelsoil.cases.schema import load_case
from wheelsoil.flexwheel.geometry import PARTS, build_wheel_mesh
from wheelsoil.flexwheel.linear import assemble_stiffness
from wheelsoil.flexwheel.stability import critical_frequency
from wheelsoil.flexwheel.structure import DEFAULT_SAFETY
from wheelsoil.granular.materials import effective_modulus
from wheelsoil.granular.timestep import estimate_time_step


def _largest_mode(stiffness, mass: np.ndarray, inertia: np.ndarray) -> tuple[float, float]:
    """(2 / omega_max, share of the highest mode's energy in translation) of the lumped system."""
    diag = np.c_[mass, mass, mass, inertia, inertia, inertia].reshape(-1)
    scale = sp.diags(1.0 / np.sqrt(diag))
    lam, vec = spla.eigsh((scale @ stiffness @ scale).tocsr(), k=1, which="LA", tol=1e-8)
    e = vec[:, 0].reshape(-1, 6) ** 2
    return 2.0 / math.sqrt(float(lam[0])), float(e[:, :3].sum() / e.sum())


def analyse(case_name: str) -> dict:
    case = load_case(case_name)
    bed = build.bed_spec(case)
    wheel = build.wheel_geometry(case)
    # the run's DEM step, at least (check_fits' bound: the smallest radius, the walls' and the wheel's contacts)
    moduli = (effective_modulus(bed.material, bed.wall_material), effective_modulus(bed.material, wheel.material))
    dem_step = case.soil.time_step or estimate_time_step(0.5 * bed.diameter_min, bed.material,
                                                         wall_moduli=moduli).stable
    mesh, _ = build_wheel_mesh(wheel)
    target = dem_step / DEFAULT_SAFETY  # one sub-step per DEM step at the default safety
    k = assemble_stiffness(mesh)
    mass, inertia = mesh.lumped_mass()
    dt, translation = _largest_mode(k, mass, inertia)
    dt_e = 2.0 / critical_frequency(mesh)
    n_tri = len(mesh.triangles)
    parts = {}
    for index, name in enumerate(PARTS):
        sel = np.flatnonzero(mesh.part[:n_tri] == index)
        if sel.size:
            parts[name] = {"facets": int(sel.size), "element_bound_min_s": float(dt_e[sel].min()),
                           "element_bound_median_s": float(np.median(dt_e[sel]))}
    out = {"case": case_name, "elements": int(mesh.n_elements), "wheel_mass_kg": float(mass.sum()),
           "dem_step_s": dem_step, "target_step_s": target, "assembled_limit_s": dt,
           "highest_mode_translation_share": translation, "parts": parts,
           "substeps_per_dem_step": math.ceil(dem_step / (DEFAULT_SAFETY * dt) * (1 - 1e-12))}
    factor = 1.001 * (target / dt) ** 2  # a hair above: the Lanczos limit carries its tolerance
    dt_u, tr_u = _largest_mode(k, mass * factor, inertia)
    out["uniform_mass_scaling"] = {"factor": factor, "limit_s": dt_u, "highest_mode_translation_share": tr_u}
    dt_b, tr_b = _largest_mode(k, mass * factor, inertia * factor)
    out["uniform_mass_and_inertia_scaling"] = {"factor": factor, "limit_s": dt_b, "highest_mode_translation_share": tr_b,
                                               "substeps_per_dem_step": math.ceil(dem_step / (DEFAULT_SAFETY * dt_b)
                                                                                  * (1 - 1e-12))}
    fm, _, _, _ = mesh.element_masses()
    scale = np.maximum(1.0, (target / dt_e[:n_tri]) ** 2)
    scaled = mass.copy()
    for a in range(3):
        np.add.at(scaled, mesh.triangles[:, a], fm * (scale - 1.0))
    dt_s, tr_s = _largest_mode(k, scaled, inertia)
    out["element_mass_scaling"] = {"elements_scaled": int(np.count_nonzero(scale > 1.0)),
                                   "added_mass_percent": 100.0 * (scaled.sum() / mass.sum() - 1.0),
                                   "limit_s": dt_s, "highest_mode_translation_share": tr_s}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", nargs="?", default="smoke-1g-steer")
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    out = analyse(args.case)
    text = json.dumps(out, indent=1)
    print(text)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
