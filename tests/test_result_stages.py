"""A drive of several stages (``[protocol]`` ``stages``, a slip ramp) in the case file, the result file and the sweep
tables, without the engine: the section's round trip and errors, each stage's summary stored and read back
(``/stages/<k>``), and one sweep row per stage at the stage's slip. A one-stage case keeps its hash and its result
layout, and its case text has no ``[protocol]`` section. The engine's staged run is in ``test_coupling_testbed.py`` (slow tier)."""

import math

import h5py
import numpy as np
import pytest

from result_files import summary, write_result

from wheelsoil.cases.results import load_result
from wheelsoil.cases.run import RESULT_NAME
from wheelsoil.cases.schema import CaseError, case_from_toml, case_to_toml, load_case
from wheelsoil.cases.sweep import load_sweep, summary_table
from wheelsoil.cases import build
from wheelsoil.coupling.rig import DriveStage
from wheelsoil.coupling.run_summary import RunSummary

RAMP = "protocol.stages=[{slip = 0.5}, {slip = -0.2, drive_time = 3.0, ramp_time = 0.4}]"


def test_the_protocol_section_round_trips_and_reaches_the_rig():
    case = load_case("mini-1g-steer", [RAMP])
    assert build.testbed_spec(case).stages == (DriveStage(0.5), DriveStage(-0.2, 3.0, 0.4))
    text = case_to_toml(case)
    assert "[protocol]" in text and case_from_toml(text) == case
    plain = load_case("mini-1g-steer")
    assert "protocol" not in case_to_toml(plain) and "# [protocol]" in case_to_toml(plain, template=True)
    assert case.case_hash() != plain.case_hash()
    # a one-stage case's hash is the one it had before the section existed: the dump without it
    assert plain.case_hash() == load_case("mini-1g-steer", ["protocol.stages=[]"]).case_hash()
    # the run's size counts every stage's drive
    assert build.plan(case).output_bytes > build.plan(plain).output_bytes


@pytest.mark.parametrize("override, message", [
    ("protocol.stages=[{slip = 1.2}]", r"protocol.stages.0.slip = 1.2: .*\(allowed slip >= -1 and < 1\)"),
    ("protocol.stages=[{slip = 0.2}, {slp = 0.4}]", r"unknown key protocol.stages.1.slp; did you mean "
                                                     r"protocol.stages.1.slip\?"),
    ("protocol.stages=[{slip = 0.2, ramp_time = '-1 s'}]", r"protocol.stages.0.ramp_time = '-1 s'"),
    ("protocol.stages=[{slip = 0.2, drive_time = 0.5}]", r"stages\[0\].drive_time = 0.5 .* more than average_time"),
    ("protocol.stage=[{slip = 0.2}]", r"unknown key protocol.stage; did you mean protocol.stages\?"),
])
def test_a_bad_stage_names_its_key_and_value(override, message):
    with pytest.raises(CaseError, match=message):
        load_case("mini-1g-steer", [override])


def _summary(slip: float, drawbar_pull: float, window: tuple) -> RunSummary:
    return summary(slip, window=window, drawbar_pull=(drawbar_pull, 0.1))


def test_each_stage_is_stored_and_read_back_and_one_stage_keeps_the_layout(tmp_path):
    case = load_case("mini-1g-steer", [RAMP])
    stages = [_summary(0.3, 10.0, (1.0, 2.0)), _summary(0.5, 14.0, (3.0, 4.0)), _summary(-0.2, -5.0, (5.0, 6.0))]
    result = load_result(write_result(tmp_path / "ramp", case, stages).parent)
    assert [s.commanded_slip for s in result.stages] == [0.3, 0.5, -0.2]
    assert [s.drawbar_pull.mean for s in result.stages] == [10.0, 14.0, -5.0]
    assert result.summary.window == (5.0, 6.0) and result.stages[1].drawbar_pull.dof == 7.0
    row = result.summary_row(1)
    assert (row["stage"], row["commanded_slip"], row["drawbar_pull_mean"], row["window_start"]) == (1, 0.5, 14.0, 3.0)
    with h5py.File(tmp_path / "ramp" / RESULT_NAME, "r") as f:
        assert sorted(f["stages"]) == ["000", "001", "002"]
        assert f["stages/001"].attrs["commanded_slip"] == 0.5
        last, summary = dict(f["stages/002"].attrs), dict(f["summary"].attrs)
        assert last.keys() == summary.keys() and all(str(last[k]) == str(summary[k]) for k in last)  # NaN as text
    plain = load_case("mini-1g-steer")
    one = load_result(write_result(tmp_path / "plain", plain, [_summary(0.3, 10.0, (1.0, 2.0))]).parent)
    assert one.stages == (one.summary,) and "stage" not in one.summary_row()
    with h5py.File(tmp_path / "plain" / RESULT_NAME, "r") as f:
        assert "stages" not in f


def test_a_sweep_table_has_a_row_per_stage_at_the_stages_slip(tmp_path):
    path = tmp_path / "sweep.toml"
    path.write_text('[sweep]\nbase = "mini-1g-steer"\n[sweep.grid]\n"test.slip_angle" = [0, 10]\n'
                    '[[sweep.rows]]\n"protocol.stages" = []\n[[sweep.rows]]\n"protocol.stages" = [{slip = 0.6}]\n')
    sweep = load_sweep(path, tmp_path / "out")
    assert len(sweep.cases) == 4
    for c in sweep.cases:
        slips = [c.case.test.slip] + [st.slip for st in c.case.protocol.stages]
        summaries = [_summary(s, 10.0 * s, (k + 1.0, k + 1.5)) for k, s in enumerate(slips)]
        write_result(c.folder, c.case, summaries)
    assert all(c.finished for c in sweep.cases)
    table = summary_table(sweep)
    assert len(table) == 6 and sorted(table["stage"]) == [0, 0, 0, 0, 1, 1]
    staged = table[table["stage"] == 1]
    assert list(staged["slip_set"]) == [0.6, 0.6] and list(staged["drawbar_pull_mean"]) == pytest.approx([6.0, 6.0])
    first = table[table["stage"] == 0]
    assert list(first["slip_set"]) == [load_case("mini-1g-steer").test.slip] * 4 and not np.isnan(first["drawbar_pull_mean"]).any()
    assert all(math.isclose(r.drawbar_pull_mean, 10.0 * r.slip_set) for r in table.itertuples())
