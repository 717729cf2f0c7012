"""The soil lab's box check judged from its runs' files (issue 33; docs/soillab/box/run.sh runs them).

The rule, fixed in ``docs/soillab/box/run.sh`` before any of its runs: a box is large enough where doubling it (across,
or in depth) changes the 100 mm plate's pressure at 10, 15 and 20 mm of sinkage by less than 10 % of the doubled box's
value; a larger change is the box's error, reported beside every plate number. Each doubling below is read from the
two boxes' ``plate.json`` (``pressure``: the simulated pressure at each sinkage); a box whose run has not finished is
said to be missing.

The depth-or-density question (``docs/soillab/box/density.sh``, fixed before its runs): the lab's box poured to the
deep box's packing (``density/plate``) against the deep box and the lab's box, at the same sinkages and 10 %: within
10 % of the deep box everywhere and more than 10 % from the lab box somewhere, the density explains the depth doubling;
within 10 % of the lab box everywhere, the depth does; otherwise both.

The depth doubling at equal packing (``docs/soillab/box/depth.sh`` for the lab's box, ``depth-wide.sh`` for the wide
one, each fixed before its runs): the deep box poured looser, to the shallow box's packing (``depth/plate``,
``depth-wide/plate``), against the shallow box by the box check's rule (a change below 10 % of the
deeper box's pressure at every sinkage: the lab box's depth holds the plate at equal packing); beside it, the two
packings and the looser deep box against the deep box (the density's effect at equal depth).

The wide box's seeds (``docs/soillab/box/wide-seeds.sh``, fixed before its runs): the wide box pressed with seeds 1 and
2 (``wide-seed1``, ``wide-seed2``) beside seed 0 (``wide``); both of its doublings (across, ``wider``, and in depth at
equal packing, ``depth-wide/plate``) judged again by the same rule against the three seeds' mean pressure, the
doubled boxes one seed each; the seeds' pressures, packings and spread beside.

Usage (from the repository root; seconds)::

    python docs/soillab_box_check.py --boxes docs/soillab/box
"""

import argparse
import json
import statistics
import sys
from pathlib import Path

#: The sinkages [m] the rule reads and the largest change it allows (of the doubled box's pressure).
SINKAGES = (0.01, 0.015, 0.02)
ALLOWED = 0.10
#: Each doubling: (what is doubled, the box, the doubled box), folder names under ``--boxes``.
DOUBLINGS = (("across", "lab", "wide"), ("in depth", "lab", "deep"),
             ("across", "wide", "wider"), ("in depth", "wide", "wide-deep"))
PLATE = 0.1
#: The depth doublings at equal packing: (key in check.json, the box, its deep box poured loose, the folder of the deep
#: box poured to the box's packing, the script that ran it), folder names under ``--boxes``.
EQUAL_PACKING = (("depth_at_equal_packing", "lab", "deep", "depth", "depth.sh"),
                 ("wide_depth_at_equal_packing", "wide", "wide-deep", "depth-wide", "depth-wide.sh"))


def pressures(folder: Path) -> dict | None:
    """Sinkage [m] -> simulated pressure [Pa] of the 100 mm plate in ``folder/plate.json`` (None: not run yet)."""
    path = folder / "plate.json"
    if not path.is_file():
        return None
    rows = json.loads(path.read_text())["pressure"]
    return {round(r["sinkage_m"], 6): r["simulated_Pa"] for r in rows if abs(r["diameter_m"] - PLATE) < 1e-9}


def judge(small: dict | None, big: dict | None) -> dict:
    """The relative changes (p_big - p_small) / p_big at :data:`SINKAGES` and the verdict."""
    if small is None or big is None:
        return {"changes": None, "verdict": "not run yet"}
    changes = [(big[z] - small[z]) / big[z] for z in SINKAGES]
    worst = max(abs(c) for c in changes)
    verdict = "passes" if worst < ALLOWED else f"fails ({worst:.0%} against {ALLOWED:.0%})"
    return {"changes": changes, "verdict": verdict}


