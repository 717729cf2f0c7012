"""Unfinished runs carried to another machine without their frames.

A run's checkpoint (``.checkpoint.h5``, :mod:`.run`) holds its whole state and its time series, so a checkpoint
alone is enough to continue it; its partial result holds the frames, which are most of an unfinished run's bytes (a
frame of the CMU twin's 21,500 spheres is 0.8 MB, 400 of them in its 20 s drive, where its checkpoint is about
0.8 kB a sphere). :func:`pack_runs` packs the checkpoint of every unfinished run under a folder, compressed, into one
file each (``<case hash>.carry.h5``, with the run folder's path relative to that folder and its ``case.toml``), and
:func:`unpack_runs` puts them back as checkpoints under a runs folder on the other machine, where ``wheelsoil run
--resume`` (and a sweep or convergence study, which resume any case folder with a checkpoint) continues each run.

What the carried run ends with: the series and summary of a run never moved, to the bit where the bed prepared on
the other machine is the same (the DEM's force pass is a gather and the thread count does not change a result, so a
bed prepared from the same case with the same code on the same backend is: ``tests/test_cases_run.py`` resumes a
carried run on a bed prepared again); its result holds only the frames from the carry on and says so in its run info
(``frames_lost_before`` [s]). Packing never moves a run backwards: a checkpoint is unpacked only into a folder with no
finished result and no checkpoint as new or newer.

Finished runs of a long sweep travel too, on request (``finished_in``): a sweep of 54 cases of 10 minutes outlasts a
session, and a fresh machine that has lost its finished cases runs them again. :func:`pack_finished` keeps a finished
result without its frames (``<case hash>.result.h5``: the series, summary, stages, run info and mesh, gzip with
shuffle; a seed004-like smoke case's, 29 series of 1,800 samples and the mesh, is 0.36 MB) and :func:`unpack_run`
puts it back as the case folder's ``result.h5`` with an empty ``/frames`` group and ``frames_dropped`` in its run
info, so the sweep finds the case finished and its tables read it (:func:`~.results.load_result`). A finished carry
is never replaced or removed by packing: it is that run's record.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import h5py

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.state_file import load_meta, load_state, save_state

from .results import partial_path
from .run import CHECKPOINT_NAME, RESULT_NAME

#: A carried run's file name: its case hash and this suffix.
CARRY_SUFFIX = ".carry.h5"
#: A carried finished run's file name: its case hash and this suffix.
FINISHED_SUFFIX = ".result.h5"
#: The checkpoint metadata a carry keeps (:mod:`.run`'s module docstring).
CHECKPOINT_META = ("case_hash", "t", "checkpoints", "frames")
#: Checkpoints larger than this on disk are not packed by default [MB] (a carry is meant to travel in a repository;
#: the seed-004 full-scale bed of 193,000 spheres makes checkpoints of about 150 MB).
DEFAULT_MAX_MB = 60.0


@dataclass(frozen=True)
class Carried:
    """One run, packed or unpacked: its ``folder`` (relative to the runs folder), case hash, simulated time ``t`` [s]
    of its checkpoint, the carry file, and what was done (``"packed"``, ``"unpacked"``, or why it was skipped)."""

    folder: str
    case_hash: str
    t: float
    carry: Path
    done: str

    def line(self) -> str:
        return f"{self.folder} (case {self.case_hash}, t = {self.t:.3f} s): {self.done}"


def _check_meta(meta: dict, path: Path, keys=CHECKPOINT_META, what: str = "not a run's checkpoint") -> None:
    """Refuse the state file at ``path`` when its metadata lacks any of ``keys``, naming them."""
    missing = [k for k in keys if k not in meta]
    if missing:
        raise WheelsoilInputError(f"{path} lacks {', '.join(missing)}: {what}")


def carry_path(dest: Path, case_hash: str) -> Path:
    """Where the carry of case ``case_hash`` lies in ``dest``."""
    return Path(dest) / f"{case_hash}{CARRY_SUFFIX}"


def unfinished_runs(runs: Path) -> list[Path]:
    """The run folders under ``runs`` (itself included) with a checkpoint and no finished result, sorted."""
    runs = Path(runs)
    found = [p.parent for p in runs.rglob(CHECKPOINT_NAME)] if runs.is_dir() else []
    return sorted(p for p in found if not (p / RESULT_NAME).is_file())


def pack_run(folder: Path, runs: Path, dest: Path) -> Carried:
    """Pack the checkpoint of the unfinished run in ``folder`` (under ``runs``) into ``dest``, compressed."""
    folder, runs = Path(folder), Path(runs)
    ckpt = folder / CHECKPOINT_NAME
    if (folder / RESULT_NAME).is_file():
        raise WheelsoilInputError(f"{folder} holds a finished run ({RESULT_NAME}): nothing to carry")
    if not ckpt.is_file():
        raise WheelsoilInputError(f"{folder} has no checkpoint ({CHECKPOINT_NAME}): nothing to carry")
    state, meta = load_state(ckpt)
    _check_meta(meta, ckpt)
    relative = folder.resolve().relative_to(runs.resolve()).as_posix()
    case_toml = (folder / "case.toml").read_text() if (folder / "case.toml").is_file() else ""
    out = carry_path(dest, meta["case_hash"])
    out.parent.mkdir(parents=True, exist_ok=True)
    save_state(out, state, {**{k: meta[k] for k in CHECKPOINT_META}, "folder": relative, "case_toml": case_toml},
               compression="gzip")
    return Carried(relative, meta["case_hash"], float(meta["t"]), out, "packed")


def _folder_under(runs: Path, relative: str, carry: Path) -> Path:
    """The folder ``relative`` that ``carry`` names, resolved under ``runs``; refused when it lies outside."""
    folder = (runs / relative).resolve()
    if runs.resolve() not in (folder, *folder.parents):
        raise WheelsoilInputError(f"{carry} names the folder {relative!r}, outside the runs folder {runs}")
    return folder


def _window_end(result: h5py.File) -> float:
    """The end [s] of a result's steady-state window (its summary's), the time a finished carry is shown at."""
    return float(result["summary"].attrs.get("window_end", 0.0)) if "summary" in result else 0.0


def finished_carry_path(dest: Path, case_hash: str) -> Path:
    """Where the carry of finished case ``case_hash`` lies in ``dest``."""
    return Path(dest) / f"{case_hash}{FINISHED_SUFFIX}"


def finished_runs(runs: Path) -> list[Path]:
    """The run folders under ``runs`` (itself included) with a finished result, sorted."""
    runs = Path(runs)
    return sorted(p.parent for p in runs.rglob(RESULT_NAME)) if runs.is_dir() else []


def _copy_compressed(src: h5py.Group, dst: h5py.Group, skip: tuple[str, ...] = ()) -> None:
    """Copy ``src``'s attributes, datasets (gzip) and groups into ``dst``, leaving out the members named in ``skip``."""
    for key, value in src.attrs.items():
        dst.attrs[key] = value
    for name, item in src.items():
        if name in skip:
            continue
        if isinstance(item, h5py.Group):
            _copy_compressed(item, dst.create_group(name))
        else:
            data = item[()]
            big = getattr(data, "size", 1) > 1
            d = dst.create_dataset(name, data=data, **({"compression": "gzip", "shuffle": True} if big else {}))
            for key, value in item.attrs.items():
                d.attrs[key] = value


