"""Backend selection: a device that is not there is an input error naming it, not a silent CPU run."""

import subprocess
import sys

import pytest


def test_a_missing_gpu_backend_is_refused_plainly(tmp_path):
    code = ("import sys\nfrom wheelsoil import runtime\nfrom wheelsoil.errors import WheelsoilInputError\n"
            "try:\n    runtime.init('cuda')\nexcept WheelsoilInputError as exc:\n    print('REFUSED', exc)\n"
            "    sys.exit(3)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    if done.returncode == 0:
        pytest.skip("this machine has a usable CUDA device")
    assert done.returncode == 3, done.stderr[-2000:]
    assert "arch='cuda': no cuda device is usable" in done.stdout and "--arch cpu" in done.stdout
    # the command line says so before any work, with the input-error status
    out = tmp_path / "run"
    cli = subprocess.run([sys.executable, "-m", "wheelsoil.cases.cli", "run", "mini-1g-steer", "--arch", "cuda",
                          "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert cli.returncode == 2, cli.stderr[-2000:]
    assert "no cuda device is usable" in cli.stderr and "Traceback" not in cli.stderr
