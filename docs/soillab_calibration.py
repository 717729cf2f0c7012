"""Calibrate the lab's particles to the CMU sand: a documented design of experiments over sliding and rolling
friction, each candidate run through the virtual soil lab (poured bed, angle of repose, both plates), its residuals
against the sand's own measurements written as it finishes, so an interrupted campaign resumes where it stopped.

Usage (from the repository root, ``../shared`` beside it; about 15 min a candidate on 2 cores)::

    python docs/soillab_calibration.py run --out docs/soillab/calibration [--resume] [--cache DIR] [--max-candidates N]
    python docs/soillab_calibration.py summary docs/soillab/calibration
    python docs/soillab_calibration.py run --design packing --out docs/soillab/packing --resume --cache DIR
    python docs/soillab_calibration.py run --design epsd --out docs/soillab/calibration-epsd --resume --cache DIR

What each candidate does, chosen before any result was seen:

* the particle density is set so that the poured bed has the sand's bulk density: the bed is prepared at the lab's
  default density, its packing fraction measured, and prepared again at 1330 / phi when that misses 1330 kg/m^3 by
  more than 1 %;
* the angle of repose (draw-down, seed 0) against the sand's 29 deg;
* the 60 and 100 mm plates pressed to 30 mm (seed 0), their pressure at 5, 10, 15, 20 and 25 mm against the mean of
  the six measured trials of each plate (both CMU sandboxes).

The objective is the mean squared log-pressure error over the plates' ten points plus the repose error in units of
2 deg (the spread of the draw-down angle over packings); its minimum over the grid and over a quadratic response
surface fitted to the grid (scipy) are reported. The design grid: sliding friction 0.3, 0.5, 0.7 x rolling friction
0.1, 0.25, 0.5, fixed after the lab's baseline (sliding 0.5, rolling 0.1) stood at 20.9 deg against the sand's 29
(docs/soillab/baseline): rolling friction is what raises a sphere packing's angle of repose, so the grid reaches
well above the baseline's. The wheel-sinkage curves are not used: they are the held-out check of the calibrated
particles.

Design "packing" (2026-11-27, fixed after the friction grid and before any of its own results). Every friction
candidate's plates were a factor of two too soft, and the measured plates' pressure needs, by Meyerhof's circular
footing with c = 0, a friction angle of at least 33.5 deg (100 mm plate at 20 mm; Terzaghi 36 deg) against the
lab's 28.6 deg shear-box angle, while the repose is already matched. A sand's peak angle rises above its repose
angle with its packing density (dilatancy); a poured sphere bed with sliding and rolling friction 0.5 is at its
loosest. The design keeps the repose match (sliding 0.5, rolling 0.5) and pours the bed denser by multiplying the
friction by 0 (densest) and 0.25 while it settles (``BedSpec.pour_friction_factor``), next to the loose pour (1) as
reference; each candidate also runs the shear box (5 / 10 / 20 kPa) so the peak angle the hypothesis rests on is
measured, and is scored by the same objective as the grid.

Design "epsd" (2026-11-27, fixed after the rolling-law check's first point and before any of its own results). The
CDT rolling resistance creeps under a sub-threshold torque at M dt / I (docs/soillab/rolling/creep.md), and the
plate's pressure fell in proportion to the pressing speed; the EPSD law holds such a torque at rest. Its first plate
(sliding 0.5, rolling 0.5, 30 mm/s, docs/soillab/rolling-law) carried 3.3 times the CDT plate's pressure. The
repose angle and the plates both depend on the law, so the friction grid is run again, the same nine candidates,
poured and tested with ``rolling_model = "epsd"`` for every soil contact (particles, box, plates), with the shear box,
scored by the same objective.

Design "epsd-surface" (2026-11-27, after the EPSD grid): the lab verifies the quadratic response surface's minimum
before it is adopted. The EPSD grid's surface has its minimum at sliding 0.52, rolling 0.50 (predicted objective
0.46, against the grid's least, 0.83 at sliding 0.7, rolling 0.5), so that one candidate is run, with the shear box,
and adopted only if its measured objective is below the grid's least.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

from wheelsoil.soillab.objective import SINKAGES, score
from wheelsoil.soillab.objective import best as objective_best

FRICTIONS = (0.3, 0.5, 0.7)
ROLLING = (0.1, 0.25, 0.5)
#: (sliding friction, rolling friction, pour friction factor, with the shear box, rolling law) of every candidate,
#: per design.
DESIGNS = {
    "friction": tuple((mu, mu_r, 1.0, False, "cdt") for mu in FRICTIONS for mu_r in ROLLING),
    "packing": ((0.5, 0.5, 0.0, True, "cdt"), (0.5, 0.5, 0.25, True, "cdt"), (0.5, 0.5, 1.0, True, "cdt")),
    "epsd": tuple((mu, mu_r, 1.0, True, "epsd") for mu in FRICTIONS for mu_r in ROLLING),
    "epsd-surface": ((0.52, 0.5, 1.0, True, "epsd"),),
    # the EPSD grid and its surface's minimum again, their plates in the wide box (0.6 x 0.6 x 0.12 m; docs/soillab/box:
    # doubled across it passes against its three seeds, doubled in depth at equal packing it changes the plate by up to
    # 18 %, the box's error): run with --box and --reuse docs/soillab/calibration-epsd docs/soillab/calibration-epsd-surface
    "epsd-box": tuple((mu, mu_r, 1.0, True, "epsd") for mu in FRICTIONS for mu_r in ROLLING)
                + ((0.52, 0.5, 1.0, True, "epsd"),),
}


def candidate_name(mu: float, mu_r: float, pour: float, law: str = "cdt") -> str:
    return (f"mu{mu:g}_mur{mu_r:g}" + ("" if pour == 1.0 else f"_pour{pour:g}")
            + ("" if law == "cdt" else f"_{law}"))


#: What a candidate keeps from an earlier calibration's file of the same particles when only its plates run again
#: (``--reuse``): the density fixed in the lab's box, that bed's packing, the repose and the shear box.
REUSED_KEYS = ("friction", "rolling_friction", "pour_friction_factor", "rolling_model", "density", "packing_fraction",
               "bulk_density", "repose_deg", "shear")


def reused_row(folders, name: str) -> dict | None:
    """The candidate file ``name`` (without .json) of the first of ``folders`` that has one, less its plates and
    scores (``REUSED_KEYS`` and where it came from); None where none has it."""
    for folder in folders:
        path = Path(folder) / "candidates" / f"{name}.json"
        if path.is_file():
            row = json.loads(path.read_text())
            kept = {k: row[k] for k in REUSED_KEYS if k in row}
            kept["reused_from"] = str(path)
            return kept
    return None


def lab_particles(mu: float, mu_r: float, law: str, density: float):
    """(material, particle pair, tool pair) of a candidate: the lab's stiffness and restitution, sliding friction
    ``mu``, rolling friction ``mu_r`` under the rolling law ``law`` for particles and tools alike, particle density
    ``density`` [kg/m^3]."""
    from wheelsoil.material import Material, PairProperties
    from wheelsoil.parameters import soil_lab

    base = soil_lab.PARTICLE_MATERIAL
    material = Material("calibration", youngs_modulus=base.youngs_modulus, poisson_ratio=base.poisson_ratio,
                        density=density)
    pair = PairProperties(restitution=soil_lab.PARTICLE_PAIR.restitution, static_friction=mu, rolling_friction=mu_r,
                          rolling_model=law)
    return material, pair, dataclasses.replace(soil_lab.TOOL_PAIR, rolling_model=law)


def candidate(mu: float, mu_r: float, cache, pour: float = 1.0, shear: bool = False, law: str = "cdt",
              box: dict | None = None, reused: dict | None = None, checkpoints: Path | None = None) -> dict:
    """One candidate through the lab: density, repose and (``shear``) the shear box in the lab's box, unless
    ``reused`` gives them (:func:`reused_row`); the plates in ``box`` (default the lab's ``PLATE_BOX``), keeping their
    state in ``checkpoints`` (a folder) so that an interrupted plate continues."""
    from wheelsoil import soillab
    from wheelsoil.granular.bed import prepare_bed
    from wheelsoil.granular.bed_spec import BedSpec
    from wheelsoil.parameters import cmu_k10, soil_lab

    start = time.perf_counter()
    base = soil_lab.PARTICLE_MATERIAL

    def spec(density, where=soil_lab.PLATE_BOX):
        material, pair, tool_pair = lab_particles(mu, mu_r, law, density)
        return BedSpec(**where, diameter_min=soil_lab.DIAMETER_MIN, diameter_max=soil_lab.DIAMETER_MAX,
                       material=material, pair=pair, wall_material=soil_lab.TOOL_MATERIAL,
                       wall_pair=tool_pair, periodic=False, seed=0, pour_friction_factor=pour)

    if reused is not None:
        row = dict(reused)
        bed_spec = spec(row["density"])
    else:
        bed_spec = spec(base.density)
        bed = prepare_bed(bed_spec, cache_dir=cache)
        phi = bed.packing_fraction
        if abs(phi * base.density / cmu_k10.BULK_DENSITY - 1.0) > 0.01:
            bed_spec = spec(round(cmu_k10.BULK_DENSITY / phi, 1))
            bed = prepare_bed(bed_spec, cache_dir=cache)
        repose = soillab.repose_test(bed_spec, soillab.ReposeSpec(seeds=(0,)), cache_dir=cache)
        row = {"friction": mu, "rolling_friction": mu_r, "pour_friction_factor": pour, "rolling_model": law,
               "density": bed_spec.material.density, "packing_fraction": bed.packing_fraction,
               "bulk_density": bed.packing_fraction * bed_spec.material.density, "repose_deg": repose.runs[0].angle}
    plate_bed = spec(row["density"], box or soil_lab.PLATE_BOX)
    measured = soillab.load_plate_curves()
    plates = {}
    for d in soil_lab.PLATE_DIAMETERS:
        keep = {} if checkpoints is None else {
            "checkpoint": checkpoints / f".{candidate_name(mu, mu_r, pour, law)}-plate{1e3 * d:g}.checkpoint.h5"}
        result = soillab.plate_test(plate_bed, soillab.PlateSpec(diameter=d), cache_dir=cache, **keep)
        z = np.array(SINKAGES)
        sim, _, _ = soillab.mean_curve([result.curve], z)
        mea, mea_sd, _ = soillab.mean_curve([c for c in measured if c.size == d], z)
        area = result.curve.area
        plates[str(d)] = {"sinkage_m": list(z), "simulated_Pa": list(sim / area), "measured_Pa": list(mea / area),
                          "measured_sd_Pa": list(mea_sd / area), "wall_seconds": result.wall_seconds,
                          "top_offset_m": result.top_offset, "inertial_number": result.inertial_number,
                          "bulk_density": result.bulk_density}
    row["plates"] = plates
    row["plate_box_m"] = [plate_bed.length, plate_bed.width, plate_bed.depth]
    if shear and reused is None:
        result = soillab.shear_test(bed_spec, soillab.ShearSpec(), cache_dir=cache)
        row["shear"] = {"normal_stress_Pa": [r.plane_normal for r in result.runs],
                        "peak_shear_Pa": [r.peak for r in result.runs],
                        "dilation_m": [float(r.cap_rise[-1]) for r in result.runs],
                        "peak_friction_angle_deg": result.peak.friction_angle,
                        "peak_friction_angle_se_deg": result.peak.friction_angle_se,
                        "peak_cohesion_Pa": result.peak.cohesion, "peak_cohesion_se_Pa": result.peak.cohesion_se,
                        "residual_friction_angle_deg": result.residual.friction_angle,
                        "residual_cohesion_Pa": result.residual.cohesion, "bulk_density": result.bulk_density}
    row["wall_seconds"] = time.perf_counter() - start
    return score(row)


def run(args) -> int:
    out = Path(args.out)
    reused = {}
    if args.reuse:  # every candidate's earlier file, read and checked before hours of plates
        names = [candidate_name(mu, mu_r, pour, law) for mu, mu_r, pour, _, law in DESIGNS[args.design]]
        reused = {name: reused_row(args.reuse, name) for name in names}
        missing = [name for name, row in reused.items() if row is None]
        if missing:
            raise SystemExit(f"--reuse {' '.join(args.reuse)}: no candidates/<name>.json for {', '.join(missing)}")
    (out / "candidates").mkdir(parents=True, exist_ok=True)
    box = dict(zip(("length", "width", "depth"), args.box)) if args.box else None
    ran = 0
    for mu, mu_r, pour, shear, law in DESIGNS[args.design]:
        path = out / "candidates" / f"{candidate_name(mu, mu_r, pour, law)}.json"
        if args.resume and path.is_file():
            print(f"{path.name}: done before, kept", flush=True)
            continue
        if args.max_candidates is not None and ran >= args.max_candidates:
            print(f"stopping after {ran} candidate(s) (--max-candidates); --resume goes on", flush=True)
            return summary(args)
        ran += 1
        row = candidate(mu, mu_r, args.cache, pour=pour, shear=shear, law=law, box=box,
                        reused=reused.get(candidate_name(mu, mu_r, pour, law)),
                        checkpoints=out / "candidates" if args.box else None)
        tmp = path.with_suffix(".partial")
        tmp.write_text(json.dumps(row, indent=1))
        tmp.replace(path)
        extra = f", peak angle {row['shear']['peak_friction_angle_deg']:.1f} deg" if "shear" in row else ""
        print(f"{path.name}: objective {row['objective']:.4f} (plates {row['plate_log_mse']:.4f}, repose "
              f"{row['repose_deg']:.1f} deg{extra}), packing {row['packing_fraction']:.3f}, density "
              f"{row['density']:g}, {row['wall_seconds']:.0f} s", flush=True)
    return summary(args)


def summary(args) -> int:
    from scipy import optimize

    rows = [score(json.loads(p.read_text())) for p in sorted(Path(args.out).glob("candidates/*.json"))]
    if not rows:
        print("no candidate finished yet")
        return 1
    print("| sliding friction | rolling friction | pour friction factor | packing fraction | density [kg/m^3] | "
          "repose [deg] | shear: peak stress at 5 / 10 / 20 kPa [kPa] | plate log-MSE | objective |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in sorted(rows, key=lambda r: (r["friction"], r["rolling_friction"], -r.get("pour_friction_factor", 1.0))):
        shear = " / ".join(f"{t / 1e3:.1f}" for t in r["shear"]["peak_shear_Pa"]) if "shear" in r else "-"
        print(f"| {r['friction']:g} | {r['rolling_friction']:g} | {r.get('pour_friction_factor', 1.0):g} | "
              f"{r['packing_fraction']:.3f} | {r['density']:.0f} | {r['repose_deg']:.1f} | {shear} | "
              f"{r['plate_log_mse']:.4f} | {r['objective']:.4f} |")
    best = objective_best(rows)
    print(f"\nleast objective: sliding {best['friction']:g}, rolling {best['rolling_friction']:g}, pour friction factor "
          f"{best.get('pour_friction_factor', 1.0):g} (objective {best['objective']:.4f}); {len(rows)} candidate(s) done")
    grid = [r for r in rows if r.get("pour_friction_factor", 1.0) == 1.0]
    if len(grid) >= 6:  # the friction grid's response surface
        x = np.array([[r["friction"], r["rolling_friction"]] for r in grid])
        y = np.array([r["objective"] for r in grid])
        basis = lambda p: np.c_[np.ones(len(p)), p, p**2, p[:, :1] * p[:, 1:]]  # noqa: E731
        coef, *_ = np.linalg.lstsq(basis(x), y, rcond=None)
        res = optimize.minimize(lambda p: float((basis(np.atleast_2d(p)) @ coef)[0]), x0=[best["friction"],
                                best["rolling_friction"]], bounds=[(min(FRICTIONS), max(FRICTIONS)),
                                                                   (min(ROLLING), max(ROLLING))])
        print(f"quadratic surface minimum: sliding {res.x[0]:.3f}, rolling {res.x[1]:.3f} (predicted objective "
              f"{res.fun:.4f}); verify it with the lab before adopting it")
    return 0


def design_choice(out, design: str) -> tuple[Path, dict]:
    """The file and row of ``design``'s choice in ``out`` by its rule (the least objective, every candidate scored again
    from its stored curves); refused, naming them, while any of the design's candidates has not finished."""
    from wheelsoil.errors import WheelsoilInputError

    folder = Path(out) / "candidates"
    paths = [folder / f"{candidate_name(mu, mu_r, pour, law)}.json" for mu, mu_r, pour, _, law in DESIGNS[design]]
    missing = [p.stem for p in paths if not p.is_file()]
    if missing:
        raise WheelsoilInputError(f"{out}: design {design!r} has {len(paths) - len(missing)} of {len(paths)} "
                                  f"candidates; not finished: {', '.join(missing)}")
    rows = [score(json.loads(p.read_text())) for p in paths]
    chosen = objective_best(rows)
    k = next(k for k, r in enumerate(rows) if r["objective"] == chosen["objective"])
    return paths[k], rows[k]


