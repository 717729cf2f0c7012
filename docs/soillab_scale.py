"""Particle-scale study of the soil lab's plate test: the 100 mm plate pressed into beds of the same particles at
three sizes, and the pressure extrapolated to zero particle size, so the lab's scale error is measured, not assumed.

Usage (from the repository root, ``../shared`` beside it; about 4, 10 and 25 min a seed on 2 cores)::

    python docs/soillab_scale.py run --out docs/soillab/scale [--resume] [--cache DIR] [--seeds 0 1]
    python docs/soillab_scale.py summary docs/soillab/scale
    python docs/soillab_scale.py run --out DIR --candidate CANDIDATE.json --box L W D [--scales 1 0.8 0.64] [...]

What it does, fixed before any result was seen:

* the lab's default particles (``wheelsoil.parameters.soil_lab``: 6.4--9.6 mm, sliding 0.5, rolling 0.1, 2340
  kg/m^3) scaled by 1, 0.8 and 0.64 (mean diameter 8, 6.4 and 5.1 mm: 12.5, 15.6 and 19.5 across the plate), the
  box (0.3 x 0.3 x 0.12 m), plate, speed (30 mm/s) and every contact property the same;
* the pressure at 5, 10, 15 and 20 mm of sinkage (the 100 mm plates were measured to 17--22 mm) of each seed;
* per sinkage, a line p = p0 + a d through the seeds' pressures against the mean diameter d (least squares, every
  seed a point), p0 its value at d = 0 with its standard error, and the scale error of the default particles,
  p(8 mm) / p0 - 1, with its standard error. The change is "converged" at a sinkage when the extrapolated change
  from the default particles is within 10 % of p0 (the lab's tolerance) at two standard errors; a curvature check
  (a quadratic through the three sizes' means) is reported beside it.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

SCALES = (1.0, 0.8, 0.64)
SINKAGES = (0.005, 0.01, 0.015, 0.02)
DIAMETER = 0.1
TOLERANCE = 0.10


def particles(candidate: str | None):
    """(material, particle pair, tool pair, pour friction factor) of the study: the lab's default particles, or those
    of a calibration candidate's file (``docs/soillab_calibration.py``: its friction, rolling friction and law, pour
    factor and the density its bed was poured at, with the calibration's stiffness, restitution and tools)."""
    from wheelsoil.parameters import soil_lab

    if candidate is None:
        return soil_lab.PARTICLE_MATERIAL, soil_lab.PARTICLE_PAIR, soil_lab.TOOL_PAIR, 1.0
    from soillab_calibration import lab_particles

    row = json.loads(Path(candidate).read_text())
    material, pair, tool = lab_particles(row["friction"], row["rolling_friction"], row["rolling_model"], row["density"])
    return material, pair, tool, row.get("pour_friction_factor", 1.0)


def one_run(scale: float, seed: int, cache, candidate: str | None = None, box: dict | None = None,
            checkpoint: Path | None = None, checkpoint_every: int = 10) -> dict:
    """The 100 mm plate on the particles (:func:`particles`) scaled by ``scale``, seed ``seed``, in ``box`` (default
    the lab's plate box); with ``checkpoint`` (a file) its state kept every ``checkpoint_every`` samples, so that an
    interrupted plate continues (``soillab.plate_test``)."""
    from wheelsoil import soillab
    from wheelsoil.granular.bed_spec import BedSpec
    from wheelsoil.parameters import soil_lab

    start = time.perf_counter()
    material, pair, tool_pair, pour = particles(candidate)
    bed_spec = BedSpec(**(box or soil_lab.PLATE_BOX), diameter_min=soil_lab.DIAMETER_MIN * scale,
                       diameter_max=soil_lab.DIAMETER_MAX * scale, material=material, pair=pair,
                       wall_material=soil_lab.TOOL_MATERIAL, wall_pair=tool_pair, periodic=False, seed=seed,
                       pour_friction_factor=pour)
    keep = {} if checkpoint is None else {"checkpoint": checkpoint, "checkpoint_every": checkpoint_every}
    result = soillab.plate_test(bed_spec, soillab.PlateSpec(diameter=DIAMETER), cache_dir=cache, **keep)
    z = np.array(SINKAGES)
    force, _, _ = soillab.mean_curve([result.curve], z)
    return {"scale": scale, "seed": seed, "mean_diameter_m": 0.5 * (bed_spec.diameter_min + bed_spec.diameter_max),
            "particles": result.particles, "bulk_density": result.bulk_density, "sinkage_m": list(z),
            "pressure_Pa": list(force / result.curve.area), "top_offset_m": result.top_offset,
            "inertial_number": result.inertial_number, "time_step_s": result.time_step, "steps": result.steps,
            "press_seconds": result.wall_seconds, "bed_seconds": result.bed_seconds,
            "wall_seconds": time.perf_counter() - start}


def run(args) -> int:
    out = Path(args.out)
    (out / "runs").mkdir(parents=True, exist_ok=True)
    box = dict(zip(("length", "width", "depth"), args.box)) if args.box else None
    for seed in args.seeds:
        for scale in args.scales:
            path = out / "runs" / f"scale{scale:g}_seed{seed}.json"
            if args.resume and path.is_file():
                print(f"{path.name}: done before, kept", flush=True)
                continue
            keep = {} if args.checkpoint_every is None else {
                "checkpoint": path.with_name(f".{path.stem}.checkpoint.h5"), "checkpoint_every": args.checkpoint_every}
            row = one_run(scale, seed, args.cache, candidate=args.candidate, box=box, **keep)
            if args.candidate:
                row["candidate"] = args.candidate
            row["box_m"] = list((box or _plate_box()).values())
            tmp = path.with_suffix(".partial")
            tmp.write_text(json.dumps(row, indent=1))
            tmp.replace(path)
            p = ", ".join(f"{1e3 * z:g} mm {1e-3 * v:.1f} kPa" for z, v in zip(row["sinkage_m"], row["pressure_Pa"]))
            print(f"{path.name}: {row['particles']} particles, {p}; {row['wall_seconds']:.0f} s", flush=True)
    return summary(args)


