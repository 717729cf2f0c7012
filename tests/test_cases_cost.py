"""The wall-time estimate a budget is checked against (cases/cost.py), and ``wheelsoil replicate --budget`` refusing a
replica count its budget cannot hold before any run."""

import math

import pytest

from wheelsoil.cases import build, schema
from wheelsoil.cases.cost import (CPU_FAST, CPU_SLOW, RunCost, check_budget, longest_simulated_seconds, run_cost,
                                  run_time_step)
from wheelsoil.errors import WheelsoilInputError


def test_the_estimate_is_the_longest_protocols_particle_steps_over_the_measured_throughputs():
    """From the run's size: particles x the longest protocol's DEM steps (lowering 2 s, settle, spin-up, whole drive)
    over the slow and fast ends per core; a longer drive costs in proportion."""
    plan = build.plan(schema.load_case("cmu-grouser"))
    t = plan.test
    assert longest_simulated_seconds(t) == pytest.approx(2.0 + t.settle_time + t.spin_up_time + t.drive_time)
    steps = math.ceil(longest_simulated_seconds(t) / run_time_step(plan))
    cost = run_cost(plan, cores=2)
    assert cost.low == pytest.approx(plan.particles * steps / (2 * CPU_FAST))
    assert cost.high == pytest.approx(plan.particles * steps / (2 * CPU_SLOW))
    longer = run_cost(build.plan(schema.load_case("cmu-grouser", [f"test.drive_time={2 * t.drive_time}"])), cores=2)
    assert longer.low / cost.low == pytest.approx((longest_simulated_seconds(t) + t.drive_time)
                                                  / longest_simulated_seconds(t), rel=1e-4)
    assert run_cost(plan, cores=4).high == pytest.approx(cost.high / 2)


def test_finished_runs_of_the_case_set_the_estimate():
    plan = build.plan(schema.load_case("mini-1g-steer"))
    cost = run_cost(plan, finished_walls=[600.0, 0.0, None, 900.0])
    assert (cost.low, cost.high) == (750.0, 750.0) and "2 finished runs" in cost.how


def test_a_budget_is_refused_when_even_the_fast_end_cannot_hold_the_runs():
    cost = RunCost(low=1800.0, high=7200.0, how="test")
    assert check_budget([cost] * 4, None).startswith("4 runs to run: 2.0 h to 8.0 h in all, 30 min to 2.0 h a run (test)")
    assert check_budget([cost] * 4, 9.0).endswith("holds them")
    assert "may not hold them all (it holds 2 at the slow end)" in check_budget([cost] * 4, 4.0)
    with pytest.raises(WheelsoilInputError, match=r"--budget 1.5 h cannot hold the runs: .* holds 3 at the most"):
        check_budget([cost] * 4, 1.5)
    for bad in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(WheelsoilInputError, match="--budget"):
            check_budget([cost] * 4, bad)
    mixed = [RunCost(600.0, 600.0, "a"), RunCost(3000.0, 6000.0, "b"), RunCost(600.0, 1200.0, "c")]
    assert check_budget(mixed, None) == "3 runs to run: 70 min to 2.2 h in all, 10 min to 1.7 h a run"
    with pytest.raises(WheelsoilInputError, match="holds 2 at the most"):
        check_budget(mixed, 1.0)
    assert "(it holds 2 at the slow end)" in check_budget(mixed, 2.0)


def test_replicate_refuses_a_budget_it_cannot_hold_before_any_run(tmp_path, capsys):
    from wheelsoil.cases.cli import EXIT_INPUT, main

    out = tmp_path / "r"
    seeds = [str(k) for k in range(40)]
    assert main(["replicate", "cmu-grouser", "--out", str(out), "--seeds", *seeds, "--budget", "1"]) == EXIT_INPUT
    err = capsys.readouterr().err
    assert "--budget 1 h cannot hold the replicas: 40 replicas to run" in " ".join(err.split()), err
    assert "Traceback" not in err
    assert not (out / "cases").exists() or not any((out / "cases").iterdir())


def test_batch_refuses_a_budget_it_cannot_hold_before_any_run(tmp_path, capsys):
    from wheelsoil.cases.cli import EXIT_INPUT, main

    out = tmp_path / "s"
    assert main(["batch", "cmu-trials-subset", "--out", str(out), "--budget", "0.5"]) == EXIT_INPUT
    err = " ".join(capsys.readouterr().err.split())
    assert "--budget 0.5 h cannot hold the cases:" in err and "Traceback" not in err
    assert not (out / "cases").exists() or not any((out / "cases").iterdir())
    assert main(["batch", "cmu-trials-subset", "--out", str(out), "--budget", "1", "--scheduler", "tcp://x:1"]) \
        == EXIT_INPUT
    assert "--budget is for runs on this machine" in capsys.readouterr().err


def test_finished_replicas_set_the_estimate_of_the_rest(tmp_path):
    """``wheelsoil replicate``'s estimate: the finished replicas' mean wall time for each one still to run."""
    from result_files import summary, write_result

    from wheelsoil.cases.commands.common import budget_said
    from wheelsoil.cases.replicas import make_replicas

    sweep = make_replicas(schema.load_case("mini-1g-steer"), [0, 1, 2, 3], tmp_path / "r")
    for c, wall in zip(sweep.cases[:2], (500.0, 700.0)):
        write_result(c.folder, c.case, [summary(0.3)], wall_seconds=wall)
    said = budget_said(sweep, 1.0, "replicas", same_case=True)
    assert said.startswith("2 replicas to run: 20 min in all, 10 min a run (the mean of 2 finished runs here)"), said
    with pytest.raises(WheelsoilInputError, match="holds 1 at the most"):
        budget_said(sweep, 0.25, "replicas", same_case=True)
    for c in sweep.cases[2:]:
        write_result(c.folder, c.case, [summary(0.3)])
    assert budget_said(sweep, 0.25, "replicas", same_case=True) == "all replicas have finished; nothing to run"

