"""One run from a case file: result layout, round trip case -> result -> case, atomic write under a kill,
resume equal to an uninterrupted run, the XDMF sidecar, renders of frames and animations."""

import json
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from wheelsoil.cases.cli import EXIT_INPUT, main
from wheelsoil.cases.results import load_result, partial_path
from wheelsoil.cases.run import CHECKPOINT_NAME, RESULT_NAME, run_case
from wheelsoil.cases.schema import load_case
from wheelsoil.coupling.run_summary import SERIES_UNITS, STEADY_QUANTITIES
from wheelsoil.errors import WheelsoilInputError

#: The mini case, short: about 0.32 s simulated (lowering, settling, 0.15 s of driving), frames every
#: 0.05 s and checkpoints every 0.1 s.
MINI = ["test.drive_time=0.15", "test.stop_when_steady=false", "output.average_time=0.05",
        "output.frame_interval=0.05", "output.checkpoint_interval=0.1", "output.render=false"]


@pytest.fixture(scope="module")
def reference(bed_cache, tmp_path_factory):
    """The mini case run uninterrupted."""
    case = load_case("mini-1g-steer", MINI)
    out = tmp_path_factory.mktemp("reference")
    outcome = run_case(case, out)
    return case, out, outcome


def test_result_file_follows_the_architecture_layout(reference):
    case, out, outcome = reference
    assert sorted(p.name for p in out.iterdir()) == ["case.toml", "result.h5", "result.xdmf", "series.csv",
                                                     "series.png", "summary.json"]
    with h5py.File(out / RESULT_NAME, "r") as f:
        for key in ("case_toml", "version", "git_rev", "taichi_version", "arch", "seed", "created"):
            assert key in f.attrs, key
        assert f.attrs["complete"] and f.attrs["arch"] == "cpu"
        for name, unit in SERIES_UNITS.items():
            assert f["series"][name].attrs["units"] == unit
            assert f["series"][name].shape == f["series"]["t"].shape
        for q in STEADY_QUANTITIES:
            assert f"{q}_mean" in f["summary"].attrs and f"{q}_std" in f["summary"].attrs
        assert f["summary"].attrs["window_end"] > f["summary"].attrs["window_start"]
        assert f["mesh/nodes0"].shape[1] == 3 and f["mesh/triangles"].shape[1] == 3
        frames = sorted(f["frames"])
        t = np.array([f["frames"][k].attrs["t"] for k in frames])
        radius = [f["frames"][k]["particles/radius"] for k in frames]
        for a, b in zip(radius[:-1], radius[1:]):  # one copy while the spheres are the same (the patch renews some)
            assert (a.id == b.id) == (a.shape == b.shape and np.array_equal(a[()], b[()]))
        for k in frames:
            n = f["frames"][k]["particles/position"].shape[0]
            assert f["frames"][k]["particles/velocity"].shape == (n, 3) == (f["frames"][k]["particles/radius"].shape[0], 3)
        assert f["frames"][frames[-1]]["wheel/nodes"].shape == f["mesh/nodes0"].shape
    # what the readers of results (validation's periodic report, the throughput benchmark) take from the run info
    from wheelsoil.cases.results import load_result
    from wheelsoil.validation.periodic import drive_start

    info = load_result(out / RESULT_NAME).info
    assert 0 < drive_start(info) < info["simulated_seconds"] and "t_hold" in info and "t_wind_up" in info
    # a frame at the first sample past each multiple of 0.05 s, and the last state
    dt = case.output.sample_interval
    expected = [k * 0.05 for k in range(1, int(t[-1] / 0.05) + 1)]
    assert np.all(np.diff(t) > 0)
    assert np.allclose(t[:-1], expected[: len(t) - 1], atol=1.01 * dt)
    assert t[-1] == pytest.approx(outcome.testbed_result.series["t"][-1])


def test_round_trip_case_to_result_to_case(reference, tmp_path):
    case, out, outcome = reference
    result = load_result(out)
    assert result.case == case
    assert result.attrs["case_hash"] == case.case_hash()
    assert load_case(out / "case.toml") == case  # the run folder's case.toml runs the same case
    for name in SERIES_UNITS:
        np.testing.assert_array_equal(result.series[name], outcome.testbed_result.series[name])
    assert result.steady("drawbar_pull") == outcome.testbed_result.summary.drawbar_pull.mean
    frame = result.to_dataframe()
    assert "drawbar_pull [N]" in frame.columns and frame.index.name == "t [s]"
    assert len(frame) == len(result.series["t"])
    row = result.summary_row()
    assert row["case"] == "mini-1g-steer" and row["vertical_force_mean"] == result.steady("vertical_force")


