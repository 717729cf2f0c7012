"""One testbed run from a case: bed, wheel, rig, result file, checkpoints, plots and the render.

:func:`run_case` is what ``wheelsoil run`` and every sweep worker call. A run folder holds::

    result.h5, result.xdmf   the result (cases.results) and its ParaView sidecar
    series.csv               the time series, units in the column names
    summary.json             steady-state means, run figures, provenance, the case hash
    case.toml                the resolved case (every key), runnable as is
    series.png, final.png    the series plot and a render of the last state

While running, ``.result.h5.partial`` collects frames and ``.checkpoint.h5`` the latest state; a run
killed after a checkpoint continues with ``resume=True`` (``--resume``) and ends with the same result
as a run that was never interrupted (bit for bit on the same machine and backend).

A checkpoint's metadata: ``case_hash``, ``t`` [s], ``checkpoints`` and ``frames`` (the frames the schedule has taken,
which times the next one) and ``frames_written`` (those the partial file holds; absent in checkpoints written before
runs could be carried: the same as ``frames``). A checkpoint carried to another machine without its partial file
(:mod:`.carry`) has ``frames_written`` 0 and ``frames_lost_before`` [s], its time: the run resumes into a new partial
file, and its result's ``run`` info keeps ``frames_lost_before`` (its frames start there; series and summary are
whole).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path

from wheelsoil.awake import keep_cores_awake, requested_by_environment
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.provenance import atomic_output, provenance, writable_folder
from wheelsoil.state_file import load_state, save_state

from . import build
from .results import ResultWriter, partial_path
from .schema import CaseFile, case_to_toml

RESULT_NAME = "result.h5"
CHECKPOINT_NAME = ".checkpoint.h5"


@dataclass
class RunOutcome:
    """What a run wrote: the folder, the result file and the in-memory testbed result."""

    out: Path
    result_path: Path
    testbed_result: object
    resumed_from: float | None = None


# -------------------------------------------------------------------- checkpoint files
#: Write a testbed state (nested dict of arrays and scalars) and its ``meta`` atomically; read one back.
save_checkpoint, load_checkpoint = save_state, load_state


# -------------------------------------------------------------------- the run
def _checkpoint_to_resume(out: Path, case_hash: str, *, resume: bool, restart: bool) -> tuple[dict | None, dict]:
    """(state, meta) of the checkpoint in ``out`` to resume from, or (None, {}) for a fresh run (then the folder's
    unfinished files are cleared). Refuses, naming what to do: --resume without a checkpoint or with another case's,
    an unfinished run's folder without --resume or --restart, and both flags at once."""
    result_path, ckpt_path = out / RESULT_NAME, out / CHECKPOINT_NAME
    if resume and restart:
        raise WheelsoilInputError("--resume and --restart exclude each other")
    if resume:
        if not ckpt_path.is_file():
            done = " (the run there finished)" if result_path.is_file() else ""
            raise WheelsoilInputError(f"nothing to resume in {out}: no checkpoint ({CHECKPOINT_NAME}){done}; "
                                      "run without --resume")
        state, meta = load_checkpoint(ckpt_path)
        if meta.get("case_hash") != case_hash:
            raise WheelsoilInputError(
                f"the checkpoint in {out} is of another case (hash {meta.get('case_hash')}, this case {case_hash}); "
                "resume with the same case file and --set overrides, or run without --resume")
        return state, meta
    if ckpt_path.is_file() and not restart:
        _, meta = load_checkpoint(ckpt_path)
        raise WheelsoilInputError(
            f"{out} holds an unfinished run with a checkpoint at t = {meta.get('t', 0.0):.3f} s: --resume "
            "continues it, --restart discards it")
    ckpt_path.unlink(missing_ok=True)
    partial_path(result_path).unlink(missing_ok=True)
    return None, {}


