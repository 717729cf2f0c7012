"""Where the long background campaigns stand (issues 33, 34, 35, 36; ``docs/background.sh`` starts them): one screen.

* the CMU twin's queue (``docs/cmu-twin/queue.json``): its last start and end in ``RUNS/cmu_queue.log``, and for each
  case that has a checkpoint under ``RUNS/*/cases`` its simulated time and when it was written;
* the wide-box calibration (``docs/soillab/calibration-epsd-box``): its finished candidates and the least objective,
  then the checks on its choice (``docs/soillab/choice-checks/run.sh``): the steps finished and the last log line;
* the validation campaigns that ``docs/validation/campaigns/five-gravities.sh`` runs: the draws each has of its target;
* issue 35's sweeps (``SWEEPS``, under RUNS): their cases finished and started; a running case's checkpoint is
  listed with the twin's.

Reads files only (it starts and stops nothing), so it can run beside the jobs::

    python docs/background_status.py [--runs RUNS]
"""

import argparse
import json
import os
import re
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CAMPAIGN_SCRIPT = ROOT / "docs" / "validation" / "campaigns" / "five-gravities.sh"
CALIBRATION = ROOT / "docs" / "soillab" / "calibration-epsd-box" / "candidates"
#: Candidates in the wide-box design (the nine grid points and the earlier surface minimum, docs/soillab/README.md).
CALIBRATION_CANDIDATES = 10
CHOICE_CHECKS = ROOT / "docs" / "soillab" / "choice-checks"


def twin_lines(runs: Path) -> list[str]:
    """The queue's last start/end lines and every checkpoint's simulated time."""
    lines = ["CMU twin queue (issue 34):"]
    log = runs / "cmu_queue.log"
    if log.is_file():
        events = [ln.strip() for ln in log.read_text().splitlines() if re.match(r"\d\d:\d\d:\d\d (start|end) ", ln)]
        lines += [f"  {ln[:150]}" for ln in events[-2:]] or ["  (no case started yet)"]
    else:
        lines.append(f"  no log at {log}")
    import h5py

    for path in sorted(runs.glob("*/cases/*/.checkpoint.h5")):
        with h5py.File(path, "r") as h5:
            t = float(h5.attrs.get("t", float("nan")))
        written = time.strftime("%Y-%m-%d %H:%M", time.localtime(os.path.getmtime(path)))
        lines.append(f"  running {path.parts[-4]}/{path.parts[-2]}: t = {t:.2f} s simulated (checkpoint {written})")
    queue = ROOT / "docs" / "cmu-twin" / "queue.json"
    if queue.is_file():
        lines.append(f"  queue: {len(json.loads(queue.read_text()))} entries in {queue.relative_to(ROOT)}")
    return lines


def calibration_lines() -> list[str]:
    """The finished wide-box candidates and the least objective among them."""
    done = []
    for path in sorted(CALIBRATION.glob("*.json")):
        record = json.loads(path.read_text())
        objective = record.get("objective")
        done.append((float(objective) if objective is not None else float("inf"), path.stem))
    lines = [f"wide-box calibration (issue 33): {len(done)} of {CALIBRATION_CANDIDATES} candidates"]
    if done:
        best = min(done)
        lines.append(f"  least objective so far: {best[1]} ({best[0]:.3f})")
    steps = sorted(p.parent.name for p in CHOICE_CHECKS.glob("*/*.json") if p.parent.name != "scale")
    scale = sorted(p.stem for p in (CHOICE_CHECKS / "scale" / "runs").glob("*.json"))
    log = CHOICE_CHECKS / "run.log"
    if steps or scale or log.is_file():
        lines.append(f"  checks on the choice: {', '.join(steps + scale) or 'none finished'}")
        if log.is_file():
            last = [ln for ln in log.read_text().splitlines() if ln.strip() and not ln.startswith("[Taichi]")]
            lines += [f"  log: {last[-1][:140]}"] if last else []
    return lines


def campaign_lines() -> list[str]:
    """Each campaign of the runner script with its draws done of its target."""
    text = CAMPAIGN_SCRIPT.read_text().replace("\\\n", " ") if CAMPAIGN_SCRIPT.is_file() else ""
    match = re.search(r'for spec in ((?:"[^"]+"\s*)+); do', text)
    lines = ["validation campaigns (issue 36):"]
    if not match:
        return lines + [f"  no campaign list found in {CAMPAIGN_SCRIPT}"]
    for spec in re.findall(r'"([^"]+)"', match.group(1)):
        kind, draws, seed = spec.split()[:3]
        path = CAMPAIGN_SCRIPT.parent / f"{kind}-{seed}.jsonl"
        done = sum(1 for ln in path.read_text().splitlines() if ln.strip()) if path.is_file() else 0
        lines.append(f"  {kind}-{seed}: {done} of {draws} draws")
    return lines


#: Issue 35's sweeps that ``docs/background.sh`` runs, by their folder under RUNS.
SWEEPS = ("gravity-terms/similar", "gravity-terms/froude", "gravity-terms/soil-stiffness", "gravity-terms/rigid-earth",
          "gravity-terms/rigid-moon", "seed004-full-scale", "seed004-like", "seed001-flexible-rigid")


def sweep_lines(runs: Path) -> list[str]:
    """Each sweep's cases under ``RUNS/SWEEP/cases``: those with a ``summary.json`` (finished) and those started
    without one (running, or stopped to resume; ``wheelsoil batch SWEEP --list`` names them all)."""
    lines = ["issue 35's sweeps:"]
    for name in SWEEPS:
        folders = sorted(p for p in (runs / name / "cases").glob("*") if p.is_dir())
        if not folders:
            lines.append(f"  {name}: no case started")
            continue
        finished = sum(1 for p in folders if (p / "summary.json").is_file())
        lines.append(f"  {name}: {finished} finished, {len(folders) - finished} started without a summary")
    return lines


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=Path, default=Path("/work/runs"), help="the runs folder (default /work/runs)")
    args = ap.parse_args(argv)
    print("\n".join(twin_lines(args.runs) + calibration_lines() + campaign_lines() + sweep_lines(args.runs)))


if __name__ == "__main__":
    main()
