"""Where a testbed run's protocol stands (:class:`ProtocolState`): the phase, the times at which each phase began,
the hub's commanded spin and angle, the wind-up controller's filter and the steady-state checks so far. The testbed
advances it sample by sample (:mod:`.testbed`); a checkpoint stores it as plain scalars (:meth:`ProtocolState.to_dict`)
and a resumed run reads it back (:meth:`ProtocolState.from_dict`). No Taichi."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, fields

from .run_summary import RunSummary

#: The protocol's phases, in order ("new" before a run starts, "done" after it ends); a drive of several stages
#: (``TestbedSpec.stages``) repeats "ramp", "wind-up" and "drive" for each further stage.
PHASES = ("new", "lower", "settle", "spin-up", "wind-up", "drive", "ramp", "done")


@dataclass
class ProtocolState:
    """A run's protocol state (times in s of simulated time, angles in rad, spins in rad/s).

    phase: one of :data:`PHASES`.
    t_release, t_spin, t_windup, t_hold: when the axle was released (settle began), the spin-up began, the
        wind-up began (the spin-up ended) and the hub was held at the commanded spin (the drive began); inf until then.
    t_average_from: the earliest start of a steady window (a period after the hold); next_check: when the steady
        state is next looked for; inf until the drive.
    wall: wall-clock seconds run so far (kept across a resume).
    hub_angle: the hub's commanded rotation so far; hub_spin: its commanded spin now.
    omega_filtered: the tread's spin filtered for the wind-up controller; tread_angle: the tread's rotation at the
        last sample (None before the first).
    shift: how far the moving soil patch has re-centred the wheel [m].
    windup_converged: the wind-up ended because the tread reached the commanded slip (not at its time limit).
    steady_in_a_row: consecutive checks that found the run steady.
    step: the running step's place in the protocol's list (None: the first step named ``phase``, as in a checkpoint
        written before protocols could repeat a step).
    stage: the drive's stage now (0: the first, at the spec's slip); ramp_spin, ramp_speed: the hub's spin [rad/s]
        and the carriage's speed [m/s] when the running stage's ramp began.
    finished_stages: the summaries of the stages that have ended, in order (the last stage's is the run's summary).
    """

    phase: str = "lower"
    t_release: float = math.inf
    t_spin: float = math.inf
    t_windup: float = math.inf
    t_hold: float = math.inf
    t_average_from: float = math.inf
    next_check: float = math.inf
    wall: float = 0.0
    hub_angle: float = 0.0
    hub_spin: float = 0.0
    omega_filtered: float = 0.0
    tread_angle: float | None = None
    shift: float = 0.0
    windup_converged: bool = False
    steady_in_a_row: int = 0
    step: int | None = None
    stage: int = 0
    ramp_spin: float = 0.0
    ramp_speed: float = 0.0
    finished_stages: tuple[RunSummary, ...] = ()

    def __post_init__(self) -> None:
        if self.phase not in PHASES:
            raise ValueError(f"protocol phase {self.phase!r} is not one of {', '.join(PHASES)}")

    def to_dict(self) -> dict:
        """Plain scalars for a checkpoint (an unset ``tread_angle`` or ``step`` is left out; the finished stages'
        summaries as one JSON text)."""
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        for key in ("tread_angle", "step"):
            if d[key] is None:
                del d[key]
        d["finished_stages"] = json.dumps([st.to_dict() for st in self.finished_stages])
        return d

    @classmethod
    def from_dict(cls, d: dict) -> ProtocolState:
        """From :meth:`to_dict` as a checkpoint file gives it back (NumPy scalars, bytes); keys a checkpoint written
        by an older version lacks take their defaults, keys this version does not know are refused."""
        types = {f.name: f.type for f in fields(cls)}
        unknown = sorted(set(d) - set(types))
        if unknown:
            raise ValueError(f"checkpoint protocol state has unknown keys {unknown}")
        values = {}
        for key, value in d.items():
            if isinstance(value, bytes):
                value = value.decode()
            if key == "phase":
                values[key] = str(value)
            elif key == "windup_converged":
                values[key] = bool(value)
            elif key in ("steady_in_a_row", "step", "stage"):
                values[key] = int(value)
            elif key == "finished_stages":
                values[key] = tuple(RunSummary.from_dict(st) for st in json.loads(value))
            else:
                values[key] = float(value)
        return cls(**values)
