"""Pour a box to another box's packing, then press the plate in it (issue 33): the shape the box checks at equal
packing share (``docs/soillab/box/density.sh``, ``depth.sh``, ``depth-wide.sh``), as one resumable command.

1. Pour the box at each ``--factors`` value of the pour friction factor (a rougher pour packs looser;
   ``wheelsoil soil-lab poured --pour-friction-factor``), one bed each, each kept in ``OUT/pour-F``.
2. Take the factor whose packing is nearest the target's (``--target``: a ``plate.json`` or ``poured.json`` of the
   box to match), on packing alone, so the choice is made before any plate is pressed in these beds.
3. Press the plate in that bed (checkpointed, hours at 10^5 spheres), kept in ``OUT/plate`` with the chosen factor.

Every step whose output exists is kept, so the same command run again continues where it stopped (a pour is not
resumable inside; the plate continues from its checkpoint). Each step's wall time and peak resident memory are
printed as it ends. Usage, from the repository root (the lab's CMU-sand particles are the default ``--lab``)::

    python docs/soillab_pour_to_packing.py --box 0.6 0.6 0.24 --factors 1.06 1.10 \\
        --target docs/soillab/box/wide/plate.json --out docs/soillab/box/depth-wide --cache /tmp/lab/cache

The judgement is not made here: ``python docs/soillab_box_check.py`` reads the plate files against its fixed rule.
"""

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

#: The CMU sand's particles as the box checks use them (``docs/soillab/box/run.sh``): diameters [m], grain density
#: [kg/m^3], sliding and rolling friction, the rolling model, one seed.
LAB = ("--dmin", "0.0064", "--dmax", "0.0096", "--density", "2541", "--friction", "0.52", "--rolling-friction", "0.5",
       "--rolling-model", "epsd", "--seeds", "0")


def packing(path: Path) -> float:
    """The packing fraction a ``poured.json`` or ``plate.json`` reports (first bed or run when there are several)."""
    d = json.loads(Path(path).read_text())
    for key in ("runs", "beds"):
        if key in d:
            return float(d[key][0]["packing_fraction"])
    return float(d["packing_fraction"])


def nearest_factor(pours: dict[str, Path], target: float) -> str:
    """The factor whose poured packing is nearest ``target`` (ties: the first given)."""
    return min(pours, key=lambda f: abs(packing(pours[f]) - target))


def run_step(label: str, argv: list[str]) -> None:
    """Run one ``wheelsoil`` step; print its wall time and peak resident memory; stop on failure."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    print(f"{label}: {time.perf_counter() - t0:.2f} s wall, {usage.ru_maxrss} KiB peak", flush=True)
    if proc.returncode != 0:
        raise SystemExit(f"{label} failed (exit {proc.returncode}): {' '.join(argv)}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--box", nargs=3, type=float, required=True, metavar=("LENGTH", "WIDTH", "DEPTH"),
                    help="the box to pour [m]")
    ap.add_argument("--factors", nargs="+", required=True, help="pour friction factors to try (0-3; above 1 looser)")
    ap.add_argument("--target", type=Path, required=True, help="plate.json or poured.json whose packing to match")
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--plate", default="0.1", help="plate diameter [m] (default 0.1)")
    ap.add_argument("--cache", default=None, help="bed cache folder (default the user cache)")
    ap.add_argument("--lab", nargs=argparse.REMAINDER, default=list(LAB),
                    help="the particles' soil-lab options, last on the line (default the CMU sand's, LAB)")
    args = ap.parse_args(argv)
    if not args.target.is_file():
        raise SystemExit(f"--target {args.target}: no such file")
    bad = [f for f in args.factors if not 0.0 <= float(f) <= 3.0]
    if bad:
        raise SystemExit(f"--factors {bad}: allowed 0 to 3 (the pour friction factor's range)")
    target = packing(args.target)
    box = [str(v) for v in args.box]
    lab = list(args.lab) + (["--cache", args.cache] if args.cache else [])
    pours = {}
    for f in args.factors:
        folder = args.out / f"pour-{f}"
        pours[f] = folder / "poured.json"
        if pours[f].is_file():
            print(f"{folder}: done before, kept", flush=True)
            continue
        run_step(f"pour {f}", ["wheelsoil", "soil-lab", "poured", "--box", *box, "--pour-friction-factor", f, *lab,
                               "--out", str(folder)])
    chosen = nearest_factor(pours, target)
    print(f"target packing {target:.4f}; poured " + ", ".join(f"{f}: {packing(p):.4f}" for f, p in pours.items())
          + f"; nearest: {chosen}", flush=True)
    plate = args.out / "plate"
    if (plate / "plate.json").is_file():
        kept = (plate / "pour_friction_factor.txt").read_text().strip()
        if kept != chosen:
            raise SystemExit(f"{plate} was pressed at factor {kept}, not the nearest {chosen}: another run's folder")
        print(f"{plate}: done before, kept", flush=True)
        return 0
    run_step(f"plate at {chosen}", ["wheelsoil", "soil-lab", "plate", "--plate", args.plate, "--box", *box,
                                    "--pour-friction-factor", chosen, *lab, "--out", str(plate),
                                    "--checkpoint-every", "10"])
    (plate / "pour_friction_factor.txt").write_text(chosen + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