def pack_finished(folder: Path, runs: Path, dest: Path) -> Carried:
    """Pack the finished result in ``folder`` (under ``runs``) into ``dest`` without its frames, compressed, with the
    run folder's path relative to ``runs`` (module docstring). Keeps a finished carry of the case already there."""
    folder, runs = Path(folder), Path(runs)
    result = folder / RESULT_NAME
    if not result.is_file():
        raise WheelsoilInputError(f"{folder} holds no finished run ({RESULT_NAME}): nothing to carry")
    relative = folder.resolve().relative_to(runs.resolve()).as_posix()
    with h5py.File(result, "r") as f:
        case_hash = str(f.attrs.get("case_hash", ""))
        if not case_hash or not f.attrs.get("complete", False):
            raise WheelsoilInputError(f"{result} is not a complete result with a case hash: not carried")
        t = _window_end(f)
        out = finished_carry_path(dest, case_hash)
        if out.is_file():
            return Carried(relative, case_hash, t, out, "kept: packed before")
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = out.with_name(f".{out.name}.partial")
        with h5py.File(tmp, "w") as g:
            _copy_compressed(f, g, skip=("frames",))
            g.attrs["folder"] = relative
    os.replace(tmp, out)
    return Carried(relative, case_hash, t, out, "packed (finished, without its frames)")


