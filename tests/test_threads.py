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
    "tasks = sorted(int(t) for t in os.listdir('/proc/self/task'))\n"
    "print(json.dumps({'pinned': {str(t): c for t, c in threads.pinned_threads().items()},\n"
    "                  'affinity': {str(t): sorted(os.sched_getaffinity(t)) for t in tasks}}))\n"
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
