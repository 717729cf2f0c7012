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


@pytest.fixture(scope="session")
def bed_cache(tmp_path_factory):
    """A fresh bed cache for the session's runs (a bed is prepared once for every test that asks for it), also
    seen by the ``wheelsoil`` processes they start (``WHEELSOIL_CACHE``); the variable is restored afterwards."""
    path = tmp_path_factory.mktemp("bed-cache")
    old = os.environ.get("WHEELSOIL_CACHE")
    os.environ["WHEELSOIL_CACHE"] = str(path)
    yield path
    if old is None:
        os.environ.pop("WHEELSOIL_CACHE")
    else:
        os.environ["WHEELSOIL_CACHE"] = old
