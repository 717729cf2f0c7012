"""What runs will cost in wall time, said before they start: the estimate a time budget is checked against.

Where finished runs of the same case are at hand (earlier replicas in the same folder), a run costs what they cost on
average (their ``result.h5`` info: wall seconds, early steady stops included). Otherwise the estimate is a range from
the run's size: its particle-steps over the longest protocol (lowering allowed 2 s, the settle, every stage's spin-up
and whole drive, at the run's DEM step) over the whole-run throughputs the project has measured on CPUs,

    wall = particles x steps / throughput,   throughput between CPU_SLOW and CPU_FAST particle-steps/s per core,

the fast end the soil alone at its best (the 53k bed, 9.0e6 on 2 cores, ``benchmarks/README.md`` run 13: no coupled
run steps faster than its soil; the CMU twin's rigid wheel alone made 4.7e6), the slow end the flexible wheels beside
other jobs (the smoke wheel, 12,046 particles at 8.2 ms a step on 2 cores: 1.5e6; the mini wheel, 3,852 particles at
3.35 ms: 1.2e6; ``docs/force-balance``), whose sub-steps cost as much as the soil. A run that turns steady stops
before its whole drive (the CMU twin's after 7-18 s of 20), so the slow end is an upper figure on a machine like the
project's; a bed not yet in the cache is prepared first, at the soil's own faster step rate, and is not counted. Runs
sharing the machine's cores add no throughput (two workers on two cores took as long in all as one after the other,
``benchmarks/README.md``): n runs cost n times one.

A budget is refused before any run when even the fast end cannot hold the runs, and said to be at risk when the slow
end cannot (:func:`check_budget`).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

from wheelsoil.coupling.rig import stage_spec
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.granular.materials import effective_modulus
from wheelsoil.granular.timestep import estimate_time_step

#: Whole coupled runs' particle-steps per wall second per CPU core, fast and slow ends (the module's docstring).
CPU_FAST, CPU_SLOW = 4.5e6, 0.6e6


@dataclass(frozen=True)
class RunCost:
    """One run's wall time [s], ``low`` to ``high`` (equal when measured), and ``how`` it was estimated, in words."""

    low: float
    high: float
    how: str

    def describe(self) -> str:
        span = _duration(self.low) if self.low == self.high else f"{_duration(self.low)} to {_duration(self.high)}"
        return f"{span} a run ({self.how})"


def _duration(seconds: float) -> str:
    return f"{seconds / 3600:.1f} h" if seconds >= 5400 else f"{seconds / 60:.0f} min"


def longest_simulated_seconds(test) -> float:
    """The longest a run of the rig ``test`` (:class:`~wheelsoil.coupling.rig.TestbedSpec`) simulates [s]: lowering
    allowed 2 s, the settle, and every stage's spin-up or ramp and whole drive."""
    total = 2.0 + test.settle_time
    for k in range(test.n_stages):
        stage = stage_spec(test, k)
        total += stage.spin_up_time + stage.drive_time
    return total


def run_time_step(plan) -> float:
    """The DEM step [s] a run of ``plan`` (:class:`~wheelsoil.cases.build.RunPlan`) takes: ``soil.time_step`` where
    given, else the stable step of its smallest particles against the soil, the walls and the wheel."""
    if plan.test.time_step is not None:
        return plan.test.time_step
    bed, wheel = plan.bed, plan.wheel
    moduli = (effective_modulus(bed.material, bed.wall_material), effective_modulus(bed.material, wheel.material))
    return estimate_time_step(0.5 * bed.diameter_min, bed.material, wall_moduli=moduli).stable


def run_cost(plan, *, finished_walls=(), cores: int | None = None) -> RunCost:
    """The :class:`RunCost` of one run of ``plan``: the mean of ``finished_walls`` (wall seconds of finished runs of
    the same case on this machine) where there are any, else the range of the module's docstring on ``cores`` CPU
    cores (default: those this process may use)."""
    walls = [float(w) for w in finished_walls if w and w > 0]
    if walls:
        mean = sum(walls) / len(walls)
        return RunCost(mean, mean, f"the mean of {len(walls)} finished run{'s' if len(walls) > 1 else ''} here")
    cores = cores or len(os.sched_getaffinity(0))
    steps = math.ceil(longest_simulated_seconds(plan.test) / run_time_step(plan))
    work = plan.particles * steps
    return RunCost(work / (CPU_FAST * cores), work / (CPU_SLOW * cores),
                   f"{plan.particles:,} particles x {steps:,} DEM steps of the longest protocol at "
                   f"{CPU_SLOW * cores:.2g}-{CPU_FAST * cores:.2g} particle-steps/s on {cores} cores: the slowest "
                   "whole runs measured to the soil alone at its best; a run steady early stops sooner")


def _fitting(walls: list[float], seconds: float) -> int:
    """How many of ``walls``, run in order, end within ``seconds``."""
    total, n = 0.0, 0
    for w in walls:
        total += w
        if total > seconds:
            break
        n += 1
    return n


def check_budget(costs: list[RunCost], budget_hours: float | None, what: str = "runs") -> str:
    """The estimate, in words, of the runs of ``costs`` (one :class:`RunCost` each) one after another on this
    machine. With ``budget_hours``: raises :class:`~wheelsoil.errors.WheelsoilInputError` when even the low end
    cannot be held in it (before any run starts), and says so when the high end cannot."""
    if budget_hours is not None and not (math.isfinite(budget_hours) and budget_hours > 0):
        raise WheelsoilInputError(f"--budget {budget_hours!r}: give the hours the {what} may take, > 0")
    low, high = sum(c.low for c in costs), sum(c.high for c in costs)
    total = _duration(low) if low == high else f"{_duration(low)} to {_duration(high)}"
    each = (costs[0].describe() if len(set(costs)) == 1 else
            f"{_duration(min(c.low for c in costs))} to {_duration(max(c.high for c in costs))} a run") if costs else ""
    said = f"{len(costs)} {what} to run: {total} in all" + (f", {each}" if each else "")
    if budget_hours is None:
        return said
    seconds = 3600.0 * budget_hours
    if low > seconds:
        raise WheelsoilInputError(
            f"--budget {budget_hours:g} h cannot hold the {what}: {said}. The budget holds "
            f"{_fitting([c.low for c in costs], seconds)} at the most; give fewer, a larger --budget, or a shorter "
            "test.drive_time")
    if high > seconds:
        return (f"{said}; --budget {budget_hours:g} h may not hold them all (it holds "
                f"{_fitting([c.high for c in costs], seconds)} at the slow end)")
    return f"{said}; --budget {budget_hours:g} h holds them"