def run_case(case: CaseFile, out: str | Path, *, arch: str | None = None, resume: bool = False,
             restart: bool = False, progress: bool = False, console=None,
             bed_cache: str | Path | None = None, plan: build.RunPlan | None = None) -> RunOutcome:
    """Run ``case`` and write its folder ``out`` (see the module docstring).

    ``resume``: continue from ``out``'s checkpoint (an error names what is missing or different).
    ``restart``: discard the checkpoint of an unfinished run in ``out`` and start afresh; without it
    (or ``resume``) such a folder is refused, so that no progress is thrown away by accident.
    ``bed_cache``: the bed cache folder (default ``WHEELSOIL_CACHE`` or ``~/.cache/wheelsoil``).
    ``plan``: the case's :class:`~wheelsoil.cases.build.RunPlan` if the caller made it (default: made here, once).
    Raises :class:`~wheelsoil.errors.WheelsoilInputError` for bad input and
    :class:`~wheelsoil.errors.SimulationUnstableError` when the run blows up; a run that fails after
    a checkpoint keeps its partial files, so that ``resume=True`` can continue it.
    """
    from wheelsoil.coupling.run_summary import SERIES_UNITS
    from wheelsoil.coupling.testbed import Testbed
    from wheelsoil.granular import prepare_bed

    say = console.print if console is not None else (lambda *a, **k: None)
    plan = plan or build.plan(case)
    out = writable_folder(out, "--out", need_bytes=plan.output_bytes)
    result_path = out / RESULT_NAME
    ckpt_path = out / CHECKPOINT_NAME
    case_hash = case.case_hash()
    ckpt_state, meta = _checkpoint_to_resume(out, case_hash, resume=resume, restart=restart)

    bed = prepare_bed(plan.bed, cache_dir=bed_cache, progress=progress, arch=arch)
    say(f"[bold]{bed.summary()}[/bold] ({'reused from cache' if bed.meta.get('from_cache') else 'prepared'})")
    spec = plan.test
    bench = Testbed(bed, plan=plan.rig, arch=arch)
    say(f"wheel {case.wheel.preset}: {bench.mesh.n_elements} elements, {bench.wheel_mass:.1f} kg, "
        f"{'rigid' if spec.rigid else 'flexible'}; DEM step {bench.dt:.3g} s; slip {spec.slip:g}, "
        f"steering {spec.slip_angle:g} deg, W = {spec.load:g} N")

    prov = provenance()
    attrs = {"case_toml": case_to_toml(case), "case_name": case.name, "case_hash": case_hash,
             "seed": case.case.seed, "bed": bed.summary(), **prov}
    nodes0 = bench.mesh.nodes.copy()
    mesh = {"nodes0": nodes0, "triangles": bench.mesh.triangles, "beams": bench.mesh.beams.reshape(-1, 2)}
    frame_dt, ckpt_dt = case.output.frame_interval, case.output.checkpoint_interval
    counters = {"frames": 0, "checkpoints": 0}
    resumed_from, frames_lost_before, kept_frames = None, meta.get("frames_lost_before"), None
    if ckpt_state is not None:
        counters["frames"], counters["checkpoints"] = int(meta["frames"]), int(meta["checkpoints"])
        kept_frames = int(meta.get("frames_written", meta["frames"]))
        if frames_lost_before is not None and kept_frames == 0 and not partial_path(result_path).is_file():
            kept_frames = None  # carried here without its frames: a new partial file
        bench.restore_state(ckpt_state)
        resumed_from = float(bench.scene.time)
        lost = f"; its frames before t = {frames_lost_before:.3f} s were not carried" if frames_lost_before else ""
        say(f"resuming from the checkpoint at t = {resumed_from:.3f} s ({kept_frames or 0} frames kept{lost})")
    writer = ResultWriter(result_path, attrs, mesh, resume_frames=kept_frames)

    def add_frame(tb) -> None:
        nodes = tb.structure.positions()
        writer.add_frame(tb.scene.time, {"position": tb.scene.positions, "velocity": tb.scene.velocities,
                                         "radius": tb.scene.radii}, nodes, tb.deformation(nodes))
        counters["frames"] += 1

    def on_sample(tb) -> None:
        t = tb.scene.time
        if frame_dt > 0 and t >= (counters["frames"] + 1) * frame_dt - 1e-12:
            add_frame(tb)
        if ckpt_dt > 0 and t >= (counters["checkpoints"] + 1) * ckpt_dt - 1e-12:
            counters["checkpoints"] = int(math.floor(t / ckpt_dt + 1e-9))
            writer.flush()
            ckpt_meta = {"case_hash": case_hash, "frames": counters["frames"], "frames_written": writer.n_frames,
                         "checkpoints": counters["checkpoints"], "t": t}
            if frames_lost_before is not None:
                ckpt_meta["frames_lost_before"] = frames_lost_before
            save_checkpoint(ckpt_path, tb.state(), ckpt_meta)

    try:
        with keep_cores_awake(requested_by_environment()):  # opt-in: WHEELSOIL_KEEP_CORES_AWAKE=1
            result = bench.run(progress=progress, on_sample=on_sample)
        add_frame(bench)
    except BaseException:
        writer.abandon()
        if not ckpt_path.is_file():
            partial_path(result_path).unlink(missing_ok=True)
        raise
    info = dict(result.info)
    if resumed_from is not None:
        info["resumed_from"] = resumed_from
    if frames_lost_before is not None:
        info["frames_lost_before"] = float(frames_lost_before)
    writer.finish(result.series, SERIES_UNITS, result.summary, info, result.stages)
    ckpt_path.unlink(missing_ok=True)
    write_run_folder(out, case, result, prov)
    return RunOutcome(out=out, result_path=result_path, testbed_result=result, resumed_from=resumed_from)


def write_run_folder(out: Path, case: CaseFile, result, prov: dict) -> list[Path]:
    """series.csv, summary.json, case.toml, series.png and (if the case asks) final.png."""
    from wheelsoil.coupling.run_summary import SERIES_UNITS

    names = list(SERIES_UNITS)
    rows = [",".join(f"{n}[{SERIES_UNITS[n]}]" for n in names)]
    rows += [",".join(f"{result.series[n][k]:.9g}" for n in names) for k in range(len(result.series["t"]))]
    written = []
    with atomic_output(out / "series.csv") as tmp:
        tmp.write_text("\n".join(rows) + "\n")
    written.append(out / "series.csv")
    summary = {"case": case.name, "case_hash": case.case_hash(), "summary": result.summary.to_dict(), "run": result.info,
               "testbed": result.spec.to_dict(), "bed": result.bed_summary, "provenance": prov}
    if len(result.stages) > 1:  # a drive of several stages: each stage's summary, in order (the last is "summary")
        summary["stages"] = [st.to_dict() for st in result.stages]
    with atomic_output(out / "summary.json") as tmp:
        tmp.write_text(json.dumps(summary, indent=2, default=str))
    written.append(out / "summary.json")
    with atomic_output(out / "case.toml") as tmp:
        tmp.write_text(case_to_toml(case))
    written.append(out / "case.toml")
    from .plots import plot_series

    written.append(plot_series(result, out / "series.png", case.name))
    if case.output.render:
        from .render import render_testbed

        with atomic_output(out / "final.png") as tmp:
            image = tmp.with_suffix(".png")  # the renderer picks the format from the suffix
            try:
                render_testbed(result, image)
                os.replace(image, tmp)
            finally:
                image.unlink(missing_ok=True)
        written.append(out / "final.png")
    return written
