"""The rig's protocol as data (issue 38 item 3): a drive of several stages (a slip ramp) from the case file's
``[protocol]`` section, stepped through the protocol's steps with a stand-in testbed (no engine): each stage ramps
linearly from the previous stage's command to its own, drives until steady, keeps its own summary, and the protocol's
state survives a checkpoint's round trip at any step. The engine's run of a staged case is in
``test_cases_run.py`` (slow tier)."""

import json
import math
from dataclasses import replace
from types import SimpleNamespace

import pytest

from wheelsoil.coupling import protocol as protocol_module
from wheelsoil.coupling.protocol import DEFAULT_PROTOCOL, advance, protocol_for, running_step
from wheelsoil.coupling.kinematics import longitudinal_slip, rig_command
from wheelsoil.coupling.protocol_state import ProtocolState
from wheelsoil.coupling.rig import DriveStage, TestbedSpec, batch_rate, carriage_speed, check_fits, stage_spec
from wheelsoil.coupling.run_summary import RunSummary
from wheelsoil.coupling.steady import SteadyState
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.flexwheel.geometry import LUNAR_ROVER
from wheelsoil.granular.bed_spec import BedSpec

RADIUS = 0.3


class StandInBench:
    """What the protocol's steps read of a testbed (``Testbed``'s own attributes and methods), without the engine:
    the rows are the time alone, and the detector finds the drive steady from its ``steady_from``-th check on."""

    def __init__(self, spec: TestbedSpec, steady_from: int = 2) -> None:
        self.spec, self.steady_from = spec, steady_from
        self.wheel = SimpleNamespace(radius=RADIUS)
        self.pitch, self.steps_per_sample, self.dt = math.radians(4.5), 1, 0.01
        self.rows = {"t": []}
        self.steady_state = None
        self.released = False
        self.enter_stage(0)

    def enter_stage(self, k: int) -> None:
        self.stage_spec = stage_spec(self.spec, k)
        self.spin_command, self.travel_speed = carriage_speed(self.stage_spec, RADIUS)
        self.batch_rate = batch_rate(self.stage_spec.slip, self.stage_spec.angular_velocity, RADIUS)
        self.slip_reference_speed = rig_command(self.stage_spec.slip, self.stage_spec.angular_velocity, RADIUS)[1]
        self.checks = 0

    def release(self) -> None:
        self.released = True

    def detect(self) -> SteadyState:
        self.checks += 1
        t = self.rows["t"]
        return SteadyState(steady=self.checks >= self.steady_from, k0=0, k1=len(t), window=(t[0], t[-1]), pitches=8)


def _stand_in_summary(bench) -> RunSummary:
    return RunSummary(steady=bench.steady_state.steady, window=bench.steady_state.window, samples=0, pitches=8,
                      pitch_deg=45.0, period_pitches=1, reasons=(), commanded_slip=bench.stage_spec.slip,
                      commanded_slip_angle=bench.stage_spec.slip_angle)


def _run(bench, state: ProtocolState, *, load_at: float = 0.0, until: float = 60.0):
    """Step the protocol sample by sample (the soil carries the load from ``load_at`` [s] on) and record each
    sample's command; returns [(t, phase, stage, spin, speed)]."""
    protocol = protocol_for(bench.spec.n_stages)
    t, log = 0.0, []
    while t < until:
        step = protocol[running_step(protocol, state)]
        command = step.command(bench, state, t)
        if command is not None:
            state.hub_spin = command[0]
            log.append((t, state.phase, state.stage, *command))
        t = round(t + bench.dt, 10)
        bench.rows["t"].append(t)
        row = {"vertical_force": bench.spec.load if t >= load_at else 0.0, "sinkage": 0.0}
        if advance(protocol, bench, state, row, t):
            return log, t
    raise AssertionError(f"the protocol did not end within {until} s (phase {state.phase})")


def _spec(**kw) -> TestbedSpec:
    base = dict(slip=0.2, rigid=True, windup="none", spin_up_time=0.2, settle_time=0.05, drive_time=2.0,
                average_time=0.4, sample_interval=0.01, angular_velocity=2.0, load=100.0)
    base.update(kw)
    return TestbedSpec(**base)


def test_the_default_protocol_is_the_one_stage_drive():
    assert protocol_for(1) == DEFAULT_PROTOCOL
    names = [s.name for s in protocol_for(3)]
    assert names == ["lower", "settle", "spin-up", "wind-up", "drive"] + ["ramp", "wind-up", "drive"] * 2
    with pytest.raises(ValueError, match="at least one stage"):
        protocol_for(0)


