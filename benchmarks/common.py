"""Measurement helpers shared by the benchmark tiers: machine description, peak memory, reference
workload, cold/warm kernel compile time."""


import os
import platform
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np


def peak_rss_mib() -> float:
    """Peak resident set size of this process [MiB] (Linux reports ru_maxrss in KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def own_peak_rss_mib() -> float:
    """Peak resident memory of this process's own address space [MiB] (``VmHWM``).

    ``getrusage``'s maximum survives fork and exec, so a child started by a large parent would report at
    least the parent's size; the high-water mark of the address space does not.
    """
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return peak_rss_mib()


def machine() -> dict:
    """What the figures were measured on."""
    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {"platform": platform.platform(), "cpu": cpu, "cores": os.cpu_count(), "python": sys.version.split()[0]}


def versions() -> dict:
    import taichi as ti

    from wheelsoil import __version__

    return {"wheelsoil": __version__, "taichi": ".".join(map(str, ti.__version__)), "numpy": np.__version__}


_reference_kernel = None


def reference_workload_seconds(repeats: int = 5) -> float:
    """Best-of-``repeats`` time [s] of a fixed workload, the yardstick that every benchmark figure
    is divided by so that figures from machines of different speed, or from one shared machine at
    different moments, can be compared.

    The workload has two parts, each as the solver uses the machine: a NumPy part (element-wise f64
    arithmetic with a square root and a division over 1e6 values, then a sort; one core) and a
    Taichi part (the same arithmetic in a parallel kernel over 2e6 values, 20 passes; all cores), so
    that a neighbour stealing a core slows the yardstick as it slows the solver's parallel loops.
    """
    global _reference_kernel
    import taichi as ti

    from wheelsoil import runtime

    runtime.init()
    if _reference_kernel is None:

        @ti.kernel
        def kernel(a: ti.types.ndarray(dtype=ti.f64, ndim=1), b: ti.types.ndarray(dtype=ti.f64, ndim=1)):
            for i in a:
                x = a[i]
                y = b[i]
                for _ in range(20):
                    x = ti.sqrt(x * x + y * y) / (1.0 + y)
                b[i] = x

        _reference_kernel = kernel
    ta = ti.ndarray(ti.f64, shape=2_000_000)
    tb = ti.ndarray(ti.f64, shape=2_000_000)
    ta.from_numpy(np.linspace(0.1, 1.0, 2_000_000))
    _reference_kernel(ta, tb)  # compile
    rng = np.random.default_rng(12345)
    a, b, c = rng.random((3, 1_000_000))
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(5):
            x = np.sqrt(a * a + b * b) / (1.0 + c)
            x.sort()
        for _ in range(5):
            tb.fill(0.5)
            _reference_kernel(ta, tb)
        tb.to_numpy()[:1]  # synchronise
        best = min(best, time.perf_counter() - t0)
    return best


def cache_times(code: str, names: tuple[str, ...]) -> dict:
    """Run the Python ``code`` in a fresh process with an empty Taichi kernel cache (``cold_cache``), then again
    with the cache it filled (``warm_cache``); the last ``len(names)`` numbers it prints are the times [s], keyed
    by ``names``."""
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, WHEELSOIL_TAICHI_CACHE=cache)
        for label in ("cold_cache", "warm_cache"):
            res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
            if res.returncode != 0:
                raise RuntimeError(res.stderr)
            out[label] = dict(zip(names, (float(v) for v in res.stdout.split()[-len(names):])))
    return out


def compile_time_cold() -> dict:
    """Time to the end of the first step of a small scene in a fresh process, with an empty Taichi
    kernel cache (``cold_cache``) and then with the cache it filled (``warm_cache``) [s]."""
    code = (
        "import time; t0=time.perf_counter();"
        "import numpy as np; from wheelsoil.granular import Scene, runtime;"
        "runtime.init(); t1=time.perf_counter();"
        "s=Scene((0,0,0),(0.2,0.2,0.2)); s.add_box_walls();"
        "s.add_spheres(np.array([[0.1,0.1,0.05],[0.1,0.1,0.08]]), np.array([0.01,0.01]));"
        "s.step(1); t2=time.perf_counter(); s.step(1); t3=time.perf_counter();"
        "print(t1-t0, t2-t1, t3-t2)"
    )
    return cache_times(code, ("init_s", "first_step_s", "steady_step_s"))


def alternating_kernel_times(calls: dict, rounds: int, repeats: int = 5) -> dict:
    """Seconds per call of each of ``calls`` ({name: function with no arguments that launches Taichi kernels}), timed
    in ``rounds`` rounds of ``repeats`` calls each, the order reversed every other round and the device synchronised
    around each timing (a shared machine's drift then falls on every function alike); {name: array of one time per
    round}."""
    import taichi as ti

    times: dict = {name: [] for name in calls}
    order = list(calls.items())
    for k in range(rounds):
        for name, call in order if k % 2 == 0 else order[::-1]:
            ti.sync()
            t0 = time.perf_counter()
            for _ in range(repeats):
                call()
            ti.sync()
            times[name].append((time.perf_counter() - t0) / repeats)
    return {name: np.array(t) for name, t in times.items()}
