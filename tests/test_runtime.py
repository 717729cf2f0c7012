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


def test_gpu_takes_the_first_device_found_or_is_refused_without_a_crash():
    """``arch="gpu"``: Taichi's own ``ti.gpu`` ended the process with a segmentation fault on a machine without a
    GPU (it goes on to OpenGL); wheelsoil tries its device backends itself and refuses plainly."""
    from wheelsoil import runtime

    code = ("import sys\nfrom wheelsoil import runtime\nfrom wheelsoil.errors import WheelsoilInputError\n"
            "try:\n    print('IN USE', runtime.init('gpu'))\nexcept WheelsoilInputError as exc:\n"
            "    print('REFUSED', exc)\n    sys.exit(3)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    if done.returncode == 0:
        assert any(f"IN USE {name}" in done.stdout for name in runtime.GPU_BACKENDS), done.stdout
        return
    assert done.returncode == 3, (done.returncode, done.stderr[-2000:])
    tried = ", ".join(runtime.GPU_BACKENDS)
    assert f"arch='gpu': none of {tried} is usable" in done.stdout and "--arch cpu" in done.stdout


@pytest.mark.parametrize("rigid, n_elements, arch, serial", [
    (True, 2772, "cpu", True), (False, 1000, "cpu", True), (False, 1001, "cpu", False),
    (True, 2772, "cuda", False), (False, 10, "vulkan", False)])
def test_a_structure_steps_serially_only_on_a_cpu(rigid, n_elements, arch, serial):
    from wheelsoil.flexwheel.structure import serial_by_default

    assert serial_by_default(rigid, n_elements, arch) is serial
