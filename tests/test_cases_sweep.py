"""Batch sweeps: grid and rows, a small sweep with one deliberately failing case, skip and retry on a
second run, the summary table and figures, and a sweep on a dask.distributed cluster."""

import json

import pandas as pd
import pytest

from wheelsoil.cases.cli import EXIT_OK, EXIT_SWEEP_FAILED, main
from wheelsoil.cases.results import load_result
from wheelsoil.cases.schema import CaseError
from wheelsoil.cases.sweep import load_sweep, run_sweep

COMMON = 'set = { "output.render" = false, "output.frame_interval" = 0.0, "output.checkpoint_interval" = 0.0, ' \
         '"test.drive_time" = 0.1, "test.stop_when_steady" = false, "output.average_time" = 0.05 }'


def write(tmp_path, text, name="sweep.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_grid_times_rows_names_and_folders(tmp_path):
    sweep = load_sweep("seed004-figures", tmp_path / "s")
    assert len(sweep.cases) == 3 * 6 * 5  # 1g with 3000 N and 500 N, 1/6 g with 500 N; slip x steering angle
    assert sweep.swept_keys == ["test.slip", "test.slip_angle", "soil.gravity", "test.load"]
    moon = [c for c in sweep.cases if c.values["soil.gravity"] == "moon"]
    assert len(moon) == 30 and all(c.case.test.load == 500.0 for c in moon)
    assert sorted({c.case.test.slip_angle for c in sweep.cases}) == [0, 5, 10, 15, 20]
    assert all(c.case.output.render is False for c in sweep.cases)
    assert len({c.folder for c in sweep.cases}) == 90  # one folder per case hash
    assert sweep.cases[0].folder.parent == tmp_path / "s" / "cases"
    assert sweep.cases[0].name == "seed004-figures-gravityearth-load3000-slip0.1-slip_angle0"


def test_bad_sweep_files_name_the_problem(tmp_path):
    with pytest.raises(CaseError, match="unknown key test.slp; did you mean test.slip"):
        load_sweep(write(tmp_path, '[sweep]\nbase = "mini-1g-steer"\n[sweep.grid]\n"test.slp" = [0.1]\n'))
    with pytest.raises(CaseError, match=r"case 1 \(test.slip=1.2\)"):
        load_sweep(write(tmp_path, '[sweep]\nbase = "mini-1g-steer"\n[sweep.grid]\n"test.slip" = [0.1, 1.2]\n'))
    with pytest.raises(CaseError, match="cases 0 and 1 are the same case"):
        load_sweep(write(tmp_path, '[sweep]\nbase = "mini-1g-steer"\n[[sweep.rows]]\n"test.slip" = 0.2\n'
                                   '[[sweep.rows]]\n"test.slip" = 0.2\n'))
    with pytest.raises(CaseError, match="sweep.basis"):
        load_sweep(write(tmp_path, '[sweep]\nbasis = "mini-1g-steer"\n'))
    with pytest.raises(CaseError, match="no case file or preset"):
        load_sweep(write(tmp_path, '[sweep]\nbase = "no-such-case"\n'))


@pytest.mark.slow
def test_a_sweep_with_one_failing_case_finishes_the_others_then_skips_and_retries(bed_cache, tmp_path, capsys):
    # the middle row cannot finish: its wheel may not wind up by more than 0.001 rad (found while it drives)
    path = write(tmp_path, f'[sweep]\nname = "three"\nbase = "mini-1g-steer"\n{COMMON}\n'
                           '[[sweep.rows]]\n"test.slip" = 0.2\n'
                           '[[sweep.rows]]\n"test.slip" = 0.4\n"test.max_wind_up" = 0.001\n'
                           '[[sweep.rows]]\n"test.slip" = 0.5\n')
    out = tmp_path / "out"
    assert main(["batch", str(path), "--out", str(out), "--workers", "2"]) == EXIT_SWEEP_FAILED
    text = capsys.readouterr().out
    assert "2 run, 0 skipped (finished before), 1 failed" in text
    status = json.loads((out / "status.json").read_text())
    failed = [v for v in status.values() if v["status"] == "failed"]
    assert len(failed) == 1 and "past test.max_wind_up = 0.001 rad" in failed[0]["error"]
    assert failed[0]["values"] == {"test.slip": 0.4, "test.max_wind_up": 0.001}
    csv = pd.read_csv(out / "summary.csv")
    parquet = pd.read_parquet(out / "summary.parquet")
    assert sorted(csv["test.slip"]) == [0.2, 0.5] and len(parquet) == 2
    pd.testing.assert_frame_equal(csv, parquet, check_dtype=False)
    for case in csv.itertuples():
        result = load_result(out / "cases" / case.case_hash)
        assert result.steady("drawbar_pull") == pytest.approx(case.drawbar_pull_mean, rel=1e-12)
    for name in ("sinkage", "drawbar_pull", "lateral_force"):
        assert (out / f"figure_{name}.png").stat().st_size > 10_000
    # the validation workflow reads the finished cases as a dataset (wheelsoil validate SWEEP_FOLDER), steady runs
    # only: these drove 0.1 s, too short for the detector, so the folder is refused; marked steady (a copy of the
    # summary), they are read
    from wheelsoil.errors import WheelsoilInputError
    from wheelsoil.validation.measured import load_measurements

    assert not csv["steady"].any()
    with pytest.raises(WheelsoilInputError, match="none of its 2 runs reached a steady state"):
        load_measurements(out)
    marked = tmp_path / "marked"
    marked.mkdir()
    csv.assign(steady=True).to_csv(marked / "summary.csv", index=False)
    data = load_measurements(marked)
    order = sorted(range(len(data)), key=lambda k: data.slip[k])
    assert list(data.slip[order]) == [0.2, 0.5] and set(data.group) == {"1g"}
    assert list(data.responses["drawbar_pull"][order]) == list(csv.sort_values("test.slip")["drawbar_pull_mean"])
    assert list(data.responses["sinkage"][order]) == list(csv.sort_values("test.slip")["tread_sinkage_mean"])
    assert set(data.radius) == {0.15} and set(data.grouser_count) == {8.0}
    # again: the finished cases are skipped (their results untouched), the failed one is retried
    sweep = load_sweep(path, out)
    stamps = {c.folder: (c.folder / "result.h5").stat().st_mtime_ns for c in sweep.cases if c.finished}
    status = run_sweep(sweep, workers=2)
    assert sorted(v["status"] for v in status.values()) == ["failed", "skipped (finished before)",
                                                            "skipped (finished before)"]
    assert all((folder / "result.h5").stat().st_mtime_ns == t for folder, t in stamps.items())


@pytest.mark.slow
def test_a_sweep_runs_on_a_dask_cluster(bed_cache, tmp_path):
    distributed = pytest.importorskip("distributed")
    path = write(tmp_path, f'[sweep]\nbase = "mini-1g-steer"\n{COMMON}\n[sweep.grid]\n"test.slip" = [0.3]\n')
    out = tmp_path / "dask"
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        assert main(["batch", str(path), "--out", str(out), "--scheduler", cluster.scheduler_address]) == EXIT_OK
    (case,) = load_sweep(path, out).cases
    assert case.finished
    assert load_result(case.folder).case == case.case
    assert len(pd.read_parquet(out / "summary.parquet")) == 1


def test_an_unreachable_scheduler_is_an_input_error(tmp_path, capsys):
    pytest.importorskip("distributed")
    path = write(tmp_path, f'[sweep]\nbase = "mini-1g-steer"\n{COMMON}\n')
    assert main(["batch", str(path), "--out", str(tmp_path / "x"), "--scheduler", "tcp://127.0.0.1:9"]) == 2
    assert "cannot reach the dask scheduler" in capsys.readouterr().err
    assert main(["batch", str(path), "--out", str(tmp_path / "y"), "--scheduler", "tcp://127.0.0.1"]) == 2
    assert "not an address such as tcp://host:8786" in capsys.readouterr().err


def test_the_summary_follows_each_finished_case(tmp_path, monkeypatch):
    """A sweep of hours writes its tables after each finished case, not only at its end: one killed half-way keeps
    a summary of what finished (what ``validate --model`` reads); a failed case writes none."""
    import wheelsoil.cases.sweep as sweep_module

    path = write(tmp_path, f'[sweep]\nbase = "mini-1g-steer"\n{COMMON}\n[sweep.grid]\n"test.slip" = [0.1, 0.2, 0.3]\n')
    sweep = load_sweep(path, tmp_path / "out")
    outcomes = iter([{"status": "finished"}, {"status": "failed", "error": "x"}, {"status": "finished"}])
    monkeypatch.setattr(sweep_module, "execute_case", lambda *a, **k: next(outcomes))
    calls = []
    monkeypatch.setattr(sweep_module, "write_summary", lambda s: calls.append(s.name))
    run_sweep(sweep, workers=1)
    assert len(calls) == 3  # after the two finished cases, and once more at the end


def test_local_workers_share_the_cores_out_and_the_users_setting_wins(tmp_path, monkeypatch):
    """``wheelsoil batch --workers K`` gives each run cores // K CPU threads (at least one): two runs of one thread
    each on two cores step 1.18-1.26 times faster in all than two of two threads (benchmarks/README.md), with the
    same results. A ``WHEELSOIL_CPU_THREADS`` the user set is left to every run."""
    import subprocess

    import wheelsoil.cases.sweep as sweep_module

    monkeypatch.delenv("WHEELSOIL_CPU_THREADS", raising=False)
    monkeypatch.setattr(sweep_module.os, "cpu_count", lambda: 8)
    assert [sweep_module.worker_threads(k) for k in (1, 2, 3, 8, 16)] == [8, 4, 2, 1, 1]
    seen = {}

    def fake_run(cmd, **kwargs):
        seen["threads"] = kwargs["env"].get("WHEELSOIL_CPU_THREADS")
        return subprocess.CompletedProcess(cmd, 3)

    monkeypatch.setattr(sweep_module.subprocess, "run", fake_run)
    sweep_module.execute_case("[case]\n", str(tmp_path / "a"), cpu_threads=sweep_module.worker_threads(2))
    assert seen["threads"] == "4"
    monkeypatch.setenv("WHEELSOIL_CPU_THREADS", "3")
    assert sweep_module.worker_threads(2) is None
    sweep_module.execute_case("[case]\n", str(tmp_path / "b"), cpu_threads=sweep_module.worker_threads(2))
    assert seen["threads"] == "3"


@pytest.mark.parametrize("value", ["0", "-1", "two", "1.5", "100000"])
def test_a_cpu_thread_count_the_machine_cannot_give_is_refused_naming_it(monkeypatch, value):
    from wheelsoil.errors import WheelsoilInputError
    from wheelsoil.runtime import threads_from_environment

    monkeypatch.setenv("WHEELSOIL_CPU_THREADS", value)
    with pytest.raises(WheelsoilInputError, match=f"WHEELSOIL_CPU_THREADS={value!r}: give a whole number"):
        threads_from_environment()
    monkeypatch.setenv("WHEELSOIL_CPU_THREADS", "1")
    assert threads_from_environment() == 1
    monkeypatch.setenv("WHEELSOIL_CPU_THREADS", " ")
    assert threads_from_environment() is None
