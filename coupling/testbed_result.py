"""What :meth:`~.testbed.Testbed.run` returns (:class:`TestbedResult`): the series, the typed summary, the rig and
wheel it ran, the run's figures and its last state. No Taichi."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from wheelsoil.flexwheel.geometry import WheelGeometry
from wheelsoil.flexwheel.mesh import StructureMesh

from .rig import TestbedSpec
from .run_statistics import summarise_window
from .run_summary import RunSummary


@dataclass
class TestbedResult:
    """Time series (NumPy arrays, units in :data:`~.run_summary.SERIES_UNITS`) and the steady-state summary."""

    __test__ = False

    series: dict
    summary: RunSummary
    spec: TestbedSpec
    wheel: WheelGeometry
    bed_summary: str
    info: dict = field(default_factory=dict)
    final_particles: dict = field(default_factory=dict)
    final_wheel_nodes: np.ndarray | None = None
    final_deformation: np.ndarray | None = None
    mesh: StructureMesh | None = None
    #: every stage's summary, in order (``TestbedSpec.stages``; one stage: ``(summary,)``)
    stages: tuple[RunSummary, ...] = ()

    def steady(self, name: str) -> float:
        """Steady-state mean of a quantity (see :data:`~.run_summary.SUMMARY_QUANTITIES`)."""
        return self.summary.mean(name)


def stage_summary(bench, rows: dict | None = None) -> RunSummary:
    """The summary of the drive's running stage, now: over the steady window :attr:`~.testbed.Testbed.steady_state`
    holds (or the detector finds), or, where none, over the drive's last ``average_time``, said to be unsteady.
    ``rows``: the series as NumPy arrays (default: the testbed's rows so far)."""
    s = bench.stage_spec
    rows = rows if rows is not None else {k: np.asarray(v) for k, v in bench.rows.items()}
    state = bench.steady_state if bench.steady_state is not None else bench.detect()
    t = rows["t"]
    k0, k1 = state.k0, state.k1
    if k1 - k0 < 2:  # nothing to average over: the last average_time of the drive, said to be unsteady
        k1 = len(t)
        k0 = max(0, int(np.searchsorted(t, t[-1] - s.average_time)))
    return summarise_window(rows, state, k0, k1, period_pitches=bench.period_pitches,
                            sample_interval=bench.steps_per_sample * bench.dt, pitch=bench.pitch,
                            commanded_slip=s.slip, commanded_slip_angle=s.slip_angle)


def testbed_result(bench, rows: dict, wall: float) -> TestbedResult:
    """What a finished :class:`~.testbed.Testbed` run returns: its series ``rows`` (NumPy arrays), the summary of its
    last stage (:func:`stage_summary`) and every stage's, the run's figures (``wall`` [s] of wall time) and its last
    state."""
    s, loop = bench.spec, bench.protocol_state
    t = rows["t"]
    summary = stage_summary(bench, rows)
    particles = {"position": bench.scene.positions, "velocity": bench.scene.velocities, "radius": bench.scene.radii}
    nodes = bench.structure.positions()
    info = {
        "wall_seconds": wall,
        "simulated_seconds": float(t[-1]),
        "dem_steps": bench.scene.steps_taken,
        "dem_time_step": bench.dt,
        "fe_substeps": bench.contact.structure_substeps,
        "fe_time_step": bench.structure.stable_time_step,
        "particles": bench.scene.n_particles,
        "fe_elements": int(bench.mesh.n_elements),
        "contact_facets": int(bench.contact.surface.n_facets),
        "wheel_mass": bench.wheel_mass,
        "contact_rebuilds": bench.contact.rebuilds,
        "seconds_per_simulated_second": wall / max(float(t[-1]), 1e-12),
        "t_released": loop.t_release, "t_spin_up": loop.t_spin, "t_wind_up": loop.t_windup,
        "t_hold": loop.t_hold, "wind_up_converged": bool(loop.windup_converged),
        "patch_shifts": int(bench.patch.shifts) if bench.patch is not None else 0,
        # grains launched above the soil's domain at one health check, at most (Scene.check_health)
        "most_grains_above_top": int(bench.scene.most_above_top),
        "patch_thrown_out": int(bench.patch.thrown_out) if bench.patch is not None else 0,
    }
    return TestbedResult(series=rows, summary=summary, spec=s, wheel=bench.wheel, bed_summary=bench.bed.summary(),
                         info=info, final_particles=particles, final_wheel_nodes=nodes,
                         final_deformation=bench.deformation(nodes), mesh=bench.mesh,
                         stages=loop.finished_stages + (summary,))