def _plate_box() -> dict:
    from wheelsoil.parameters import soil_lab

    return dict(soil_lab.PLATE_BOX)


def extrapolate(rows: list[dict]) -> list[dict]:
    """Per sinkage: p0 (the line's value at d = 0) with its standard error, the default particles' scale error
    and whether it is converged (:mod:`wheelsoil.scale_extrapolation`), and a quadratic's p0 through the sizes'
    means beside it."""
    from wheelsoil.errors import WheelsoilInputError
    from wheelsoil.scale_extrapolation import extrapolate_to_zero_size

    d = np.array([r["mean_diameter_m"] for r in rows])
    d_default = float(d.max())
    out = []
    for k, z in enumerate(SINKAGES):
        p = np.array([r["pressure_Pa"][k] for r in rows])
        ok = np.isfinite(p)
        entry = {"sinkage_m": z, "points": int(ok.sum())}
        try:
            fit = extrapolate_to_zero_size(d, p)
        except WheelsoilInputError:
            out.append(entry)
            continue
        error, error_se = fit.relative_change(d_default)
        entry.update(p0_Pa=fit.value, p0_se_Pa=fit.value_se, slope_Pa_per_m=fit.slope, dof=fit.dof,
                     default_Pa=fit.value + fit.change(d_default)[0], scale_error=error, scale_error_se=error_se,
                     converged=fit.converged(d_default, TOLERANCE))
        sizes = np.unique(d[ok])
        # the line's error at each size run (x0.8 is the CMU twin's particles), with its standard error and verdict
        entry["by_scale"] = {}
        for x in sizes[::-1]:
            change, change_se = fit.relative_change(x)
            entry["by_scale"][f"{x / d_default:.3g}"] = {"scale_error": change, "scale_error_se": change_se,
                                                         "converged": fit.converged(x, TOLERANCE)}
        if sizes.size >= 3:
            means = [float(np.mean(p[ok][d[ok] == x])) for x in sizes]
            entry["p0_quadratic_Pa"] = float(np.polyfit(sizes, means, 2)[-1])
        out.append(entry)
    return out


def summary(args) -> int:
    rows = [json.loads(p.read_text()) for p in sorted(Path(args.out).glob("runs/*.json"))]
    if not rows:
        print("no run finished yet")
        return 1
    print("| scale | mean diameter [mm] | seed | particles | " + " | ".join(f"p({1e3 * z:g} mm) [kPa]" for z in SINKAGES)
          + " | wall [s] |")
    print("|---" * (5 + len(SINKAGES)) + "|")
    for r in sorted(rows, key=lambda r: (-r["scale"], r["seed"])):
        print(f"| {r['scale']:g} | {1e3 * r['mean_diameter_m']:.2f} | {r['seed']} | {r['particles']} | "
              + " | ".join(f"{1e-3 * v:.2f}" for v in r["pressure_Pa"]) + f" | {r['wall_seconds']:.0f} |")
    table = extrapolate(rows)
    print("\n| sinkage [mm] | points | p0 [kPa] | default particles [kPa] | scale error | converged (10 %, 2 SE) | "
          "p0, quadratic [kPa] |")
    print("|---|---|---|---|---|---|---|")
    for e in table:
        if "p0_Pa" not in e:
            print(f"| {1e3 * e['sinkage_m']:g} | {e['points']} | - | - | - | too few points | - |")
            continue
        quad = f"{1e-3 * e['p0_quadratic_Pa']:.2f}" if "p0_quadratic_Pa" in e else "-"
        print(f"| {1e3 * e['sinkage_m']:g} | {e['points']} | {1e-3 * e['p0_Pa']:.2f} +- {1e-3 * e['p0_se_Pa']:.2f} | "
              f"{1e-3 * e['default_Pa']:.2f} | {100 * e['scale_error']:+.0f} +- {100 * e['scale_error_se']:.0f} % | "
              f"{'yes' if e['converged'] else 'no'} | {quad} |")
    (Path(args.out) / "extrapolation.json").write_text(json.dumps(table, indent=1))
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("run")
    p.add_argument("--out", default="docs/soillab/scale")
    p.add_argument("--resume", action="store_true")
    p.add_argument("--cache", default=None)
    p.add_argument("--seeds", type=int, nargs="+", default=[0])
    p.add_argument("--scales", type=float, nargs="+", default=list(SCALES),
                   help="particle scales [-] (default 1 0.8 0.64)")
    p.add_argument("--candidate", default=None, metavar="JSON",
                   help="a calibration candidate's file (docs/soillab_calibration.py): its particles instead of the "
                        "lab's defaults")
    p.add_argument("--box", type=float, nargs=3, default=None, metavar=("LENGTH", "WIDTH", "DEPTH"),
                   help="the plate's box [m] (default the lab's 0.3 x 0.3 x 0.12 m)")
    p.add_argument("--checkpoint-every", type=int, default=None, metavar="SAMPLES",
                   help="keep each plate's state every SAMPLES samples beside its result, so that a run interrupted "
                        "continues with --resume (another trajectory than without; default: none)")
    p.set_defaults(func=run)
    p = sub.add_parser("summary")
    p.add_argument("out", nargs="?", default="docs/soillab/scale")
    p.set_defaults(func=summary)
    args = parser.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
