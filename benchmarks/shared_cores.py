"""Several runs sharing the cores: how many worker threads each should have.

A sweep with ``--workers K``, or a campaign beside a sweep, runs K processes on the same cores. By default each
process starts one Taichi worker per core and pins them one to a core (:mod:`wheelsoil.threads`), so K processes put
K workers on every core, and every parallel loop of every process waits for its slowest worker. This benchmark
measures the aggregate throughput of K concurrent processes stepping the same soil, with every process at its default
(one worker per core, pinned) against one worker each (``WHEELSOIL_CPU_THREADS=1``, unpinned), in alternating rounds
in one run.

Each process loads the bed (from the cache; the parent prepares it once), steps it ``--warmup`` steps, then times
``--steps`` steps; the aggregate is the sum over the K processes of particles x steps / own timed wall, valid where
their timed loops overlap (the overlap is reported: the common span over the longest loop).

Run (nothing else running; minutes):  python -m wheelsoil.benchmarks.shared_cores [--processes 2] [--rounds 3]
      [--case cmu-grouser] [--steps 1500] [--out benchmarks/results/shared-cores.json]
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from wheelsoil.benchmarks.common import machine, versions

#: The two settings compared: name -> the environment each process gets.
SETTINGS = {"default (a worker per core, pinned)": {},
            "one worker each": {"WHEELSOIL_CPU_THREADS": "1", "WHEELSOIL_PIN_THREADS": "0"}}


def _bed(case_name: str):
    from wheelsoil.cases import build
    from wheelsoil.cases.schema import load_case
    from wheelsoil.granular import prepare_bed

    return prepare_bed(build.bed_spec(load_case(case_name)))


def child(case_name: str, warmup: int, steps: int) -> dict:
    """Step the case's bed and report the timed loop (one JSON line)."""
    from wheelsoil import runtime

    runtime.init()
    import taichi as ti

    bed = _bed(case_name)
    scene = bed.to_scene()
    scene.step(warmup)
    start_wall, t0, cpu0 = time.time(), time.perf_counter(), time.process_time()
    scene.step(steps)
    scene.check_health()  # the last step's results back on the host
    wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    return {"particles": bed.n_particles, "steps": steps, "wall_s": wall, "cpu_s": cpu,
            "start": start_wall, "end": start_wall + wall,
            "threads": int(ti.lang.impl.current_cfg().cpu_max_num_threads)}


def one_round(setting: str, processes: int, args) -> dict:
    """K concurrent processes under ``setting``; their aggregate particle-steps per second and overlap."""
    cmd = [sys.executable, "-m", "wheelsoil.benchmarks.shared_cores", "--child", "--case", args.case,
           "--warmup", str(args.warmup), "--steps", str(args.steps)]
    env = {**os.environ, **SETTINGS[setting]}
    procs = [subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
             for _ in range(processes)]
    outs = []
    for p in procs:
        stdout, stderr = p.communicate()
        if p.returncode != 0:
            raise RuntimeError(f"a benchmark process failed:\n{stderr[-3000:]}")
        outs.append(json.loads(stdout.strip().splitlines()[-1]))
    longest = max(o["wall_s"] for o in outs)
    common = min(o["end"] for o in outs) - max(o["start"] for o in outs)
    return {"setting": setting, "threads": [o["threads"] for o in outs],
            "aggregate_particle_steps_per_s": sum(o["particles"] * o["steps"] / o["wall_s"] for o in outs),
            "cpu_per_wall": sum(o["cpu_s"] for o in outs) / longest, "overlap": max(0.0, common) / longest,
            "processes": outs}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--case", default="cmu-grouser", help="the case preset whose bed is stepped")
    ap.add_argument("--processes", type=int, default=2, help="concurrent processes (K)")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds of the two settings")
    ap.add_argument("--warmup", type=int, default=100)
    ap.add_argument("--steps", type=int, default=1500)
    ap.add_argument("--out", default=None, help="write the figures as JSON here")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.case, args.warmup, args.steps)))
        return 0
    if args.processes < 1 or args.rounds < 1 or args.steps < 1:
        ap.error("--processes, --rounds and --steps must be at least 1")
    _bed(args.case)  # prepared once, so that every process loads it from the cache
    names = list(SETTINGS)
    rounds, ratios = [], []
    for k in range(args.rounds):
        pair = {}
        for setting in (names if k % 2 == 0 else names[::-1]):
            r = pair[setting] = one_round(setting, args.processes, args)
            rounds.append(r)
            print(f"round {k + 1}, {setting}: {r['aggregate_particle_steps_per_s'] / 1e6:.2f} M particle-steps/s "
                  f"(threads {r['threads']}, {r['cpu_per_wall']:.2f} cores busy, overlap {r['overlap']:.0%})",
                  flush=True)
        # the round ran both settings back to back: one worker each over the default
        ratios.append(pair[names[1]]["aggregate_particle_steps_per_s"] / pair[names[0]]["aggregate_particle_steps_per_s"])
    best = {s: max(r["aggregate_particle_steps_per_s"] for r in rounds if r["setting"] == s) for s in names}
    report = {"case": args.case, "processes": args.processes, "steps": args.steps, "rounds": rounds,
              "best_M_particle_steps_per_s": {s: v / 1e6 for s, v in best.items()},
              "ratio_one_worker_over_default_per_round": ratios,
              "ratio_median": statistics.median(ratios), "machine": machine(), "versions": versions()}
    print(f"{args.processes} processes: one worker each / default = {statistics.median(ratios):.2f} (median of "
          f"{len(ratios)} rounds: {', '.join(f'{r:.2f}' for r in ratios)}); best "
          + ", ".join(f"{s}: {v / 1e6:.2f} M" for s, v in best.items()))
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(report, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
