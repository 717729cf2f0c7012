"""Keep idle CPU cores awake while the solver steps (opt-in; for virtual machines).

Taichi's CPU backend runs every parallel loop on a thread pool whose workers sleep on a condition
variable between loops, and a DEM step has two or more such loops. On a virtual machine a core that
finds nothing to run halts, and waking it for the next loop goes through the hypervisor: on the 2-core
cloud VM of ``benchmarks/README.md`` the stepping threads sat idle for 15-30 % of the wall time
between loops. MPI codes such as LIGGGHTS do not pay this, because their ranks busy-poll.

:func:`keep_cores_awake` gives the same effect without touching Taichi: it starts one helper process
per core that spins under the ``SCHED_IDLE`` policy. The kernel runs such a process only when nothing
else wants the core and preempts it at once when a solver thread wakes up, so the solver loses
(almost) nothing to it while its cores no longer halt. The price is that the cores show 100 % busy
for as long as the helpers run: use it for runs and benchmarks on dedicated (virtual) machines, not
on a shared workstation or a laptop on battery. Set ``WHEELSOIL_KEEP_CORES_AWAKE=1`` to make
:func:`wheelsoil.cases.run_case` (so ``wheelsoil run`` and every case of ``wheelsoil batch``) use it;
``benchmarks/dem_throughput.py --keep-cores-awake`` times it beside the plain run.

The helpers exit when the ``with`` block ends, and each one also exits by itself within a fraction
of a second if its parent process dies, so none is ever left spinning.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from collections.abc import Iterator

#: The helper: spin, and leave as soon as the parent process is gone (checked every ~10 ms). The
#: parent's pid comes as an argument: a parent that dies before the helper starts must count as gone.
_SPIN = (
    "import os, sys\n"
    "parent = int(sys.argv[1])\n"
    "while os.getppid() == parent:\n"
    "    for _ in range(100000):\n"
    "        pass\n"
)

ENV_VAR = "WHEELSOIL_KEEP_CORES_AWAKE"


def requested_by_environment() -> bool:
    """Whether ``WHEELSOIL_KEEP_CORES_AWAKE`` asks for awake cores (``1``, ``true``, ``yes``, ``on``)."""
    return os.environ.get(ENV_VAR, "").strip().lower() in {"1", "true", "yes", "on"}


def _idle_policy() -> None:  # pragma: no cover - runs in the child before exec
    os.sched_setscheduler(0, os.SCHED_IDLE, os.sched_param(0))


def supported() -> bool:
    """``SCHED_IDLE`` helpers need Linux (``os.SCHED_IDLE``)."""
    return sys.platform.startswith("linux") and hasattr(os, "SCHED_IDLE")


@contextlib.contextmanager
def keep_cores_awake(enabled: bool = True, cores: int | None = None) -> Iterator[int]:
    """Run the block with ``cores`` (default: all) ``SCHED_IDLE`` spinning helpers; yields how many run.

    With ``enabled=False``, or where the platform has no ``SCHED_IDLE``, nothing is started (yields 0).
    """
    if not enabled or not supported():
        yield 0
        return
    n = int(cores if cores is not None else (os.cpu_count() or 1))
    helpers: list[subprocess.Popen] = []
    try:
        for _ in range(max(n, 0)):
            helpers.append(
                subprocess.Popen(
                    [sys.executable, "-S", "-c", _SPIN, str(os.getpid())],
                    preexec_fn=_idle_policy,
                    stdin=subprocess.DEVNULL,
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                )
            )
        yield len(helpers)
    finally:
        for proc in helpers:
            proc.kill()
        for proc in helpers:
            proc.wait()
