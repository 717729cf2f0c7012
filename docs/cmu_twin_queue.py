"""The CMU twin's runs, one case at a time, in the order a queue file gives (issue 34; docs/cmu-twin/README.md).

The sweeps' cases take one to several hours each on 2 cores, so they run one at a time in an order chosen for what each
finished case lets be judged (the README's "Queue order"), not the sweeps' own order. The queue is a JSON list, read
again before each entry (so it can be reordered while a case runs), with entries of two kinds:

* ``[sweep, wheel preset, steering angle, commanded slip, seed or null, drive or absent]``: the one case of the sweep
  preset (``cases/presets/sweeps/<sweep>.toml``, run into ``RUNS/<sweep>``) at that wheel and steering angle [deg],
  whose commanded slip is within 0.05 of the one given, at that seed (null: any) and drive [s] (absent: any; a sweep
  with a longer drive of one trial, ``cmu_sweep.LONGER_DRIVES``, has two cases of it); it must match one case only;
* ``["convergence", out folder, case file, factor, level drive time]``: ``wheelsoil convergence`` of one factor at x1
  and x2 (the bin checks; ``RUNS/`` in the out folder is the ``--runs`` folder), its reference the case file itself: a
  finished sweep case under ``RUNS/*/cases`` with the same case hash is linked into ``out/cases`` first
  (:func:`link_reference`), so the reference is not run twice.

Finished cases are skipped and a running case resumes from its checkpoint, so the script is restarted with the same
command after an interruption. A case recorded in the repository (its case hash in ``<recorded>/<sweep>/summary.csv``,
written by ``docs/cmu_twin_runs.py``) is skipped too, though its files are not under ``RUNS`` (a fresh machine): it is
not run twice. ::

    nohup python docs/cmu_twin_queue.py --runs RUNS --queue docs/cmu-twin/queue.json >> RUNS/cmu_queue.log 2>&1 &

Beside another long job on the same cores (the soil lab's calibration), give each one thread
(``WHEELSOIL_CPU_THREADS=1`` in the environment of both): two runs on two cores then step 1.18-1.26 times faster in all
than with a thread per core each (``cases/sweep.py``, ``benchmarks/README.md``).
"""

import argparse
import json
import subprocess
import sys
import time
import traceback
from pathlib import Path


def log(msg: str) -> None:
    print(time.strftime("%H:%M:%S"), msg, flush=True)


def link_reference(runs: Path, out: Path, case: str) -> Path | None:
    """Link a finished run of ``case`` (same case hash) found in ``runs/*/cases`` into ``out/cases``; returns the run
    linked (None: none found, or ``out`` has its own)."""
    from wheelsoil.cases.run import RESULT_NAME
    from wheelsoil.cases.schema import load_case

    digest = load_case(case).case_hash()
    target = out / "cases" / digest
    if target.exists():
        return None
    for found in sorted(runs.glob(f"*/cases/{digest}")):
        if (found / RESULT_NAME).is_file() and found.resolve() != target.resolve():
            target.parent.mkdir(parents=True, exist_ok=True)
            target.symlink_to(found.resolve(), target_is_directory=True)
            log(f"reference {digest}: the finished run {found}")
            return found
    return None


def run_convergence(runs: Path, out: str, case: str, factor: str, drive: float) -> int:
    """``wheelsoil convergence`` of ``factor`` at x1 and x2 into ``out`` (finished levels kept)."""
    out = str(runs / out[len("RUNS/"):]) if out.startswith("RUNS/") else out
    link_reference(runs, Path(out), case)
    cmd = [sys.executable, "-m", "wheelsoil.cases.cli", "convergence", case, "--factors", factor,
           f"--{factor.replace('_', '-')}-levels", "1,2", "--level-drive-time", str(drive), "--out", out]
    log("start " + " ".join(cmd[2:]))
    t0 = time.time()
    rc = subprocess.call(cmd)
    log(f"end convergence {out} {factor}: exit status {rc} in {time.time() - t0:.0f} s")
    return rc


def recorded_cases(recorded: Path, sweep: str) -> set[str]:
    """The case hashes ``recorded/<sweep>/summary.csv`` holds (the runs recorded in the repository; none: empty)."""
    import csv

    path = recorded / sweep / "summary.csv"
    if not path.is_file():
        return set()
    with open(path, newline="") as f:
        return {row["case_hash"] for row in csv.DictReader(f)}


def run_sweep_case(runs: Path, name: str, wheel: str, angle: float, slip: float, seed, drive: float | None = None,
                   recorded: Path | None = None) -> None:
    """The one case of sweep ``name`` at that wheel, steering angle, slip (within 0.05), seed and drive [s] (None:
    any); skipped where it has finished under ``runs`` or is recorded under ``recorded`` (:func:`recorded_cases`)."""
    from wheelsoil.cases.sweep import Sweep, load_sweep, run_sweep, write_summary

    sweep = load_sweep(name, runs / name)
    hits = [c for c in sweep.cases if c.values.get("wheel.preset") == wheel
            and float(c.values.get("test.slip_angle")) == angle and abs(float(c.values["test.slip"]) - slip) < 0.05
            and (seed is None or c.values.get("case.seed") == seed)
            and (drive is None or float(c.values.get("test.drive_time")) == float(drive))]
    if len(hits) != 1:
        log(f"{name} {wheel} {angle} {slip} {seed} {drive}: {len(hits)} matching cases, not one; skipped")
        return
    case = hits[0]
    if case.finished:
        log(f"{name} {case.folder.name} finished before")
        write_summary(sweep)
        return
    if recorded is not None and case.folder.name in recorded_cases(recorded, name):
        log(f"{name} {case.folder.name} recorded in {recorded / name} (its files are not here); skipped")
        return
    log(f"start {name} {case.folder.name} {case.name}")
    t0 = time.time()
    status = run_sweep(Sweep(sweep.name, [case], sweep.out, sweep.swept_keys), workers=1)
    log(f"end {name} {case.folder.name}: {status} in {time.time() - t0:.0f} s")
    write_summary(sweep)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", required=True, help="folder of the sweeps' runs (outside the repository)")
    ap.add_argument("--queue", default="docs/cmu-twin/queue.json")
    ap.add_argument("--recorded", default="docs/cmu-twin/runs",
                    help="the runs recorded in the repository (docs/cmu_twin_runs.py's --out): their cases are skipped")
    args = ap.parse_args(argv)
    runs, queue = Path(args.runs), Path(args.queue)
    k = 0
    while k < len(entries := json.loads(queue.read_text())):
        entry = entries[k]
        k += 1
        try:
            if entry[0] == "convergence":
                run_convergence(runs, *entry[1:])
            else:
                run_sweep_case(runs, *entry, recorded=Path(args.recorded))
        except Exception:  # one failed case does not stop the queue; its traceback is in the log
            traceback.print_exc()
    log("queue done")
    return 0


if __name__ == "__main__":
    sys.exit(main())
