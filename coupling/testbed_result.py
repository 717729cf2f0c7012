"""What :meth:`~.testbed.Testbed.run` returns (:class:`TestbedResult`): the series, the typed summary, the rig and
wheel it ran, the run's figures and its last state. No Taichi."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from wheelsoil.flexwheel.geometry import WheelGeometry
from wheelsoil.flexwheel.mesh import StructureMesh

from .rig import TestbedSpec
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

    def steady(self, name: str) -> float:
        """Steady-state mean of a quantity (see :data:`~.run_summary.SUMMARY_QUANTITIES`)."""
        return self.summary.mean(name)
