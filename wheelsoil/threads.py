"""Pin Taichi's CPU worker threads one to a core (Linux), so that every parallel loop uses every core.

Taichi's CPU backend splits a parallel loop into one task per worker thread (about half the items each on two
cores, as measured with Taichi 1.7.4) and each worker sleeps on a condition variable between loops. Left to
the Linux scheduler on the 2-core benchmark VM, the second worker often did not start within a loop, or ran on
its partner's core, the two taking turns: in 11,927-item loops of ~2 ms it took no part at all in about a third
of the launches, and in others joined only after its partner had done much of the work (the order in which
the items were processed shows it; ``benchmarks/README.md``). Pinned one to a core, the second worker joined
every launch within a few tens of microseconds and the loop took 2.09 ms instead of 3.55 ms (median of 30).

:func:`pin_worker_threads` finds the workers by what they do (the threads that gain CPU time while a
parallel calibration kernel runs; no reliance on Taichi's thread names or creation order) and binds worker k
to the k-th CPU this process may use, like ``OMP_PROC_BIND=spread``. :func:`wheelsoil.runtime.init` calls it
on the CPU backend when the worker pool covers exactly the CPUs the process may use (the default); set
``WHEELSOIL_PIN_THREADS=0`` to leave the threads to the scheduler (for example when other programs share the
cores and should be able to push the solver's threads aside).
"""

import os
import sys
import threading

import taichi as ti

ENV_VAR = "WHEELSOIL_PIN_THREADS"

_state: dict = {"pinned": {}}


def requested_by_environment() -> bool:
    """False when ``WHEELSOIL_PIN_THREADS`` is ``0``, ``false``, ``no`` or ``off``; True otherwise."""
    return os.environ.get(ENV_VAR, "").strip().lower() not in {"0", "false", "no", "off"}


def supported() -> bool:
    """Per-thread affinity and CPU clocks need Linux (``os.sched_setaffinity`` on a thread id, ``/proc``)."""
    return sys.platform.startswith("linux") and hasattr(os, "sched_setaffinity") and os.path.isdir("/proc/self/task")


def _thread_ids() -> list[int]:
    return sorted(int(t) for t in os.listdir("/proc/self/task"))


def _cpu_ns(tid: int) -> int:
    """CPU time a thread has run [ns] (first field of its schedstat; 0 if it has exited)."""
    try:
        with open(f"/proc/self/task/{tid}/schedstat") as f:
            return int(f.read().split()[0])
    except (OSError, ValueError, IndexError):
        return 0


@ti.kernel
def _calibration(values: ti.types.ndarray(dtype=ti.f64, ndim=1), rounds: ti.i32):
    for i in range(values.shape[0]):
        s = 0.0
        for q in range(rounds):
            s += ti.cos(values[i] * q + i)
        values[i] = s


def find_worker_threads(n_workers: int, *, launches: int = 40, min_ns: int = 200_000) -> list[int]:
    """The ids of the threads that run Taichi's parallel loops: those, other than the calling thread, that gain
    at least ``min_ns`` of CPU time over ``launches`` launches of a parallel calibration kernel (~2 ms each on
    two cores). Stops early once ``n_workers`` are found; may find fewer."""
    values = ti.ndarray(ti.f64, shape=20_000)
    values.fill(0.5)
    _calibration(values, 2)  # compile outside the measurement
    me = {os.getpid(), threading.get_native_id()}
    before = {t: _cpu_ns(t) for t in _thread_ids()}
    found: list[int] = []
    for k in range(launches):
        _calibration(values, 20)
        if k % 5 == 4:
            gained = {t: _cpu_ns(t) - before.get(t, 0) for t in _thread_ids() if t not in me}
            found = sorted((t for t, ns in gained.items() if ns >= min_ns), key=lambda t: -gained[t])
            if len(found) >= n_workers:
                break
    return sorted(found[:n_workers])


def pin_worker_threads(n_workers: int) -> dict[int, int]:
    """Bind each of Taichi's ``n_workers`` CPU worker threads to its own CPU of the process's affinity set.

    Returns {thread id: cpu}; empty (nothing changed) where it is not supported, switched off by
    ``WHEELSOIL_PIN_THREADS``, where the pool does not cover exactly the CPUs the process may use, or where the
    workers cannot all be identified. Idempotent within a process.
    """
    if _state["pinned"] or not (supported() and requested_by_environment()):
        return dict(_state["pinned"])
    cpus = sorted(os.sched_getaffinity(0))
    if n_workers < 2 or n_workers != len(cpus):
        return {}
    try:
        workers = find_worker_threads(n_workers)
    except Exception:  # noqa: BLE001 - an optimisation that cannot run must never stop a simulation
        return {}
    if len(workers) != n_workers:
        return {}
    pinned = {}
    try:
        for tid, cpu in zip(workers, cpus):
            os.sched_setaffinity(tid, {cpu})
            pinned[tid] = cpu
    except OSError:
        for tid in pinned:  # undo a partial pinning rather than leave the pool lopsided
            try:
                os.sched_setaffinity(tid, set(cpus))
            except OSError:
                pass
        return {}
    _state["pinned"] = pinned
    return dict(pinned)


def pinned_threads() -> dict[int, int]:
    """{thread id: cpu} of the workers pinned in this process (empty if none)."""
    return dict(_state["pinned"])