def test_xdmf_sidecar_opens_in_vtks_xdmf_reader(reference):
    vtk = pytest.importorskip("vtk")
    _, out, _ = reference
    result = load_result(out)
    reader = vtk.vtkXdmfReader()
    reader.SetFileName(str(out / "result.xdmf"))
    reader.UpdateInformation()
    times = reader.GetOutputInformation(0).Get(vtk.vtkStreamingDemandDrivenPipeline.TIME_STEPS())
    np.testing.assert_allclose(times, result.frame_times)
    reader.UpdateTimeStep(times[-1])  # the last frame (a moving patch changes the sphere count between frames)
    blocks = reader.GetOutputDataObject(0)
    last = result.frame(-1)
    names = [blocks.GetMetaData(i).Get(vtk.vtkCompositeDataSet.NAME()) for i in range(blocks.GetNumberOfBlocks())]
    # the reader names a time step's blocks "particles[k]", "wheel[k]"
    particles, wheel = (blocks.GetBlock([m.split("[")[0] for m in names].index(n)) for n in ("particles", "wheel"))
    assert particles.GetNumberOfPoints() == len(last["position"])
    assert particles.GetPointData().GetArray("velocity").GetNumberOfComponents() == 3
    assert wheel.GetNumberOfCells() == len(last["triangles"])
    assert wheel.GetPointData().GetArray("deflection") is not None


@pytest.mark.slow
def test_a_killed_run_leaves_no_finished_file_and_resume_equals_the_uninterrupted_run(reference, tmp_path):
    case, ref_out, _ = reference
    out = tmp_path / "killed"
    cmd = [sys.executable, "-m", "wheelsoil.cases.cli", "run", "mini-1g-steer", "--out", str(out)]
    for item in MINI:
        cmd += ["--set", item]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 300
    while not (out / CHECKPOINT_NAME).exists():
        assert proc.poll() is None, "the run ended before its first checkpoint"
        assert time.monotonic() < deadline, "no checkpoint within 300 s"
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    # nothing that looks finished: no result file, and the partial one says it is incomplete
    assert not (out / RESULT_NAME).exists()
    with h5py.File(partial_path(out / RESULT_NAME), "r") as f:
        assert not f.attrs["complete"]
    with pytest.raises(WheelsoilInputError, match="a partial file exists: the run did not finish"):
        load_result(out)
    # a plain rerun would throw the progress away: it is refused and says how to go on
    with pytest.raises(WheelsoilInputError, match="holds an unfinished run with a checkpoint at t = 0.1.* --resume"):
        run_case(case, out)
    # another case cannot resume it
    with pytest.raises(WheelsoilInputError, match="the checkpoint in .* is of another case"):
        run_case(load_case("mini-1g-steer", MINI + ["test.slip=0.4"]), out, resume=True)
    outcome = run_case(case, out, resume=True)
    assert outcome.resumed_from is not None and outcome.resumed_from > 0.09
    a, b = load_result(ref_out), load_result(out)
    for name in SERIES_UNITS:
        np.testing.assert_array_equal(b.series[name], a.series[name], err_msg=name)
    np.testing.assert_array_equal(b.frame_times, a.frame_times)
    for k in range(len(a.frame_times)):
        np.testing.assert_array_equal(b.frame(k)["position"], a.frame(k)["position"])
        np.testing.assert_array_equal(b.frame(k)["wheel_nodes"], a.frame(k)["wheel_nodes"])
    assert not (out / CHECKPOINT_NAME).exists() and not partial_path(out / RESULT_NAME).exists()


class _StopAfterCheckpoint(Exception):
    """Raised by the test's checkpoint writer once a run has kept a checkpoint with frames before it."""


