"""A testbed run's progress on the terminal (rich): the phase, the time, the forces and the tread's slip."""

from __future__ import annotations

import math

import numpy as np

from .kinematics import longitudinal_slip


class RunProgress:
    """The run's progress on the terminal (rich): phase, time, forces and the tread's slip."""

    def __init__(self, bench) -> None:
        """``bench``: the running :class:`~.testbed.Testbed` (its rows, protocol state and rig settings are read)."""
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        self.bench = bench
        self.bar = Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"),
                            TimeElapsedColumn(), transient=True)
        self.bar.start()
        self.task = self.bar.add_task("testbed", total=None)

    def update(self) -> None:
        b, rows = self.bench, self.bench.rows
        loop, s = b.protocol_state, b.stage_spec
        total = completed = None
        if math.isfinite(loop.t_spin):  # the running stage's longest drive
            end = loop.t_spin + s.spin_up_time + s.drive_time
            total, completed = 1000, int(1000 * min(1.0, (b.scene.time - loop.t_release) / (end - loop.t_release)))
        stage = f" {loop.stage + 1}/{b.spec.n_stages}" if b.spec.n_stages > 1 else ""
        text = (f"{loop.phase + stage:8s} t = {b.scene.time:.3f} s  DP {rows['drawbar_pull'][-1]:8.1f} N  "
                f"Fz {rows['vertical_force'][-1]:8.1f} N  T {rows['torque'][-1]:7.1f} N m  "
                f"sinkage {1e3 * rows['sinkage'][-1]:6.1f} mm")
        if loop.phase in ("wind-up", "drive", "ramp"):
            n = max(1, int(b.pitch / b.batch_rate / (b.steps_per_sample * b.dt)))
            omega_t = float(np.mean(rows["tread_omega"][-n:]))
            slip = longitudinal_slip(b.slip_reference_speed, omega_t, b.wheel.radius)
            text += f"  tread slip {slip:.3f} (commanded {s.slip:g})"
        self.bar.update(self.task, total=total, completed=completed, description=text)

    def stop(self) -> None:
        self.bar.stop()
