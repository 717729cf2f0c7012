"""A state to continue a run from, as one HDF5 file: a nested dict of NumPy arrays and scalars (groups for dicts,
datasets for arrays, attributes for scalars) and a flat dict of metadata, written atomically so that a run killed
while writing keeps its previous file. Used by the testbed's checkpoints (``wheelsoil.cases.run``) and the soil lab's
pressing tests (``wheelsoil.soillab.penetration``)."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from .provenance import atomic_output


def attr_value(value):
    """An HDF5 attribute as plain Python: bytes to str, NumPy scalars to Python numbers."""
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.generic):
        return value.item()
    return value


#: Arrays smaller than this many elements are stored without a filter (a compressed dataset is chunked, and a
#: chunk's overhead outweighs what a few values would save).
COMPRESS_FROM = 1024


def _write_tree(group: h5py.Group, tree: dict, compression: str | None = None) -> None:
    for key, value in tree.items():
        if isinstance(value, dict):
            _write_tree(group.create_group(key), value, compression)
        elif isinstance(value, np.ndarray):
            if compression is not None and value.size >= COMPRESS_FROM:
                group.create_dataset(key, data=value, compression=compression, shuffle=True)
            else:
                group.create_dataset(key, data=value)
        else:
            group.attrs[key] = value


def _read_tree(group: h5py.Group) -> dict:
    out = {k: attr_value(v) for k, v in group.attrs.items()}
    for key, item in group.items():
        out[key] = _read_tree(item) if isinstance(item, h5py.Group) else item[()]
    return out


def save_state(path: str | Path, state: dict, meta: dict, *, compression: str | None = None) -> None:
    """Write ``state`` (nested dict of arrays and scalars) and ``meta`` (scalars) to ``path`` atomically;
    ``compression``: an HDF5 filter for the larger arrays (``"gzip"``, with byte shuffling; default none: a running
    checkpoint is written often and read back whole, a carried one, :mod:`wheelsoil.cases.carry`, travels)."""
    with atomic_output(Path(path)) as tmp:
        with h5py.File(tmp, "w") as f:
            _write_tree(f.create_group("state"), state, compression)
            for key, value in meta.items():
                f.attrs[key] = value


def load_state(path: str | Path) -> tuple[dict, dict]:
    """(state, meta) of a file :func:`save_state` wrote."""
    with h5py.File(path, "r") as f:
        state = _read_tree(f["state"])
        meta = {k: attr_value(v) for k, v in f.attrs.items()}
    return state, meta


def load_meta(path: str | Path) -> dict:
    """The metadata of a file :func:`save_state` wrote, without reading its arrays."""
    with h5py.File(path, "r") as f:
        return {k: attr_value(v) for k, v in f.attrs.items()}