@pytest.mark.slow  # a mini run and a bed prepared again: 1-2 min
def test_a_run_carried_without_its_frames_ends_as_the_uninterrupted_run_on_a_bed_prepared_again(
        reference, tmp_path, monkeypatch):
    from wheelsoil.cases import run as run_module
    from wheelsoil.cases.carry import CARRY_SUFFIX, pack_runs, unpack_runs
    from wheelsoil.cases.schema import case_to_toml

    case, ref_out, _ = reference
    here = tmp_path / "here"
    out = here / "sweep" / "cases" / case.case_hash()
    write = run_module.save_checkpoint

    def write_then_stop(path, state, meta):  # the machine goes away after the checkpoint at t = 0.2 s
        write(path, state, meta)
        if meta["t"] > 0.19:
            raise _StopAfterCheckpoint

    monkeypatch.setattr(run_module, "save_checkpoint", write_then_stop)
    with pytest.raises(_StopAfterCheckpoint):
        run_case(case, out)
    monkeypatch.undo()
    (out / "case.toml").write_text(case_to_toml(case))  # as a sweep's case folder holds it
    with h5py.File(partial_path(out / RESULT_NAME), "r") as f:
        assert len(f["frames"]) >= 3  # frames the carry leaves behind

    carried = tmp_path / "carried"
    [packed] = pack_runs(here, carried)
    assert packed.done == "packed" and packed.carry == carried / f"{case.case_hash()}{CARRY_SUFFIX}"
    assert packed.folder == f"sweep/cases/{case.case_hash()}"
    assert packed.carry.stat().st_size < (out / CHECKPOINT_NAME).stat().st_size  # compressed

    there = tmp_path / "there"  # the other machine: another runs folder and another bed cache
    [unpacked] = unpack_runs(carried, there)
    folder = there / packed.folder
    assert unpacked.done.startswith("unpacked") and unpacked.t == pytest.approx(packed.t)
    assert sorted(p.name for p in folder.iterdir()) == [CHECKPOINT_NAME, "case.toml"]
    assert load_case(folder / "case.toml") == case
    outcome = run_case(case, folder, resume=True, bed_cache=tmp_path / "bed-prepared-again")
    assert outcome.resumed_from == pytest.approx(packed.t)

    a, b = load_result(ref_out), load_result(folder)
    for name in SERIES_UNITS:
        np.testing.assert_array_equal(b.series[name], a.series[name], err_msg=name)
    assert json.dumps(b.summary.to_dict(), sort_keys=True) == json.dumps(a.summary.to_dict(), sort_keys=True)
    assert b.info["frames_lost_before"] == pytest.approx(packed.t)
    after = a.frame_times > packed.t + 1e-12
    np.testing.assert_array_equal(b.frame_times, a.frame_times[after])
    for k, ref_k in enumerate(np.flatnonzero(after)):
        np.testing.assert_array_equal(b.frame(k)["position"], a.frame(int(ref_k))["position"])

    # nothing moves backwards: the finished run is kept, and packing removes the carry whose run has finished
    assert unpack_runs(carried, there)[0].done == "kept as it is: the run has finished here"
    assert [c.done for c in pack_runs(there, carried)] == ["removed: the run has finished here"]
    assert not list(carried.iterdir())


def test_carry_refuses_what_it_cannot_carry_and_never_packs_over_a_newer_carry(tmp_path):
    from wheelsoil.cases.carry import pack_run, pack_runs, unpack_run
    from wheelsoil.state_file import save_state

    runs = tmp_path / "runs"
    with pytest.raises(WheelsoilInputError, match="the runs folder .* does not exist"):
        pack_runs(runs, tmp_path / "carried")
    old, new = runs / "a", tmp_path / "elsewhere" / "a"
    for folder, t in ((old, 1.0), (new, 2.0)):
        folder.mkdir(parents=True)
        save_state(folder / CHECKPOINT_NAME, {"x": np.arange(2000.0)}, {"case_hash": "c0ffee", "t": t,
                                                                       "checkpoints": 4, "frames": 20})
    with pytest.raises(WheelsoilInputError, match="must be > 0"):
        pack_runs(runs, tmp_path / "carried", max_mb=0)
    [skipped] = pack_runs(runs, tmp_path / "carried", max_mb=1e-3)
    assert skipped.done.startswith("not packed: its checkpoint is 0 MB, over --max-mb 0.001")
    pack_runs(new.parent, tmp_path / "carried")  # the run at t = 2 s, packed on another machine
    [kept] = pack_runs(runs, tmp_path / "carried")  # this machine's older checkpoint does not replace it
    assert kept.done.startswith("not packed: the carry in") and "t = 2.000 s" in kept.done
    assert unpack_run(tmp_path / "carried" / "c0ffee.carry.h5", runs).done == "unpacked: resume it (wheelsoil run " \
        "--resume, or its sweep)"
    assert unpack_run(tmp_path / "carried" / "c0ffee.carry.h5", runs).done == \
        "kept as it is: its checkpoint here is at t = 2.000 s"
    (old / RESULT_NAME).write_text("finished")
    with pytest.raises(WheelsoilInputError, match="holds a finished run"):
        pack_run(old, runs, tmp_path / "carried")
    (runs / "b").mkdir()
    with pytest.raises(WheelsoilInputError, match="has no checkpoint"):
        pack_run(runs / "b", runs, tmp_path / "carried")
    save_state(runs / "b" / CHECKPOINT_NAME, {}, {"samples": 10, "t": 0.2})  # a soil-lab press's, say
    with pytest.raises(WheelsoilInputError, match="lacks case_hash, checkpoints, frames: not a run's checkpoint"):
        pack_runs(runs, tmp_path / "carried")
    save_state(tmp_path / "stray.carry.h5", {}, {"case_hash": "c0ffee", "t": 1.0, "checkpoints": 1, "frames": 1,
                                                  "folder": "../../outside"})
    with pytest.raises(WheelsoilInputError, match="outside the runs folder"):
        unpack_run(tmp_path / "stray.carry.h5", runs)


