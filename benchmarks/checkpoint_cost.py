"""What checkpoints cost a run: the time to take the testbed's state and to write it, per checkpoint.

Runs a case (default ``smoke-1g-steer``) with checkpoints every ``--interval`` simulated seconds and times
:meth:`wheelsoil.coupling.testbed.Testbed.state` and the checkpoint write around every call::

    python -m wheelsoil.benchmarks.checkpoint_cost                  # about 90 s on 2 cores (bed cached)
    python -m wheelsoil.benchmarks.checkpoint_cost --case mini-1g-steer --interval 0.02

Prints JSON: checkpoints taken, mean seconds to take and to write one, checkpoint file size, the run's
wall time and the share of it spent on checkpoints.
"""

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--case", default="smoke-1g-steer")
    ap.add_argument("--interval", type=float, default=0.05, help="simulated seconds between checkpoints")
    ap.add_argument("--arch", default=None)
    args = ap.parse_args(argv)

    import wheelsoil.cases.run as run
    from wheelsoil.cases.schema import load_case
    from wheelsoil.coupling.testbed import Testbed

    cost = {"state": [], "write": [], "bytes": 0}
    take, write = Testbed.state, run.save_checkpoint

    def timed_state(self):
        t0 = time.perf_counter()
        out = take(self)
        cost["state"].append(time.perf_counter() - t0)
        return out

    def timed_write(path, state, meta):
        t0 = time.perf_counter()
        write(path, state, meta)
        cost["write"].append(time.perf_counter() - t0)
        cost["bytes"] = Path(path).stat().st_size

    Testbed.state, run.save_checkpoint = timed_state, timed_write
    case = load_case(args.case, [f"output.checkpoint_interval={args.interval!r}", "output.render=false"])
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        run.run_case(case, out, arch=args.arch)
        wall = time.perf_counter() - t0
    n = len(cost["write"])
    spent = sum(cost["state"]) + sum(cost["write"])
    print(json.dumps({
        "case": args.case, "interval_s": args.interval, "checkpoints": n,
        "state_seconds_mean": sum(cost["state"]) / max(n, 1), "write_seconds_mean": sum(cost["write"]) / max(n, 1),
        "checkpoint_mib": cost["bytes"] / 2**20, "run_wall_seconds": wall, "share_of_wall": spent / wall,
    }, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
