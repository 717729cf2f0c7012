"""Provenance and safe file writing shared by every package.

* :func:`atomic_output` -- write to a temporary sibling and rename only when complete, so a crashed
  or killed run never leaves a file that looks finished.
* :func:`writable_folder`, :func:`writable_file` -- check (and make) an output place before any work, so a
  bad ``--out`` is an input error naming it and not a traceback after minutes of simulation.
* :func:`write_markdown_and_json` -- a report's markdown and JSON files, each atomically.
* :func:`provenance` -- the versions and revision every result file carries.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import json
import os
import subprocess
import tempfile
from pathlib import Path

from .errors import WheelsoilInputError


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike):
    """Yield a temporary path next to ``path``; rename it to ``path`` if the block succeeds.

    On an exception the temporary file is removed and ``path`` is left as it was.
    """
    final = Path(path)
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = final.with_name(f".{final.name}.{os.getpid()}.partial")
    try:
        yield tmp
        os.replace(tmp, final)
    finally:
        if tmp.exists():
            tmp.unlink()


def writable_folder(path: str | os.PathLike, what: str = "--out", *, need_bytes: int = 0) -> Path:
    """Make the folder ``path`` (with its parents) and check that a file can be written in it and, when
    ``need_bytes`` is given, that its disk has that much free; returns it. Errors name ``what`` and the path."""
    folder = Path(path)
    for parent in [folder, *folder.parents]:
        if parent.exists():
            if not parent.is_dir():
                raise WheelsoilInputError(f"{what} {str(folder)!r}: {str(parent)!r} is a file, not a folder")
            break
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".write-test-"):
            pass
    except OSError as exc:
        raise WheelsoilInputError(f"{what} {str(folder)!r} cannot be written: {exc.strerror or exc}") from None
    if need_bytes > 0:
        free = os.statvfs(folder).f_bavail * os.statvfs(folder).f_frsize if hasattr(os, "statvfs") else 0
        if free and need_bytes > free:
            raise WheelsoilInputError(f"{what} {str(folder)!r}: the output needs about {need_bytes / 2**30:.3g} GiB "
                                      f"and its disk has {free / 2**30:.3g} GiB free")
    return folder


def writable_file(path: str | os.PathLike, what: str = "--out") -> Path:
    """Check that the file ``path`` can be written (its folder made and writable, the path not a folder)."""
    target = Path(path)
    if target.is_dir():
        raise WheelsoilInputError(f"{what} {str(target)!r} is a folder; give a file name")
    writable_folder(target.parent, f"{what} {str(target)!r}: its folder")
    return target


def write_markdown_and_json(markdown_path: str | os.PathLike, markdown: str, json_path: str | os.PathLike,
                            data, *, default=None) -> Path:
    """A report's two files, each written atomically: the markdown text and ``data`` as indented JSON
    (``default`` converts what JSON cannot hold, as in :func:`json.dumps`); returns the markdown path."""
    with atomic_output(json_path) as tmp:
        tmp.write_text(json.dumps(data, indent=1, default=default))
    with atomic_output(markdown_path) as tmp:
        tmp.write_text(markdown)
    return Path(markdown_path)


def git_revision() -> str | None:
    """The git revision of the source tree wheelsoil runs from, if it is a checkout."""
    here = Path(__file__).resolve().parent
    try:
        out = subprocess.run(
            ["git", "-C", str(here), "rev-parse", "HEAD"], capture_output=True, text=True, timeout=5
        )
    except (OSError, subprocess.SubprocessError):
        return None
    if out.returncode != 0:
        return None
    rev = out.stdout.strip()
    dirty = subprocess.run(
        ["git", "-C", str(here), "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True
    ).stdout.strip()
    return rev + ("-dirty" if dirty else "")


def provenance() -> dict:
    """Package version, git revision, Taichi version and backend, creation time (UTC, ISO 8601)."""
    import taichi as ti

    from wheelsoil import __version__
    from wheelsoil.runtime import current_arch

    return {
        "version": __version__,
        "git_rev": git_revision() or "unknown",
        "taichi_version": ".".join(str(v) for v in ti.__version__),
        "arch": current_arch() or "uninitialised",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    }