def test_a_finished_run_carried_without_its_frames_reads_back_as_the_same_result(reference, tmp_path):
    import shutil

    from wheelsoil.cases.carry import FINISHED_SUFFIX, pack_runs, unpack_runs

    case, ref_out, _ = reference
    here = tmp_path / "here"
    folder = here / "sweep" / "cases" / case.case_hash()
    shutil.copytree(ref_out, folder)
    carried = tmp_path / "carried"
    with pytest.raises(WheelsoilInputError, match="outside the runs folder"):
        pack_runs(here, carried, finished_in=("../elsewhere",))
    assert pack_runs(here, carried) == []  # finished runs travel only on request
    [packed] = pack_runs(here, carried, finished_in=("sweep",))
    assert packed.done == "packed (finished, without its frames)"
    assert packed.carry == carried / f"{case.case_hash()}{FINISHED_SUFFIX}"
    assert packed.carry.stat().st_size < (folder / RESULT_NAME).stat().st_size / 3  # the frames were most of it
    assert [c.done for c in pack_runs(here, carried, finished_in=("sweep",))] == ["kept: packed before"]

    there = tmp_path / "there"
    [unpacked] = unpack_runs(carried, there)
    assert unpacked.done == "unpacked (finished, without its frames)"
    a, b = load_result(ref_out), load_result(there / packed.folder)
    for name in SERIES_UNITS:
        np.testing.assert_array_equal(b.series[name], a.series[name], err_msg=name)
    assert json.dumps(b.summary.to_dict(), sort_keys=True) == json.dumps(a.summary.to_dict(), sort_keys=True)
    assert b.case == a.case and len(b.frame_times) == 0 and b.info["frames_dropped"]
    assert load_case(there / packed.folder / "case.toml") == case
    assert unpack_runs(carried, there)[0].done == "kept as it is: the run has finished here"


def test_carry_command_says_what_it_did(tmp_path, capsys):
    assert main(["carry", "pack", str(tmp_path), "--to", str(tmp_path / "c")]) == 0
    assert "no unfinished run with a checkpoint under" in capsys.readouterr().out
    assert main(["carry", "unpack", str(tmp_path / "missing"), "--into", str(tmp_path)]) == EXIT_INPUT
    assert "wheelsoil carry: error: the carry folder" in capsys.readouterr().err


def test_resume_without_a_checkpoint_is_refused(tmp_path, capsys):
    rc = main(["run", "mini-1g-steer", "--resume", "--out", str(tmp_path / "empty")])
    assert rc == EXIT_INPUT
    assert "nothing to resume" in capsys.readouterr().err


def _non_blank(image: np.ndarray) -> bool:
    colours = np.unique(image.reshape(-1, image.shape[-1])[::97], axis=0)
    return image.std() > 10 and len(colours) > 50


@pytest.mark.slow  # 10 s of rendering; the layout and resume tests stay fast
def test_render_of_a_frame_and_an_animation(reference, tmp_path):
    import imageio.v2 as imageio

    _, out, _ = reference
    result = load_result(out)
    png = tmp_path / "frame.png"
    assert main(["render", str(out), "--frame", "1", "--size", "640", "480", "--out", str(png)]) == 0
    image = imageio.imread(png)
    assert image.shape[:2] == (480, 640) and _non_blank(image[..., :3])
    gif = tmp_path / "run.gif"
    assert main(["render", str(out / RESULT_NAME), "--animate", "--size", "320", "240", "--out", str(gif)]) == 0
    frames = imageio.mimread(gif)
    assert len(frames) == len(result.frame_times)
    assert all(f.shape[:2] == (240, 320) for f in frames)
    assert not np.array_equal(frames[0], frames[-1])  # the wheel moved
    assert main(["render", str(out), "--animate", "--out", str(tmp_path / "run.avi")]) == EXIT_INPUT
