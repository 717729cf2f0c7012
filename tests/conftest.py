import os

import pytest

os.environ.setdefault("WHEELSOIL_ARCH", "cpu")


def pytest_collection_modifyitems(config, items):
    # Nothing to adjust yet; slow tests are selected with -m slow.
    return None


@pytest.fixture(scope="session", autouse=True)
def taichi_runtime():
    from wheelsoil.granular import runtime

    runtime.init()
    yield
