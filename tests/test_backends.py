"""The tests that can run on any backend, on every backend this machine has (issue 37 item 3).

Taichi runs one backend per process, and the session's tests run on ``WHEELSOIL_ARCH`` (the CPU unless set;
``conftest.py``), which is the CPU's share of the parametrisation. Each device backend found here (a subprocess asks
:func:`wheelsoil.runtime.init` for it) runs the verification tests listed in ``tests/portable.txt`` (the Hertz and
Mindlin checks, the beam and ring elements, the sphere--wheel contact, the bed, the force balance) in a pytest of its
own with ``WHEELSOIL_ARCH`` set to it, and must pass them all. Where a backend has no device the case is skipped,
naming what was found.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DEVICE_BACKENDS = ("cuda", "vulkan")


def portable_tests() -> list[str]:
    lines = (ROOT / "tests" / "portable.txt").read_text().splitlines()
    return [line.strip() for line in lines if line.strip() and not line.startswith("#")]


def device_found(arch: str) -> tuple[bool, str]:
    """Whether wheelsoil starts on ``arch`` here, and what it said."""
    code = ("import sys\nfrom wheelsoil import runtime\nfrom wheelsoil.errors import WheelsoilInputError\n"
            f"try:\n    runtime.init({arch!r})\nexcept WheelsoilInputError as exc:\n    print(exc)\n    sys.exit(3)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    said = done.stdout.strip().splitlines() or done.stderr.strip().splitlines() or ["(nothing)"]
    return done.returncode == 0, said[-1][-300:]


def test_the_portable_list_names_existing_test_files():
    names = portable_tests()
    assert names and all((ROOT / name).is_file() for name in names), names


@pytest.mark.parametrize("arch", DEVICE_BACKENDS)
def test_the_portable_verification_tests_pass_on_every_device_backend_found(arch):
    found, said = device_found(arch)
    if not found:
        pytest.skip(f"no {arch} device here: {said}")
    env = dict(os.environ, WHEELSOIL_ARCH=arch)
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-m", "not slow",
                           *portable_tests()], cwd=ROOT, env=env, capture_output=True, text=True, timeout=1800)
    assert done.returncode == 0, f"on {arch}:\n{done.stdout[-4000:]}"
