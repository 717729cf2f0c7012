"""Vector and matrix ndarrays free their memory when dropped (wheelsoil.ndarray_release works around Taichi 1.7's
leak, taichi-dev/taichi#8763): allocating and dropping the same arrays many times does not grow the process by
what was allocated."""

import taichi as ti
from taichi.lang.matrix import MatrixNdarray, VectorNdarray


def _rss_mib() -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmRSS in /proc/self/status")


def test_dropped_vector_and_matrix_ndarrays_give_their_memory_back():
    assert "__del__" in VectorNdarray.__dict__ and "__del__" in MatrixNdarray.__dict__
    rounds, rows = 40, 21000
    per_round_mib = rows * (16 * 3 + 9) * 8 / 2**20  # an (n, 16) vec3 history array and an (n,) 3x3 matrix array

    def allocate_and_drop():
        a = ti.Vector.ndarray(3, ti.f64, shape=(rows, 16))
        b = ti.Matrix.ndarray(3, 3, ti.f64, shape=(rows,))
        a.fill(1.0)  # touched, so that the pages are resident
        b.fill(1.0)
        ti.sync()

    for _ in range(3):
        allocate_and_drop()
    before = _rss_mib()
    for _ in range(rounds):
        allocate_and_drop()
    grown = _rss_mib() - before
    # leaked, the process would grow by rounds * per_round_mib (about 365 MiB); allow a few arrays' worth of slack
    assert grown < 0.25 * rounds * per_round_mib, (grown, rounds * per_round_mib)
