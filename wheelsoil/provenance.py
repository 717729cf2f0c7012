"""Provenance and safe file writing shared by every package.

* :func:`atomic_output` -- write to a temporary sibling and rename only when complete, so a crashed
  or killed run never leaves a file that looks finished.
* :func:`provenance` -- the versions and revision every result file carries.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import os
import subprocess
from pathlib import Path


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
