"""Case files: schema errors name the file, key, value and what is allowed; units; overrides; round trips."""

import math

import pytest

from wheelsoil.cases import build
from wheelsoil.cases.cli import EXIT_INPUT, EXIT_OK, main
from wheelsoil.cases.schema import (
    CaseError,
    case_from_toml,
    case_to_toml,
    load_case,
    parse_override,
    preset_names,
    validate_case,
)
from wheelsoil.cases.units import UnitError, to_unit


def write(tmp_path, text, name="case.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_malformed_toml_names_the_file_and_line(tmp_path):
    path = write(tmp_path, "[test]\nslip = 0.3\nload 3000\n")
    with pytest.raises(CaseError) as exc:
        load_case(path)
    msg = str(exc.value)
    assert str(path) in msg and "not valid TOML" in msg and "line 3" in msg


def test_unknown_keys_and_sections_suggest_the_closest_valid_one(tmp_path):
    path = write(tmp_path, "[test]\nslp = 0.3\n[wheel]\ngrouser_cout = 12\n[tset]\nload = 1\n")
    with pytest.raises(CaseError) as exc:
        load_case(path)
    problems = exc.value.problems
    assert len(problems) == 3, problems
    assert "unknown key test.slp; did you mean test.slip?" in problems
    assert "unknown key wheel.grouser_cout; did you mean wheel.grouser_count?" in problems
    assert "unknown section [tset]; did you mean test?" in problems
    assert str(path) in str(exc.value)


@pytest.mark.parametrize("text, key, value, allowed", [
    ("[test]\nslip = 1.5", "test.slip", "1.5", "allowed slip >= -1 and < 1"),
    ("[test]\nslip_angle = -95", "test.slip_angle", "-95", "allowed slip_angle > -90 and <= 90; unit deg"),
    ("[test]\nload = 0", "test.load", "0", "allowed load > 0; unit N"),
    ("[test]\nslip_angle = 90", "test.slip_angle", "90", "needs slip_speed = 'travel'"),
    ("[soil]\npoisson_ratio = 0.5", "soil.poisson_ratio", "0.5", "allowed poisson_ratio > -1 and < 0.5"),
    ("[contact]\nrestitution = 1.2", "contact.restitution", "1.2", "allowed restitution > 0 and <= 1"),
    ("[output]\nframe_interval = -1", "output.frame_interval", "-1", "allowed frame_interval >= 0; unit s"),
    ("[wheel]\nspokes_per_row = 0", "wheel.spokes_per_row", "0", "allowed spokes_per_row >= 1"),
])
def test_out_of_range_values_name_key_value_and_range(tmp_path, text, key, value, allowed):
    path = write(tmp_path, text + "\n")
    with pytest.raises(CaseError) as exc:
        load_case(path)
    (line,) = exc.value.problems
    assert line.startswith(f"{key} = {value}:"), line
    assert allowed in line, line


def test_wrong_types_and_gravity_forms(tmp_path):
    with pytest.raises(CaseError, match=r"test.slip = 'fast': 'fast' is not a number \(or a percentage such as '30 %'\)"):
        load_case(write(tmp_path, '[test]\nslip = "fast"\n'))
    with pytest.raises(CaseError, match="gravity is 'earth', 'moon', a magnitude"):
        load_case(write(tmp_path, '[soil]\ngravity = "mars"\n'))
    with pytest.raises(CaseError, match="point down"):
        load_case(write(tmp_path, "[soil]\ngravity = [0, 0, 9.81]\n"))
    moon = load_case(write(tmp_path, '[soil]\ngravity = "moon"\n'))
    assert moon.soil.gravity_vector == (0.0, 0.0, -9.81 / 6.0)
    assert build.bed_spec(load_case(write(tmp_path, "[soil]\ngravity = 3.71\n"))).gravity == (0.0, 0.0, -3.71)


def test_cross_checks_of_the_solver_name_the_problem(tmp_path):
    with pytest.raises(CaseError, match="too narrow for particles of diameter 0.5 m"):
        load_case("mini-1g-steer", ["soil.diameter_max=0.5"])
    with pytest.raises(CaseError, match="hub_radius"):
        load_case("mini-1g-steer", ["wheel.hub_radius=0.2"])


def test_units_convert_to_the_keys_unit_and_refuse_other_dimensions(tmp_path):
    case = load_case(write(tmp_path, '[test]\ndrive_time = "2500 ms"\nload = "2.5 kN"\nslip = "40 %"\n'
                                     'slip_angle = "0.1 rad"\n[soil]\ndiameter_min = "25 mm"\n'))
    assert case.test.drive_time == pytest.approx(2.5, rel=1e-15)
    assert case.test.load == 2500.0 and case.test.slip == pytest.approx(0.4)
    assert case.test.slip_angle == pytest.approx(math.degrees(0.1))
    assert case.soil.diameter_min == 0.025  # exactly as written in metres
    assert to_unit("37.5 mm", "m") == 0.0375
    with pytest.raises(UnitError, match="unit 'kN' does not fit this key; write it in s, ms, min"):
        to_unit("3 kN", "s")
    with pytest.raises(CaseError, match=r"test.drive_time = 'soon': 'soon' is not a number, or a number with a unit \(s, ms, min\)"):
        load_case(write(tmp_path, '[test]\ndrive_time = "soon"\n'))


def test_set_overrides_parse_toml_values_and_name_bad_keys():
    assert parse_override("test.slip=0.5") == (["test", "slip"], 0.5)
    assert parse_override("soil.gravity=moon") == (["soil", "gravity"], "moon")
    assert parse_override("soil.gravity=[0, 0, -1.62]") == (["soil", "gravity"], [0, 0, -1.62])
    assert parse_override('test.drive_time="800 ms"') == (["test", "drive_time"], "800 ms")
    case = load_case("smoke-1g-steer", ["test.slip=0.5", "soil.gravity=moon", "wheel.rigid=true"])
    assert (case.test.slip, case.soil.gravity, case.wheel.rigid) == (0.5, "moon", True)
    with pytest.raises(CaseError, match="unknown key test.slipp; did you mean test.slip"):
        load_case("smoke-1g-steer", ["test.slipp=0.5"])
    with pytest.raises(CaseError, match="is not section.key=value"):
        load_case("smoke-1g-steer", ["test.slip"])
    with pytest.raises(CaseError, match=r"with --set test.slip=2: test.slip = 2"):
        load_case("smoke-1g-steer", ["test.slip=2"])


def test_every_preset_round_trips_through_its_resolved_toml():
    names = preset_names()
    assert {"smoke-1g-steer", "smoke-moon-steer", "seed004-1g-steer", "seed004-moon-steer", "mini-1g-steer"} <= set(names)
    for name in names:
        case = load_case(name)
        text = case_to_toml(case)
        assert case_from_toml(text, name) == case, name
        assert case.name == name
        # the solver's objects build from every preset, once, into the run plan
        plan = build.plan(case)
        assert (plan.bed, plan.wheel, plan.test) == build.specs(case)
        assert plan.particles > 0 and plan.elements > 0 and plan.output_bytes > plan.particles


def test_case_hash_ignores_the_name_and_follows_the_physics():
    a = load_case("mini-1g-steer")
    assert load_case("mini-1g-steer", name="renamed").case_hash() == a.case_hash()
    assert load_case("mini-1g-steer", ["test.slip=0.31"]).case_hash() != a.case_hash()
    assert load_case("mini-1g-steer", ["case.seed=1"]).case_hash() != a.case_hash()


def test_the_windup_filter_reaches_the_rig_and_its_default_keeps_the_hash():
    a = load_case("smoke-moon-steer")
    assert load_case("smoke-moon-steer", ["test.windup_filter=0.04"]).case_hash() == a.case_hash()
    slow = load_case("smoke-moon-steer", ["test.windup_filter=0.098"])
    assert slow.case_hash() != a.case_hash()
    assert build.testbed_spec(slow).windup_filter == 0.098
    assert build.testbed_spec(a).windup_filter == 0.04


def test_the_rolling_law_reaches_every_soil_contact_and_the_default_keeps_the_hash():
    a = load_case("mini-1g-steer")
    assert load_case("mini-1g-steer", ["soil.rolling_model='cdt'"]).case_hash() == a.case_hash()
    epsd = load_case("mini-1g-steer", ["soil.rolling_model='epsd'"])
    assert epsd.case_hash() != a.case_hash()
    bed, test = build.bed_spec(epsd), build.testbed_spec(epsd)
    assert bed.pair.rolling_model == bed.wall_pair.rolling_model == test.pair.rolling_model == "epsd"
    assert build.bed_spec(a).cache_key() != bed.cache_key()
    assert build.bed_spec(a).pair.rolling_model == "cdt"


def test_presets_hold_the_seed004_settings():
    full = load_case("seed004-1g-steer")
    bed = build.bed_spec(full)
    assert (bed.length, bed.width, bed.depth, bed.diameter_min, bed.diameter_max) == (3.5, 1.0, 0.4, 0.016, 0.024)
    assert bed.material.youngs_modulus == 50e6 and bed.material.density == 3200.0  # seed 004 Table 1
    assert bed.pair.static_friction == 0.42 and bed.pair.rolling_friction == 0.11
    spec = build.testbed_spec(full)
    assert spec.pair.static_friction == 0.39 and spec.pair.rolling_friction == 0.15
    wheel = build.wheel_geometry(full)
    assert (wheel.radius, wheel.width) == (0.6, 0.5)
    assert wheel.radius * spec.angular_velocity == pytest.approx(0.6)  # r omega = 0.6 m/s
    moon = load_case("seed004-moon-steer")
    assert build.bed_spec(moon).gravity[2] == pytest.approx(-9.81 / 6) and moon.test.load == 500.0


def test_validate_case_refuses_a_non_table():
    with pytest.raises(CaseError, match="a case is a TOML table"):
        validate_case([1, 2], "x")


def test_cli_case_show_list_and_check(tmp_path, capsys):
    assert main(["case", "list"]) == EXIT_OK
    assert "mini-1g-steer" in capsys.readouterr().out
    assert main(["case", "show", "mini-1g-steer", "--set", "test.slip=0.4"]) == EXIT_OK
    text = capsys.readouterr().out
    assert "slip = 0.4  # [1] longitudinal slip" in text
    assert case_from_toml(text).test.slip == 0.4
    path = write(tmp_path, text)
    assert main(["case", "check", str(path)]) == EXIT_OK
    assert "valid" in capsys.readouterr().out
    assert main(["case", "check", str(write(tmp_path, "[test]\nslip = 3\n", "bad.toml"))]) == EXIT_INPUT
    assert "bad.toml: test.slip = 3" in capsys.readouterr().err


def test_case_show_from_a_fresh_process_is_a_valid_case_file(tmp_path):
    """stdout is only the case text (no Taichi banner), so `wheelsoil case show X > my.toml` works."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "wheelsoil.cases.cli", "case", "show", "smoke-moon-steer"],
                          capture_output=True, text=True, check=True)
    path = write(tmp_path, done.stdout, "copy.toml")
    assert load_case(path).name == "copy"  # a copy takes its own file name
    assert load_case(path, name="smoke-moon-steer") == load_case("smoke-moon-steer")


def test_prepare_bed_takes_a_case_or_options_not_both(capsys):
    assert main(["prepare-bed", "mini-1g-steer", "--length", "2"]) == EXIT_INPUT
    assert "--length does not go with a CASE: set the case's soil instead" in capsys.readouterr().err
    assert main(["prepare-bed", "--set", "soil.length=2"]) == EXIT_INPUT
    assert "--set needs a CASE" in capsys.readouterr().err
    assert main(["prepare-bed", "mini-1g-steer", "--set", "soil.lenght=2"]) == EXIT_INPUT
    assert "unknown key soil.lenght; did you mean soil.length?" in capsys.readouterr().err


def test_the_readme_example_case_is_the_preset_it_says(tmp_path):
    """README: 'this one is the smoke-moon-steer preset (the same case hash)' -- the example is a test."""
    import re
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    m = re.search(r"this one is the `([\w-]+)` preset.*?```toml\n(.*?)```", readme, re.S)
    assert m, "the README's example case block was not found"
    path = tmp_path / "example.toml"
    path.write_text(m.group(2))
    assert load_case(path, name=m.group(1)).case_hash() == load_case(m.group(1)).case_hash()


def test_steady_drift_confidence_reaches_the_rig_and_leaves_stored_hashes_alone():
    """output.steady_drift_confidence (added 2026-11-28) reaches the rig's spec; at its default of 0 a case keeps the
    hash it had before the key existed (stored runs are not rerun), and any other value is another case."""
    plain = load_case("smoke-1g-steer")
    explicit = load_case("smoke-1g-steer", ["output.steady_drift_confidence=0"])
    strict = load_case("smoke-1g-steer", ["output.steady_drift_confidence=0.5"])
    assert plain.case_hash() == explicit.case_hash() != strict.case_hash()
    assert build.testbed_spec(strict).steady_drift_confidence == 0.5
    with pytest.raises(CaseError, match="steady_drift_confidence"):
        load_case("smoke-1g-steer", ["output.steady_drift_confidence=-1"])
