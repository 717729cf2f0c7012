"""Taichi runtime set-up shared by every solver in the package.

Taichi is initialised once per process. The offline kernel cache is on (kernels compiled once are
reused by later processes), and its location can be moved with ``WHEELSOIL_TAICHI_CACHE``. On the CPU
backend the worker threads are pinned one to a core (:mod:`wheelsoil.threads`; ``WHEELSOIL_PIN_THREADS=0``
switches it off).
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import taichi as ti

from . import ndarray_release, threads
from .errors import WheelsoilInputError

_ARCHES = {
    "cpu": ti.cpu,
    "cuda": ti.cuda,
    "gpu": ti.gpu,
    "vulkan": ti.vulkan,
    "metal": ti.metal,
}

_state: dict = {"arch": None, "init_seconds": None}

#: What ``arch="gpu"`` tries, in order: the first that Taichi starts on a device is used. Taichi's own ``ti.gpu``
#: is not used: on a machine without CUDA it goes on to OpenGL, whose probe ended the process with a segmentation
#: fault on the project's machines (Taichi 1.7.4, no GPU; 2026-12-07), where a plain refusal is owed.
GPU_BACKENDS = ("cuda", "vulkan", "metal") if sys.platform == "darwin" else ("cuda", "vulkan")


def default_cache_dir() -> Path:
    """Root folder for wheelsoil's caches (``WHEELSOIL_CACHE`` or ``~/.cache/wheelsoil``)."""
    root = os.environ.get("WHEELSOIL_CACHE")
    return Path(root) if root else Path.home() / ".cache" / "wheelsoil"


def init(arch: str | None = None, *, debug: bool = False, cpu_threads: int | None = None) -> str:
    """Initialise Taichi for wheelsoil (idempotent).

    Parameters
    ----------
    arch:
        ``"cpu"`` (default, also taken from ``WHEELSOIL_ARCH``), ``"cuda"``, ``"gpu"`` (the first of
        :data:`GPU_BACKENDS` with a usable device), ``"vulkan"`` or ``"metal"``. Asking for a different backend
        after the first initialisation is an error, because every array already allocated lives on the first one.
    cpu_threads:
        Number of CPU threads for parallel loops (default: ``WHEELSOIL_CPU_THREADS``, else all cores). Runs that
        share the cores (a sweep's workers, a campaign beside a run) go faster in all with fewer threads each
        (``benchmarks/README.md``, "Several runs sharing the cores"); ``wheelsoil batch`` sets it for its workers.

    Returns the name of the backend actually in use (for ``"gpu"``, the one found).
    """
    requested = (arch or os.environ.get("WHEELSOIL_ARCH") or "cpu").lower()
    if requested not in _ARCHES:
        raise WheelsoilInputError(
            f"arch={requested!r} is not a Taichi backend wheelsoil knows; choose one of {sorted(_ARCHES)}"
        )
    if _state["arch"] is not None:
        same = requested == _state["arch"] or (requested == "gpu" and _state["arch"] in GPU_BACKENDS)
        if arch is not None and not same:
            raise WheelsoilInputError(
                f"Taichi is already running on arch={_state['arch']!r} in this process; "
                f"arch={requested!r} cannot be selected now (start a new process)"
            )
        return _state["arch"]
    cache = Path(os.environ.get("WHEELSOIL_TAICHI_CACHE", default_cache_dir() / "taichi"))
    cache.mkdir(parents=True, exist_ok=True)
    kwargs = dict(
        default_fp=ti.f64,
        default_ip=ti.i32,
        offline_cache=True,
        offline_cache_file_path=str(cache),
        debug=debug,
        log_level=ti.WARN,
    )
    if cpu_threads is None:
        cpu_threads = threads_from_environment()
    if cpu_threads is not None:
        kwargs["cpu_max_num_threads"] = int(cpu_threads)
    t0 = time.perf_counter()
    ndarray_release.install()  # vector and matrix ndarrays free their memory when dropped (Taichi 1.7's leak)
    tried = GPU_BACKENDS if requested == "gpu" else (requested,)
    for name in tried:
        ti.init(**dict(kwargs, arch=_ARCHES[name]))
        actual = ti.lang.impl.current_cfg().arch
        if name == "cpu" or actual not in (ti.x64, ti.arm64):
            break
        ti.reset()  # Taichi fell back to the CPU: try the next device backend, or refuse below
    else:
        # Taichi falls back to the CPU with a log line; a user who asked for a device is told plainly instead
        which = f"none of {', '.join(tried)}" if len(tried) > 1 else f"no {requested} device"
        raise WheelsoilInputError(
            f"arch={requested!r}: {which} is usable on this machine (Taichi would fall back to the CPU, "
            f"{actual.name}); use --arch cpu, or run where the device and its driver are installed"
        )
    _state["init_seconds"] = time.perf_counter() - t0
    if name == "cpu":
        threads.pin_worker_threads(int(ti.lang.impl.current_cfg().cpu_max_num_threads))
    _state["arch"] = name
    return name


#: The environment variable that sets the CPU backend's worker threads (:func:`init`).
CPU_THREADS_VAR = "WHEELSOIL_CPU_THREADS"


def threads_from_environment() -> int | None:
    """The worker threads ``WHEELSOIL_CPU_THREADS`` asks for (None: unset or empty); anything but a whole number from
    1 to the machine's cores is refused, naming the value."""
    raw = os.environ.get(CPU_THREADS_VAR, "").strip()
    if not raw:
        return None
    cores = os.cpu_count() or 1
    try:
        value = int(raw)
    except ValueError:
        value = 0
    if not 1 <= value <= cores:
        raise WheelsoilInputError(f"{CPU_THREADS_VAR}={raw!r}: give a whole number of CPU threads from 1 to this "
                                  f"machine's {cores} cores (or leave it unset: all of them)")
    return value


def current_arch() -> str | None:
    """Backend Taichi was initialised with, or ``None`` before :func:`init`."""
    return _state["arch"]
