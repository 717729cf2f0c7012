import os

import pytest

os.environ.setdefault("WHEELSOIL_ARCH", "cpu")


@pytest.fixture(scope="session", autouse=True)
def taichi_runtime():
    from wheelsoil import runtime

    runtime.init()
    yield


SHARED_MEASURED = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data", "measured")


@pytest.fixture(scope="session")
def measured_dir():
    """``../shared/data/measured`` beside the repository; skipped where missing, a failure under CI=true."""
    path = os.path.abspath(SHARED_MEASURED)
    if not os.path.isdir(path):
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"CI=true but the measured data folder {path} is missing")
        pytest.skip(f"measured data folder {path} not present")
    return path