def depth_or_density(lab: dict | None, deep: dict | None, dense: dict | None) -> dict:
    """The denser lab box's relative differences from the deep box and from the lab box at :data:`SINKAGES` (each of
    the denser box's pressure) and what they say (module docstring)."""
    if lab is None or deep is None or dense is None:
        return {"from_deep": None, "from_lab": None, "verdict": "not run yet"}
    from_deep = [(dense[z] - deep[z]) / dense[z] for z in SINKAGES]
    from_lab = [(dense[z] - lab[z]) / dense[z] for z in SINKAGES]
    near_deep = all(abs(c) < ALLOWED for c in from_deep)
    near_lab = all(abs(c) < ALLOWED for c in from_lab)
    if near_deep and not near_lab:
        verdict = "the density explains the depth doubling"
    elif near_lab:
        verdict = "the depth, not the density, stiffens the deep box"
    else:
        verdict = "both (neither box within 10 % everywhere)"
    return {"from_deep": from_deep, "from_lab": from_lab, "verdict": verdict}


def depth_at_equal_packing(lab: dict | None, deep: dict | None, loose_deep: dict | None) -> dict:
    """The looser deep box judged as a depth doubling of the lab's box (:func:`judge`), and its relative difference
    from the deep box poured as loose as the particles' own friction lets it, (p_loose_deep - p_deep) / p_loose_deep."""
    doubling = judge(lab, loose_deep)
    from_deep = (None if deep is None or loose_deep is None
                 else [(loose_deep[z] - deep[z]) / loose_deep[z] for z in SINKAGES])
    return {**doubling, "from_deep": from_deep}

#: The wide box's seeds (folder names under ``--boxes``) and the doublings judged against their mean:
#: (what is doubled, the doubled box's folder).
WIDE_SEEDS = ("wide", "wide-seed1", "wide-seed2")
WIDE_DOUBLINGS = (("across", "wider"), ("in depth at equal packing", "depth-wide/plate"))


def seed_mean(curves: list[dict | None]) -> dict | None:
    """The mean pressure [Pa] over seeds at :data:`SINKAGES` (None until every seed has run)."""
    if any(c is None for c in curves):
        return None
    return {z: statistics.fmean(c[z] for c in curves) for z in SINKAGES}


def wide_three_seeds(boxes: Path) -> dict:
    """The wide box's seeds and both of its doublings judged against their mean (module docstring)."""
    curves = [pressures(boxes / s) for s in WIDE_SEEDS]
    mean = seed_mean(curves)
    seeds = [{"folder": s, "packing": packing(boxes / s),
              "pressure_Pa": None if c is None else [c[z] for z in SINKAGES]} for s, c in zip(WIDE_SEEDS, curves)]
    spread = None if mean is None else [statistics.stdev(c[z] for c in curves) / mean[z] for z in SINKAGES]
    doublings = [{"doubled": what, "doubled_box": big, **judge(mean, pressures(boxes / big))}
                 for what, big in WIDE_DOUBLINGS]
    return {"seeds": seeds, "mean_Pa": None if mean is None else [mean[z] for z in SINKAGES],
            "relative_spread": spread, "doublings": doublings}