def test_a_stage_takes_its_own_slip_drive_time_and_ramp_time():
    spec = _spec(stages=(DriveStage(0.5), DriveStage(-0.3, drive_time=4.0, ramp_time=0.5)))
    assert spec.n_stages == 3 and stage_spec(spec, 0) is spec
    one, two = stage_spec(spec, 1), stage_spec(spec, 2)
    assert (one.slip, one.drive_time, one.spin_up_time, one.stages) == (0.5, 2.0, 0.2, ())
    assert (two.slip, two.drive_time, two.spin_up_time) == (-0.3, 4.0, 0.5)
    assert replace(two, slip=spec.slip, drive_time=2.0, spin_up_time=0.2) == replace(spec, stages=())
    with pytest.raises(ValueError, match="stages 0 to 2"):
        stage_spec(spec, 3)
    # a one-stage spec reads as before; a staged one lists its stages
    assert "stages" not in _spec().to_dict()
    assert spec.to_dict()["stages"][1] == {"slip": -0.3, "drive_time": 4.0, "ramp_time": 0.5}


@pytest.mark.parametrize("bad, match", [
    (dict(slip=1.0), r"protocol stage slip = 1\.0 is out of range"),
    (dict(slip=0.3, drive_time=0.0), "drive_time = 0"),
    (dict(slip=0.3, ramp_time=-1.0), "ramp_time = -1"),
])
def test_a_stage_out_of_range_is_refused_naming_the_key(bad, match):
    with pytest.raises(WheelsoilInputError, match=match):
        DriveStage(**bad)


def test_a_stage_shorter_than_the_averaging_window_is_refused():
    with pytest.raises(WheelsoilInputError, match=r"stages\[1\]\.drive_time = 0\.3 .* more than average_time = 0\.4"):
        _spec(stages=(DriveStage(0.4), DriveStage(0.5, drive_time=0.3)))


def test_the_static_bin_must_hold_every_stage_of_the_drive():
    bed = BedSpec(length=3.0, width=0.8, depth=0.1, diameter_min=0.02, diameter_max=0.03, periodic=False)
    wheel = LUNAR_ROVER.with_element_size(0.1)
    spec = _spec(slip=0.0, drive_time=1.0, average_time=0.2, angular_velocity=1.0, rigid=False)
    check_fits(bed, wheel, spec)  # 0.72 m of travel in a 3 m bin (r omega = 0.6 m/s), 2.64 m more with the stages
    with pytest.raises(WheelsoilInputError, match=r"and its further stages \(protocol.stages\)"):
        check_fits(bed, wheel, replace(spec, stages=(DriveStage(0.0, drive_time=2.0), DriveStage(0.0, drive_time=2.0))))


@pytest.mark.parametrize("steady_from", [1, 2, 3])
def test_each_stage_ramps_from_the_last_command_drives_until_steady_and_keeps_its_summary(monkeypatch, steady_from):
    monkeypatch.setattr(protocol_module, "stage_summary", _stand_in_summary)
    spec = _spec(stages=(DriveStage(0.5), DriveStage(-0.5, ramp_time=0.5)), steady_checks=1)
    bench = StandInBench(spec, steady_from=steady_from)
    state = ProtocolState()
    log, t_end = _run(bench, state, load_at=0.1)
    assert bench.released and state.stage == 2
    # the finished stages keep their summaries in order; the last stage's is the testbed's own (steady_state)
    assert [s.commanded_slip for s in state.finished_stages] == [0.2, 0.5]
    assert bench.steady_state.steady and bench.stage_spec.slip == -0.5
    commands = {k: [(t, spin, speed) for t, phase, stage, spin, speed in log if stage == k] for k in range(3)}
    for k in range(3):
        spin, speed = carriage_speed(stage_spec(spec, k), RADIUS)
        assert commands[k][-1][1:] == pytest.approx((spin, speed), rel=1e-12)  # the stage drives at its command
    for k in (1, 2):
        ramp = [(t, spin, speed) for t, phase, stage, spin, speed in log if stage == k and phase == "ramp"]
        start, ramp_time = ramp[0][0], stage_spec(spec, k).spin_up_time
        spin0, speed0 = carriage_speed(stage_spec(spec, k - 1), RADIUS)
        spin1, speed1 = carriage_speed(stage_spec(spec, k), RADIUS)
        for t, spin, speed in ramp:  # linear from the previous stage's command to this one's
            f = min(1.0, (t - start) / ramp_time)
            assert (spin, speed) == pytest.approx((spin0 + (spin1 - spin0) * f, speed0 + (speed1 - speed0) * f))
        assert ramp[-1][0] - start == pytest.approx(ramp_time - bench.dt, abs=1e-9)
    # stages that reach a steady state later drive longer
    assert t_end > 1.5


