"""The smoke-benchmark regression gate (logic only: no timing happens in tests)."""

from wheelsoil.benchmarks.smoke import compare, figure


def report(throughput, wall, memory, ref=0.1):
    return {"figures": {
        "dem_particle_steps_per_s": figure(throughput, "1/s", reference_s=ref, higher_is_better=True, gated=True),
        "dem_wall_s_per_simulated_s": figure(wall, "s/s", reference_s=ref, higher_is_better=False, gated=True),
        "peak_rss_mib": figure(memory, "MiB", reference_s=ref, higher_is_better=False, gated=True, normalise=False),
        "compile_s_cold_cache": figure(99.0, "s", reference_s=ref, higher_is_better=False, gated=False),
    }}


def test_gate_passes_within_tolerance_and_on_a_faster_machine():
    base = report(4e6, 14.0, 200.0)
    assert compare(report(3e6, 18.0, 250.0), base, 0.5) == []
    # a machine twice as slow (reference workload takes twice as long) with half the raw throughput
    assert compare(report(2e6, 28.0, 200.0, ref=0.2), base, 0.5) == []


def test_gate_names_the_figure_and_both_values():
    base = report(4e6, 14.0, 200.0)
    failures = compare(report(1.5e6, 40.0, 400.0), base, 0.5)
    assert len(failures) == 3
    assert failures[0].startswith("dem_particle_steps_per_s regressed")
    assert "1.5e+06 1/s now vs 4e+06 1/s in the baseline" in failures[0]
    assert any(f.startswith("peak_rss_mib regressed") for f in failures)
    assert not any("compile_s_cold_cache" in f for f in failures)  # informational figures never gate


def test_missing_figure_is_reported():
    base = report(4e6, 14.0, 200.0)
    now = report(4e6, 14.0, 200.0)
    del now["figures"]["dem_wall_s_per_simulated_s"]
    assert compare(now, base, 0.5) == ["dem_wall_s_per_simulated_s: in the baseline but not measured now"]



def test_bench_command_runs_the_tier_in_its_own_process_and_passes_its_status(tmp_path, capsys):
    """'wheelsoil bench' hands over to python -m wheelsoil.benchmarks.smoke: a missing baseline is refused
    there, before any timing, and its status 2 is the command's."""
    import subprocess
    import sys

    from wheelsoil.cases.cli import main

    assert main(["bench", "--smoke", "--baseline", str(tmp_path / "missing.json")]) == 2
    done = subprocess.run([sys.executable, "-c", "import sys, wheelsoil.cases.cli; "
                           "sys.exit(any(m.startswith('wheelsoil.benchmarks') for m in sys.modules))"])
    assert done.returncode == 0  # the case layer does not import the benchmarks


def test_contact_culling_benchmark_refuses_a_folder_without_a_run_before_any_work(tmp_path, capsys):
    from wheelsoil.benchmarks.contact_culling import main

    assert main(["--run", str(tmp_path)]) == 2
    assert f"{tmp_path} has no case.toml: give a run folder with a checkpoint" in capsys.readouterr().err
    assert main(["--run", str(tmp_path), "--rounds", "1"]) == 2
    assert "--rounds 1 >= 2" in capsys.readouterr().err
