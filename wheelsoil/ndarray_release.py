"""Free the memory of vector and matrix ndarrays when Python drops them (a Taichi 1.7 bug, worked around here).

In Taichi 1.7 only ``ScalarNdarray`` frees its device memory in ``__del__``; ``VectorNdarray`` and
``MatrixNdarray`` never do (taichi-dev/taichi issue #8763, fix proposed in PR #8764: move ``__del__`` to the
``Ndarray`` base class). Every reallocation of a vector ndarray therefore leaks it: on the CPU an 8 MB
``ti.Vector.ndarray(3, f64, (21000, 16))`` created and dropped 60 times grew the process by 463-475 MiB (two runs). The CMU twin
reallocates its per-sphere contact histories at every shift of its moving soil patch (about nine a second when the
wheel is dragged), and a dragged run's resident memory grew to 3.4 GB by t = 10 s.

:func:`install` gives the two classes the base-class ``__del__`` of that fix: the same call ``ScalarNdarray``
makes (``Program.delete_ndarray``, which waits for no pending kernel to need the array). Compute graphs bind no
arrays (:mod:`wheelsoil.graph_launch`), so no cached launch holds a freed one. Where a Taichi version gives the
classes their own ``__del__``, nothing is changed.
"""

from __future__ import annotations

from taichi.lang import impl
from taichi.lang.matrix import MatrixNdarray, VectorNdarray


def _delete_ndarray(self) -> None:
    """``ScalarNdarray.__del__`` of Taichi 1.7 (``taichi/lang/_ndarray.py``), guarded for interpreter shutdown."""
    try:
        runtime = impl.get_runtime() if impl is not None else None
        if runtime is not None and runtime.prog is not None:
            runtime.prog.delete_ndarray(self.arr)
    except Exception:  # noqa: BLE001 - a finaliser at shutdown must not raise
        pass


def install() -> tuple[str, ...]:
    """Give the ndarray classes without a ``__del__`` of their own the base-class one; returns their names."""
    patched = []
    for cls in (VectorNdarray, MatrixNdarray):
        if "__del__" not in cls.__dict__:
            cls.__del__ = _delete_ndarray
            patched.append(cls.__name__)
    return tuple(patched)