def test_a_stage_that_never_steadies_ends_at_its_drive_time(monkeypatch):
    monkeypatch.setattr(protocol_module, "stage_summary", _stand_in_summary)
    spec = _spec(stages=(DriveStage(0.4, drive_time=1.0),), stop_when_steady=False)
    bench = StandInBench(spec, steady_from=10**6)
    state = ProtocolState()
    log, t_end = _run(bench, state)
    first = state.finished_stages[0]
    assert not first.steady and first.commanded_slip == 0.2
    ramp_start = min(t for t, phase, stage, *_ in log if phase == "ramp")
    assert ramp_start - state.t_release == pytest.approx(0.05 + 0.2 + 2.0, abs=0.05)  # settle, spin-up, drive
    assert t_end - ramp_start == pytest.approx(0.2 + 1.0, abs=0.05)  # the stage's ramp and drive_time


def test_the_protocol_state_survives_a_checkpoint_at_every_step(monkeypatch):
    monkeypatch.setattr(protocol_module, "stage_summary", _stand_in_summary)
    spec = _spec(stages=(DriveStage(0.5), DriveStage(0.1)), steady_checks=1)
    reference_bench, reference = StandInBench(spec), ProtocolState()
    log, _ = _run(reference_bench, reference)
    # a state taken in each step, written as a checkpoint writes it, read back and continued, ends the same way
    protocol = protocol_for(spec.n_stages)
    for k in range(len(protocol)):
        bench, state = StandInBench(spec), ProtocolState()
        t = 0.0
        while running_step(protocol, state) < k or state.phase == "new":
            bench.rows["t"].append(t := round(t + bench.dt, 10))
            if advance(protocol, bench, state, {"vertical_force": spec.load, "sinkage": 0.0}, t):
                break
        restored = ProtocolState.from_dict(state.to_dict())
        assert json.dumps(restored.to_dict()) == json.dumps(state.to_dict())  # NaN statistics compare as text
        assert running_step(protocol, restored) == running_step(protocol, state)
        assert [s.commanded_slip for s in restored.finished_stages] == [0.2, 0.5][:state.stage]


def test_a_checkpoint_from_before_the_step_index_finds_its_step_by_name():
    old = ProtocolState(phase="drive").to_dict()
    assert "step" not in old
    for key in ("finished_stages", "stage", "ramp_spin", "ramp_speed"):
        del old[key]
    state = ProtocolState.from_dict(old)
    assert state.step is None and running_step(DEFAULT_PROTOCOL, state) == 4
    # a repeated step is told apart by its place, which a checkpoint keeps
    staged = protocol_for(2)
    later = ProtocolState(phase="drive", step=7, stage=1)
    assert running_step(staged, ProtocolState.from_dict(later.to_dict())) == 7
    with pytest.raises(ValueError, match="not in this protocol"):
        running_step(DEFAULT_PROTOCOL, later)


def test_the_progress_line_names_the_phase_stage_and_tread_slip():
    """The terminal's progress line (``Testbed.run(progress=True)``, what ``wheelsoil run`` shows in a terminal) reads
    the typed protocol state: the phase, the stage of a slip ramp and the tread slip beside the commanded one."""
    from wheelsoil.coupling.run_progress import RunProgress

    spec = _spec(stages=(DriveStage(0.5),))
    bench = StandInBench(spec)
    bench.enter_stage(1)
    bench.protocol_state = ProtocolState(phase="drive", step=7, stage=1, t_release=0.1, t_spin=1.0)
    bench.scene = SimpleNamespace(time=1.5)
    omega_t = bench.spin_command * 0.9  # the tread turns slower than the hub (winding up)
    bench.rows = {"drawbar_pull": [3.0], "vertical_force": [100.0], "torque": [5.0], "sinkage": [0.01],
                  "tread_omega": [omega_t] * 20}
    bar = RunProgress(bench)
    try:
        bar.update()
        line = bar.bar.tasks[0].description
    finally:
        bar.stop()
    tread = longitudinal_slip(bench.slip_reference_speed, omega_t, RADIUS)
    assert tread < 0.5 and f"tread slip {tread:.3f} (commanded 0.5)" in line  # a wound-up tread slips less
    assert line.startswith("drive 2/2") and "t = 1.500 s" in line
    assert bar.bar.tasks[0].total == 1000  # the running stage's longest drive sets the bar's end
