"""Matplotlib for files, not screens: every figure wheelsoil writes goes through :func:`pyplot`."""

from __future__ import annotations


def pyplot():
    """``matplotlib.pyplot`` on the offscreen Agg backend (no display needed: CI, clusters, worker processes),
    imported on first use so that importing a module that can plot does not import matplotlib."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