def packing(folder: Path) -> float | None:
    """The packing fraction of the bed the plate was pressed in (``folder/plate.json``; None: not run yet)."""
    path = folder / "plate.json"
    return json.loads(path.read_text())["runs"][0]["packing_fraction"] if path.is_file() else None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--boxes", default="docs/soillab/box")
    args = ap.parse_args(argv)
    boxes = Path(args.boxes)
    lines = ["# The box check, judged from the runs' files", "",
             f"Generated by `python docs/soillab_box_check.py --boxes {args.boxes}`; the rule (fixed in `run.sh` "
             "before "
             f"any run): doubling changes the 100 mm plate's pressure at 10, 15 and 20 mm by less than "
             f"{ALLOWED:.0%} of the doubled box's value.", "",
             "| doubled | box → doubled box | change at 10 / 15 / 20 mm | verdict |", "|---|---|---|---|"]
    verdicts = []
    for what, small, big in DOUBLINGS:
        v = judge(pressures(boxes / small), pressures(boxes / big))
        verdicts.append({"doubled": what, "box": small, "doubled_box": big, **v})
        change = "–" if v["changes"] is None else " / ".join(f"{c:+.0%}" for c in v["changes"])
        lines.append(f"| {what} | {small} → {big} | {change} | {v['verdict']} |")
    density = depth_or_density(pressures(boxes / "lab"), pressures(boxes / "deep"), pressures(boxes / "density" / "plate"))
    lines += ["", "Depth or density (`density.sh`: the lab's box poured to the deep box's packing):", "",
              "| denser lab box against | difference at 10 / 15 / 20 mm |", "|---|---|"]
    for key, name in (("from_deep", "the deep box"), ("from_lab", "the lab's box")):
        cell = "–" if density[key] is None else " / ".join(f"{c:+.0%}" for c in density[key])
        lines.append(f"| {name} | {cell} |")
    lines += ["", f"Verdict: {density['verdict']}."]
    fmt = (lambda v: "–" if v is None else f"{v:.4f}")
    equals = {}
    for key, box, deep, looser, script in EQUAL_PACKING:
        equal = depth_at_equal_packing(pressures(boxes / box), pressures(boxes / deep),
                                       pressures(boxes / looser / "plate"))
        equal["packing"] = {name: packing(boxes / folder) for name, folder in
                            (("box", box), ("deep", deep), ("looser_deep", f"{looser}/plate"))}
        pk = equal["packing"]
        lines += ["", f"Depth at equal packing, the {box} box (`{script}`: its deep box poured looser, to its packing; "
                  f"packing {box} {fmt(pk['box'])}, deep {fmt(pk['deep'])}, looser deep {fmt(pk['looser_deep'])}):",
                  "", "| looser deep box against | change at 10 / 15 / 20 mm |", "|---|---|"]
        for k, name in (("changes", f"the {box} box (the depth doubling at equal packing)"),
                        ("from_deep", "its deep box poured loose (the density at equal depth)")):
            cell = "–" if equal[k] is None else " / ".join(f"{c:+.0%}" for c in equal[k])
            lines.append(f"| {name} | {cell} |")
        lines += ["", f"Verdict on the {box} box's depth doubling at equal packing: {equal['verdict']}."]
        equals[key] = equal
    wide = wide_three_seeds(boxes)
    kpa = (lambda values: "–" if values is None else " / ".join(f"{1e-3 * v:.1f}" for v in values))
    lines += ["", "The wide box's seeds (`wide-seeds.sh`: both doublings against the three seeds' mean):", "",
              "| wide box | packing | pressure at 10 / 15 / 20 mm [kPa] |", "|---|---|---|"]
    lines += [f"| {s['folder']} | {fmt(s['packing'])} | {kpa(s['pressure_Pa'])} |" for s in wide["seeds"]]
    spread = ("–" if wide["relative_spread"] is None
              else " / ".join(f"{c:.0%}" for c in wide["relative_spread"]))
    lines += [f"| mean (the seeds' standard deviation, of the mean) | | {kpa(wide['mean_Pa'])} ({spread}) |", "",
              "| doubled | the three-seed wide box → | change at 10 / 15 / 20 mm | verdict |", "|---|---|---|---|"]
    for d in wide["doublings"]:
        change = "–" if d["changes"] is None else " / ".join(f"{c:+.0%}" for c in d["changes"])
        lines.append(f"| {d['doubled']} | {d['doubled_box']} | {change} | {d['verdict']} |")
    (boxes / "check.md").write_text("\n".join(lines) + "\n")
    (boxes / "check.json").write_text(json.dumps({"doublings": verdicts, "depth_or_density": density,
                                                  **equals, "wide_three_seeds": wide}, indent=1) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