def _unpack_finished(carry: Path, runs: Path) -> Carried:
    """Put the finished carry ``carry`` back under ``runs`` as its folder's ``result.h5`` (frames empty), unless a
    finished result is there already."""
    carry, runs = Path(carry), Path(runs)
    with h5py.File(carry, "r") as f:
        relative, case_hash = str(f.attrs.get("folder", "")), str(f.attrs.get("case_hash", ""))
        if not relative or not case_hash or not f.attrs.get("complete", False):
            raise WheelsoilInputError(f"{carry} is not a carried finished run (wheelsoil carry pack --finished-in)")
        t = _window_end(f)
        folder = _folder_under(runs, relative, carry)
        said = lambda done: Carried(relative, case_hash, t, carry, done)  # noqa: E731
        if (folder / RESULT_NAME).is_file():
            return said("kept as it is: the run has finished here")
        folder.mkdir(parents=True, exist_ok=True)
        if f.attrs.get("case_toml") and not (folder / "case.toml").is_file():
            (folder / "case.toml").write_text(str(f.attrs["case_toml"]))
        tmp = partial_path(folder / RESULT_NAME)
        with h5py.File(tmp, "w") as g:
            _copy_compressed(f, g)
            del g.attrs["folder"]
            g.create_group("frames")
            g.require_group("run").attrs["frames_dropped"] = True
    os.replace(tmp, folder / RESULT_NAME)
    return said("unpacked (finished, without its frames)")


def pack_runs(runs: Path, dest: Path, *, max_mb: float = DEFAULT_MAX_MB,
              finished_in: tuple[str, ...] = ()) -> list[Carried]:
    """Pack every unfinished run under ``runs`` (:func:`unfinished_runs`) into ``dest``, and every finished run under
    the subfolders ``finished_in`` of ``runs`` (:func:`pack_finished`; one a case). Skipped, and said: a
    checkpoint over ``max_mb``, and one older than the carry of its case already in ``dest`` (a carry not unpacked
    here: packing never moves a run backwards). Carries in ``dest`` of runs that have finished under ``runs`` are
    removed (their results are here). Refuses two unfinished runs of one case under ``runs`` (their carries would
    share a name) before packing any."""
    runs, dest = Path(runs), Path(dest)
    if not runs.is_dir():
        raise WheelsoilInputError(f"the runs folder {runs} does not exist")
    if max_mb <= 0:
        raise WheelsoilInputError(f"--max-mb {max_mb} must be > 0")
    for sub in finished_in:
        if not (runs / sub).resolve().is_relative_to(runs.resolve()):
            raise WheelsoilInputError(f"--finished-in {sub!r} is outside the runs folder {runs}")
    folders = unfinished_runs(runs)
    by_case: dict[str, list[Path]] = {}
    metas = {}
    for folder in folders:
        meta = load_meta(folder / CHECKPOINT_NAME)
        _check_meta(meta, folder / CHECKPOINT_NAME)
        metas[folder] = meta
        by_case.setdefault(str(meta.get("case_hash")), []).append(folder)
    twice = {h: fs for h, fs in by_case.items() if len(fs) > 1}
    if twice:
        h, fs = next(iter(twice.items()))
        raise WheelsoilInputError(f"two unfinished runs of case {h} under {runs} ({', '.join(map(str, fs))}): "
                                  "pack each into its own folder")
    done = []
    for folder in folders:
        meta = metas[folder]
        size_mb = (folder / CHECKPOINT_NAME).stat().st_size / 1e6
        relative = folder.resolve().relative_to(runs.resolve()).as_posix()
        carry = carry_path(dest, meta["case_hash"])
        skipped = lambda why: Carried(relative, str(meta["case_hash"]), float(meta["t"]), carry, why)  # noqa: E731
        carried_t = float(load_meta(carry).get("t", -1.0)) if carry.is_file() else -1.0
        if size_mb > max_mb:
            done.append(skipped(f"not packed: its checkpoint is {size_mb:.0f} MB, over --max-mb {max_mb:g}"))
        elif carried_t > float(meta["t"]):
            done.append(skipped(f"not packed: the carry in {dest} is newer (t = {carried_t:.3f} s; unpack it first)"))
        else:
            done.append(pack_run(folder, runs, dest))
    for carry in sorted(dest.glob(f"*{CARRY_SUFFIX}")) if dest.is_dir() else []:
        meta = load_meta(carry)
        here = runs / str(meta.get("folder", ""))
        if (here / RESULT_NAME).is_file():
            carry.unlink()
            done.append(Carried(str(meta["folder"]), str(meta["case_hash"]), float(meta["t"]), carry,
                                "removed: the run has finished here"))
    packed_cases = {}
    for sub in finished_in:
        for folder in finished_runs(runs / sub):
            item = pack_finished(folder, runs, dest)
            if item.case_hash in packed_cases and packed_cases[item.case_hash] != item.folder:
                item = Carried(item.folder, item.case_hash, item.t, item.carry,
                               f"not packed: case {item.case_hash} finished in {packed_cases[item.case_hash]} too")
            packed_cases.setdefault(item.case_hash, item.folder)
            done.append(item)
    return done


