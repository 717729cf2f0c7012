"""Worker-thread pinning (wheelsoil.threads): each Taichi CPU worker on its own core, or none touched when off."""

import json
import os
import subprocess
import sys

import pytest

from wheelsoil import threads

CHILD = (
    "import json, os\n"
    "from wheelsoil import runtime, threads\n"
    "runtime.init('cpu')\n"
    "affinity = {}\n"
    "for t in sorted(int(t) for t in os.listdir('/proc/self/task')):\n"
    "    try:\n"
    "        affinity[str(t)] = sorted(os.sched_getaffinity(t))\n"
    "    except ProcessLookupError:\n"
    "        pass  # a short-lived thread that ended between the listing and the query\n"
    "print(json.dumps({'pinned': {str(t): c for t, c in threads.pinned_threads().items()}, 'affinity': affinity}))\n"
)


def _child(env_value: str | None) -> dict:
    env = dict(os.environ)
    env.pop(threads.ENV_VAR, None)
    if env_value is not None:
        env[threads.ENV_VAR] = env_value
    done = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


needs_cores = pytest.mark.skipif(
    not threads.supported() or len(os.sched_getaffinity(0)) < 2, reason="needs Linux and at least two usable CPUs"
)


@needs_cores
def test_each_worker_is_bound_to_its_own_cpu():
    out = _child(None)
    cpus = sorted(os.sched_getaffinity(0))
    pinned = {int(t): c for t, c in out["pinned"].items()}
    assert len(pinned) == len(cpus), out  # the default pool has one worker per usable CPU
    assert sorted(pinned.values()) == cpus  # one worker per CPU, every CPU used
    for tid, cpu in pinned.items():
        assert out["affinity"][str(tid)] == [cpu]  # the kernel really holds that binding
    # the main thread and the other threads keep the whole set
    others = [t for t in out["affinity"] if int(t) not in pinned]
    assert others and all(out["affinity"][t] == cpus for t in others)


@needs_cores
@pytest.mark.parametrize("value", ["0", "off"])
def test_switched_off_by_the_environment(value):
    out = _child(value)
    cpus = sorted(os.sched_getaffinity(0))
    assert out["pinned"] == {}
    assert all(aff == cpus for aff in out["affinity"].values())


def test_environment_switch_values(monkeypatch):
    for value, expected in (("", True), ("1", True), ("on", True), ("0", False), ("False", False), ("no", False)):
        monkeypatch.setenv(threads.ENV_VAR, value)
        assert threads.requested_by_environment() is expected


def _fresh(monkeypatch, cpus=(0, 1)):
    monkeypatch.setattr(threads, "_state", {"pinned": {}})
    monkeypatch.setattr(threads, "supported", lambda: True)
    monkeypatch.delenv(threads.ENV_VAR, raising=False)
    monkeypatch.setattr(threads.os, "sched_getaffinity", lambda pid: set(cpus))


def test_a_failing_calibration_pins_nothing(monkeypatch):
    _fresh(monkeypatch)

    def broken(n_workers):
        raise RuntimeError("no calibration on this machine")

    monkeypatch.setattr(threads, "find_worker_threads", broken)
    assert threads.pin_worker_threads(2) == {}


def test_a_pool_that_does_not_cover_the_cpus_is_left_alone(monkeypatch):
    _fresh(monkeypatch, cpus=(0, 1, 2, 3))
    called = []
    monkeypatch.setattr(threads, "find_worker_threads", lambda n: called.append(n) or [])
    assert threads.pin_worker_threads(2) == {} and called == []  # decided before any calibration


STEP_CHILD = (
    "import json, sys\n"
    "import numpy as np\n"
    "from wheelsoil import runtime\n"
    "runtime.init('cpu')\n"
    "import taichi as ti\n"
    "from wheelsoil.granular import Scene\n"
    "rng = np.random.default_rng(7)\n"
    "n = 12 ** 3\n"
    "grid = np.stack(np.meshgrid(*[np.arange(12)] * 3, indexing='ij'), -1).reshape(-1, 3)\n"
    "x = 0.021 * grid + 0.02 + rng.uniform(-0.002, 0.002, (n, 3))\n"
    "scene = Scene((0, 0, 0), (0.3, 0.3, 0.4), gravity=(0, 0, -9.81))\n"
    "scene.add_box_walls()\n"
    "scene.add_spheres(x, rng.uniform(0.009, 0.0105, n), rng.normal(0, 0.3, (n, 3)))\n"
    "scene.step(400)\n"
    "print(json.dumps({'threads': ti.lang.impl.current_cfg().cpu_max_num_threads, 'contacts': scene.contact_count,\n"
    "                  'x': scene.positions.tolist(), 'w': scene.angular_velocities.tolist()}))\n"
)


@needs_cores
def test_the_cpu_thread_count_changes_the_speed_not_the_result():
    """``WHEELSOIL_CPU_THREADS`` (what ``wheelsoil batch`` sets for its workers): a colliding, falling packing of
    1,728 spheres stepped 400 times with one worker thread and with one per core ends bit for bit the same (the force
    pass sums each sphere's contacts in a fixed order, whatever the threads)."""
    runs = {}
    for value in ("1", str(len(os.sched_getaffinity(0)))):
        env = {**os.environ, "WHEELSOIL_CPU_THREADS": value}
        done = subprocess.run([sys.executable, "-c", STEP_CHILD], capture_output=True, text=True, env=env, timeout=300)
        assert done.returncode == 0, done.stderr[-2000:]
        runs[value] = json.loads(done.stdout.strip().splitlines()[-1])
        assert runs[value]["threads"] == int(value)
    one, many = runs.values()
    assert one["threads"] == 1 < many["threads"]
    assert one["contacts"] > 100  # colliding spheres, not spheres apart (188 at the time of writing)
    assert one["x"] == many["x"] and one["w"] == many["w"]
