"""wheelsoil.awake: the opt-in helpers that keep idle cores from halting between parallel loops."""

import os

import pytest

from wheelsoil.awake import keep_cores_awake, requested_by_environment, supported

pytestmark = pytest.mark.skipif(not supported(), reason="SCHED_IDLE helpers need Linux")


def _children() -> set[int]:
    me = str(os.getpid())
    kids = set()
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    fields = fh.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if fields[1] == me:  # field 4 of /proc/PID/stat: the parent's pid
                kids.add(int(entry))
    return kids


def test_helpers_spin_at_idle_priority_and_are_gone_after_the_block():
    before = _children()
    with keep_cores_awake(cores=2) as n:
        assert n == 2
        helpers = _children() - before
        assert len(helpers) == 2
        for pid in helpers:
            assert os.sched_getscheduler(pid) == os.SCHED_IDLE
    assert not (_children() & helpers)


def test_disabled_starts_nothing(monkeypatch):
    with keep_cores_awake(False) as n:
        assert n == 0
    monkeypatch.setenv("WHEELSOIL_KEEP_CORES_AWAKE", "1")
    assert requested_by_environment()
    monkeypatch.setenv("WHEELSOIL_KEEP_CORES_AWAKE", "0")
    assert not requested_by_environment()


def test_helpers_exit_when_their_parent_dies(tmp_path):
    """A killed run must not leave helpers spinning: each one leaves when its parent is gone."""
    import subprocess
    import sys
    import time

    script = (
        "import os, sys\n"
        "from wheelsoil.awake import keep_cores_awake\n"
        "with keep_cores_awake(cores=2):\n"
        "    kids = [p for p in os.listdir('/proc') if p.isdigit() and open(f'/proc/{p}/stat').read()"
        ".rsplit(')', 1)[1].split()[1] == str(os.getpid())]\n"
        "    print(' '.join(kids), flush=True)\n"
        "    os._exit(0)  # dies without leaving the with block\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60, cwd=tmp_path)
    pids = [int(p) for p in out.stdout.split()]
    assert len(pids) == 2, out.stderr
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(os.path.exists(f"/proc/{p}") and _alive(p) for p in pids):
        time.sleep(0.05)
    assert not any(os.path.exists(f"/proc/{p}") and _alive(p) for p in pids)


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            state = fh.read().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"