def unpack_run(carry: Path, runs: Path) -> Carried:
    """Put the carried checkpoint ``carry`` back under ``runs`` (its folder as packed), unless that folder holds a
    finished run or a checkpoint as new or newer; the folder's partial result, if any, is removed (its frames do not
    belong to the carried state). A finished carry (``*.result.h5``) goes back as the folder's result."""
    carry, runs = Path(carry), Path(runs)
    if carry.name.endswith(FINISHED_SUFFIX):
        return _unpack_finished(carry, runs)
    state, meta = load_state(carry)
    _check_meta(meta, carry, CHECKPOINT_META + ("folder",), "not a carried run (wheelsoil carry pack)")
    relative, t = str(meta["folder"]), float(meta["t"])
    folder = _folder_under(runs, relative, carry)
    said = lambda done: Carried(relative, str(meta["case_hash"]), t, carry, done)  # noqa: E731
    if (folder / RESULT_NAME).is_file():
        return said("kept as it is: the run has finished here")
    if (folder / CHECKPOINT_NAME).is_file():
        here = float(load_meta(folder / CHECKPOINT_NAME).get("t", -1.0))
        if here >= t:
            return said(f"kept as it is: its checkpoint here is at t = {here:.3f} s")
    folder.mkdir(parents=True, exist_ok=True)
    if meta.get("case_toml") and not (folder / "case.toml").is_file():
        (folder / "case.toml").write_text(str(meta["case_toml"]))
    partial_path(folder / RESULT_NAME).unlink(missing_ok=True)
    save_state(folder / CHECKPOINT_NAME, state, {**{k: meta[k] for k in CHECKPOINT_META}, "frames_written": 0,
                                                 "frames_lost_before": t})
    return said("unpacked: resume it (wheelsoil run --resume, or its sweep)")


def unpack_runs(dest: Path, runs: Path) -> list[Carried]:
    """:func:`unpack_run` of every carry in ``dest`` into ``runs``: the finished ones first (a case finished is not
    resumed from an older checkpoint)."""
    dest = Path(dest)
    if not dest.is_dir():
        raise WheelsoilInputError(f"the carry folder {dest} does not exist")
    carries = sorted(dest.glob(f"*{FINISHED_SUFFIX}")) + sorted(dest.glob(f"*{CARRY_SUFFIX}"))
    return [unpack_run(c, runs) for c in carries]
