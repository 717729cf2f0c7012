import os

import pytest

os.environ.setdefault("WHEELSOIL_ARCH", "cpu")


@pytest.fixture(scope="session", autouse=True)
def taichi_runtime():
    from wheelsoil import runtime

    runtime.init()
    yield
