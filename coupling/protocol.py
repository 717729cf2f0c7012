"""The rig's protocol as a list of steps (issue 38 item 3): lower the wheel to the load, let it settle, spin it up,
wind it up, drive until steady (:data:`DEFAULT_PROTOCOL`; :mod:`.testbed` documents each); a drive of several stages
(``TestbedSpec.stages``, a slip ramp) adds a ramp to the next stage's command, a wind-up and a drive per further stage
(:func:`protocol_for`). A step commands the hub's
spin and the carriage's speed for the sample about to be taken (:meth:`ProtocolStep.command`) and, after the sample,
says whether the protocol moves on (:meth:`ProtocolStep.after_sample`); what it decides goes into the run's typed
:class:`~.protocol_state.ProtocolState`, which checkpoints keep. The testbed supplies the physics (the rig's commands,
the measurements, the steady-state detector); a step reads the testbed it drives and never the engine directly.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import ClassVar

import numpy as np

from wheelsoil.errors import SimulationUnstableError

from .kinematics import longitudinal_slip
from .protocol_state import ProtocolState
from .steady import confirm_steady
from .testbed_result import stage_summary

#: What a step says after a sample: stay, move on to the next step, or end the run.
STAY, NEXT, END = "stay", "next", "end"


class ProtocolStep:
    """One step of the protocol; ``name`` is the phase the protocol state records while it runs."""

    name: ClassVar[str] = ""

    def applies(self, bench) -> bool:
        """Whether the step runs for this testbed (a step that does not is skipped)."""
        return True

    def begin(self, bench, state: ProtocolState, t: float) -> None:
        """What the step sets up when it begins at time ``t`` [s]."""

    def command(self, bench, state: ProtocolState, t: float) -> tuple[float, float] | None:
        """The hub's spin [rad/s] and the carriage's speed [m/s] for the sample about to be taken (None: as before)."""
        return None

    def after_sample(self, bench, state: ProtocolState, row: dict, t: float) -> str:
        """:data:`STAY`, :data:`NEXT` or :data:`END` after the sample ``row`` ending at ``t`` [s]."""
        return STAY


class Lower(ProtocolStep):
    """Lower the wheel at ``lowering_speed`` until the soil carries the load W, then release the axle under W."""

    name = "lower"

    def after_sample(self, bench, state, row, t):
        s = bench.stage_spec
        if row["vertical_force"] >= s.load:
            bench.release()
            state.t_release = t
            return NEXT
        if row["sinkage"] > 0.5 * bench.wheel.radius:
            raise SimulationUnstableError(
                f"the bed does not carry the load {s.load} N: the wheel sank {row['sinkage']:.3f} m "
                f"(more than half its radius) while lowered, with the soil carrying {row['vertical_force']:.1f} N")
        return STAY


class Settle(ProtocolStep):
    """Rest, free vertically under W, for ``settle_time``."""

    name = "settle"

    def after_sample(self, bench, state, row, t):
        if t >= state.t_release + bench.stage_spec.settle_time - 1e-12:
            state.t_spin = t
            state.omega_filtered = 0.0
            return NEXT
        return STAY


class SpinUp(ProtocolStep):
    """Ramp the hub's spin and the carriage's speed together over ``spin_up_time``."""

    name = "spin-up"

    def command(self, bench, state, t):
        s = bench.stage_spec
        ramp = min(1.0, (t - state.t_spin) / s.spin_up_time) if s.spin_up_time > 0 else 1.0
        return bench.spin_command * ramp, bench.travel_speed * ramp

    def after_sample(self, bench, state, row, t):
        if t >= state.t_spin + bench.stage_spec.spin_up_time - 1e-12:
            state.t_windup = t
            return NEXT
        return STAY


class Ramp(ProtocolStep):
    """Begin the drive's next stage (``TestbedSpec.stages``): move the hub's spin and the carriage's speed linearly
    from the previous stage's command to the new stage's over its ``ramp_time``."""

    name = "ramp"

    def begin(self, bench, state, t):
        state.ramp_spin, state.ramp_speed = state.hub_spin, bench.travel_speed
        state.stage += 1
        state.steady_in_a_row = 0
        bench.enter_stage(state.stage)
        state.t_spin = t

    def command(self, bench, state, t):
        s = bench.stage_spec
        ramp = min(1.0, (t - state.t_spin) / s.spin_up_time) if s.spin_up_time > 0 else 1.0
        return (state.ramp_spin + (bench.spin_command - state.ramp_spin) * ramp,
                state.ramp_speed + (bench.travel_speed - state.ramp_speed) * ramp)

    def after_sample(self, bench, state, row, t):
        if t >= state.t_spin + bench.stage_spec.spin_up_time - 1e-12:
            state.t_windup = t
            return NEXT
        return STAY


class WindUp(ProtocolStep):
    """Wind a flexible wheel up by tread-speed feedback on the hub (``windup = "controller"``; a rigid wheel has
    nothing to wind up) until the tread turns at the commanded slip, or for at most half the drive."""

    name = "wind-up"

    def applies(self, bench) -> bool:
        return bench.spec.windup == "controller" and not bench.spec.rigid

    def command(self, bench, state, t):
        s, omega = bench.stage_spec, bench.spin_command
        spin = omega + s.windup_gain * (omega - state.omega_filtered)
        return min(max(spin, 0.5 * omega), 1.5 * omega), bench.travel_speed

    def after_sample(self, bench, state, row, t):
        converged = wound_up(bench, state)
        if converged or t >= state.t_windup + 0.5 * bench.stage_spec.drive_time:
            state.windup_converged = converged
            return NEXT
        return STAY


class Drive(ProtocolStep):
    """Hold the hub at exactly the commanded spin and drive until a steady window of ``average_time`` is found at
    ``steady_checks`` checks in a row, one pitch apart (``stop_when_steady``), or until ``drive_time`` has passed since
    the spin-up (or the stage's ramp) ended. A stage that another follows keeps its summary
    (``ProtocolState.finished_stages``) before the protocol moves on."""

    name = "drive"

    def begin(self, bench, state, t):
        state.t_hold = t
        # the first window may start one whole period after the hold (the hub's step from the controller's spin to
        # omega is a small disturbance the wheel rides out within a period)
        state.t_average_from = t + bench.pitch / bench.batch_rate
        state.next_check = state.t_average_from + bench.stage_spec.average_time

    def command(self, bench, state, t):
        return bench.spin_command, bench.travel_speed

    def after_sample(self, bench, state, row, t):
        s = bench.stage_spec
        if t < state.next_check - 1e-12:
            return STAY
        state.next_check = t + bench.pitch / bench.batch_rate
        ended = t >= state.t_windup + s.drive_time - 1e-12
        if s.stop_when_steady or ended:
            found = bench.detect()
            if found.steady and found.window[1] - found.window[0] < s.average_time * (1.0 - 1e-9):
                found = replace(found, steady=False, reasons=["the steady window is shorter than average_time"])
            bench.steady_state, state.steady_in_a_row = confirm_steady(found, state.steady_in_a_row, s.steady_checks)
            if (bench.steady_state.steady and s.stop_when_steady) or ended:
                if state.stage < bench.spec.n_stages - 1:
                    state.finished_stages += (stage_summary(bench),)
                    bench.steady_state = None
                    return NEXT
                return END
        return STAY


def wound_up(bench, state: ProtocolState) -> bool:
    """The tread's spin over its last pitch gives the commanded slip within a third of the tolerance, and the
    controller's hub spin gives it within the tolerance (slips at the commanded travel speed)."""
    s, rows = bench.stage_spec, bench.rows
    omega_t = np.asarray(rows["tread_omega"])
    t = np.asarray(rows["t"])
    n_pitch = int(math.ceil(bench.pitch / bench.batch_rate / (bench.steps_per_sample * bench.dt)))
    if len(t) < n_pitch or t[-n_pitch] < state.t_windup:
        return False
    r, v = bench.wheel.radius, bench.slip_reference_speed
    slip_error = abs(longitudinal_slip(v, float(omega_t[-n_pitch:].mean()), r) - s.slip)
    spin_error = abs(longitudinal_slip(v, state.hub_spin, r) - s.slip)
    return slip_error <= s.slip_tolerance / 3.0 and spin_error <= s.slip_tolerance


#: The rig's protocol: lower, settle, spin up, wind up (flexible wheels with the controller), drive until steady.
DEFAULT_PROTOCOL: tuple[ProtocolStep, ...] = (Lower(), Settle(), SpinUp(), WindUp(), Drive())


def protocol_for(n_stages: int) -> tuple[ProtocolStep, ...]:
    """The protocol of a drive of ``n_stages`` stages: :data:`DEFAULT_PROTOCOL`, then for every further stage a ramp
    to its command, a wind-up and a drive."""
    if n_stages < 1:
        raise ValueError(f"a drive has at least one stage, not {n_stages}")
    return DEFAULT_PROTOCOL + (Ramp(), WindUp(), Drive()) * (n_stages - 1)


def running_step(protocol: tuple[ProtocolStep, ...], state: ProtocolState) -> int:
    """The running step's place in ``protocol``: ``state.step``, or for a state that has none (a checkpoint from
    before protocols could repeat a step) the first step named ``state.phase``."""
    if state.step is not None:
        if not 0 <= state.step < len(protocol) or protocol[state.step].name != state.phase:
            raise ValueError(f"protocol step {state.step} ({state.phase!r}) is not in this protocol: its steps are "
                             f"{[s.name for s in protocol]}")
        return state.step
    for k, step in enumerate(protocol):
        if step.name == state.phase:
            return k
    raise ValueError(f"the protocol has no step {state.phase!r}: its steps are {[s.name for s in protocol]}")


def advance(protocol: tuple[ProtocolStep, ...], bench, state: ProtocolState, row: dict, t: float) -> bool:
    """Ask the running step after a sample and move the protocol on; True when the run is over. The next step that
    applies begins at ``t``; a step that does not apply is skipped."""
    here = running_step(protocol, state)
    verdict = protocol[here].after_sample(bench, state, row, t)
    if verdict == END:
        return True
    if verdict == NEXT:
        k = here + 1
        while k < len(protocol) and not protocol[k].applies(bench):
            k += 1
        if k == len(protocol):
            return True
        state.phase, state.step = protocol[k].name, k
        protocol[k].begin(bench, state, t)
    return False