def choice(args) -> int:
    """Print the path of the design's choice (:func:`design_choice`); refuse while any candidate has not finished."""
    from wheelsoil.errors import WheelsoilInputError

    try:
        path, _ = design_choice(args.out, args.design)
    except WheelsoilInputError as exc:
        print(exc, file=sys.stderr)
        return 1
    print(path)
    return 0


def figure(args) -> int:
    """The calibration's plates in one figure (issue 33): a panel per plate size, pressure against sinkage, the
    sand's measured trials (thin lines; both boxes) with their mean and standard deviation at the objective's
    sinkages, every candidate of the folder faint and the least objective bold (the design's choice once all of its
    candidates have finished; "least so far" before), with ``--seed-plates``' curves beside it: ``wheelsoil soil-lab
    plate`` folders of other seeds, which must be of the chosen particles (their files do not say)."""
    import pandas as pd

    from wheelsoil import soillab
    from wheelsoil.plotting import pyplot

    paths = sorted(Path(args.out).glob("candidates/*.json"))
    if not paths:
        print(f"{args.out}: no candidate finished yet", file=sys.stderr)
        return 1
    rows = [score(json.loads(p.read_text())) for p in paths]
    chosen = objective_best(rows)
    complete = len(rows) == len(DESIGNS[args.design])
    measured = soillab.load_plate_curves()
    seeds = []
    for folder in args.seed_plates or []:
        path = Path(folder) / "plate.csv"
        if not path.is_file():
            print(f"--seed-plates {folder}: no plate.csv", file=sys.stderr)
            return 1
        seeds.append(pd.read_csv(path))
    plt = pyplot()
    diameters = sorted(chosen["plates"], key=float)
    fig, axes = plt.subplots(1, len(diameters), figsize=(5.2 * len(diameters), 4.2), squeeze=False)
    for ax, d in zip(axes[0], diameters):
        for k, curve in enumerate(c for c in measured if f"{c.size:g}" == d):
            ax.plot(1e3 * curve.sinkage, 1e-3 * curve.pressure, color="0.75", lw=0.8,
                    label="CMU sand, each trial" if k == 0 else None)
        plate = chosen["plates"][d]
        z = 1e3 * np.asarray(plate["sinkage_m"])
        ax.errorbar(z, 1e-3 * np.asarray(plate["measured_Pa"]), yerr=1e-3 * np.asarray(plate["measured_sd_Pa"]),
                    fmt="ks", ms=4, capsize=3, label="CMU sand, mean ± sd")
        for row in rows:
            if row["objective"] != chosen["objective"]:
                ax.plot(z, 1e-3 * np.asarray(row["plates"][d]["simulated_Pa"]), color="tab:blue", alpha=0.25,
                        lw=0.8, marker=".")
        ax.plot(z, 1e-3 * np.asarray(plate["simulated_Pa"]), color="tab:red", lw=2, marker="o",
                label=f"DEM, sliding {chosen['friction']:g}, rolling {chosen['rolling_friction']:g}, seed 0 "
                      f"({'the choice' if complete else 'least so far'})")
        for k, table in enumerate(seeds):
            dem = table[(table["source"] == "DEM") & np.isclose(table["size_m"], float(d))]
            for label, curve in dem.groupby("label"):
                ax.plot(1e3 * curve["sinkage_m"], 1e-3 * curve["force_N"] / (np.pi * float(d) ** 2 / 4),
                        color="tab:red", lw=0.8, ls="--", label=f"{label}" if k < 2 else None)
        ax.plot([], [], color="tab:blue", alpha=0.4, label="the other candidates")
        z_max = 1e3 * max(plate["sinkage_m"]) * 1.1
        shown = [p for row in rows for p in row["plates"][d]["simulated_Pa"]]
        shown += [p for c in measured if f"{c.size:g}" == d for p in c.pressure[1e3 * c.sinkage <= z_max]]
        ax.set_xlim(0, z_max)
        ax.set_ylim(0, 1.1e-3 * np.nanmax(shown))
        ax.set_xlabel("sinkage [mm]")
        ax.set_ylabel("plate pressure [kPa]")
        ax.set_title(f"{1e3 * float(d):g} mm plate, box {' × '.join(f'{v:g}' for v in chosen['plate_box_m'])} m"
                     if "plate_box_m" in chosen else f"{1e3 * float(d):g} mm plate")
        ax.legend(fontsize=7)
    fig.suptitle(f"{Path(args.out).name}: objective {chosen['objective']:.3f} (plates' log-MSE "
                 f"{chosen['plate_log_mse']:.3f}, repose {chosen['repose_deg']:.1f}° against 29°)", fontsize=10)
    fig.tight_layout()
    out = Path(args.png or Path(args.out) / "plates.png")
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("run")
    p.add_argument("--out", default="docs/soillab/calibration")
    p.add_argument("--design", choices=sorted(DESIGNS), default="friction")
    p.add_argument("--resume", action="store_true")
    p.add_argument("--cache", default=None)
    p.add_argument("--max-candidates", type=int, default=None, help="run at most this many (a session's share)")
    p.add_argument("--box", type=float, nargs=3, default=None, metavar=("LENGTH", "WIDTH", "DEPTH"),
                   help="the plates' box [m] (default the lab's 0.3 x 0.3 x 0.12 m); an interrupted plate continues "
                        "from its checkpoint")
    p.add_argument("--reuse", nargs="+", default=None, metavar="DIR",
                   help="earlier calibration folders whose candidate files give each candidate's density, repose and "
                        "shear box: only the plates run again (in --box)")
    p.set_defaults(func=run)
    p = sub.add_parser("summary")
    p.add_argument("out", nargs="?", default="docs/soillab/calibration")
    p.set_defaults(func=summary)
    p = sub.add_parser("figure", help="the plates of every candidate and the sand's in one figure")
    p.add_argument("out")
    p.add_argument("--design", choices=sorted(DESIGNS), required=True)
    p.add_argument("--seed-plates", nargs="+", default=None, metavar="DIR",
                   help="soil-lab plate folders of the chosen particles with other seeds, drawn beside it")
    p.add_argument("--png", default=None, help="the figure's file (default OUT/plates.png)")
    p.set_defaults(func=figure)
    p = sub.add_parser("choice", help="the path of the design's chosen candidate (fails until all have finished)")
    p.add_argument("out")
    p.add_argument("--design", choices=sorted(DESIGNS), required=True)
    p.set_defaults(func=choice)
    args = parser.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
