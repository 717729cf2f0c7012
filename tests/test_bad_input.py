"""Bad input from the command line is a clean error before any work: exit status 2, a message naming the key
or path, its value and what is allowed, and no traceback (issue 19's list: binary case files, output places
that cannot be written, physically impossible or machine-breaking values, frames finer than samples)."""

import pytest

from wheelsoil.cases.cli import EXIT_INPUT, main

@pytest.fixture()
def a_file(tmp_path):
    path = tmp_path / "a-file"
    path.write_text("not a folder\n")
    return path


def _refused(argv, capsys, *needles):
    assert main(argv) == EXIT_INPUT
    err = capsys.readouterr().err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in err, err
    return err


def test_a_binary_case_or_sweep_file(tmp_path, capsys):
    garbage = tmp_path / "garbage.toml"
    garbage.write_bytes(b"\x89PNG\r\n\x1a\n\x00\xff binary")
    _refused(["case", "check", str(garbage)], capsys, "garbage.toml", "not a TOML text file")
    _refused(["batch", str(garbage), "--out", str(tmp_path / "sweep")], capsys, "not a TOML text file")


@pytest.mark.parametrize("where", ["under-a-file", "a-file", "proc"])
def test_an_output_folder_that_cannot_be_written(where, a_file, tmp_path, capsys):
    out = {"under-a-file": a_file / "sub", "a-file": a_file, "proc": "/proc/wheelsoil-test"}[where]
    _refused(["run", "mini-1g-steer", "--out", str(out)], capsys, "--out", str(out))


@pytest.mark.parametrize("override, needles", [
    ("soil.youngs_modulus=1e15", ["soil.youngs_modulus", "1.2e+12"]),
    ("wheel.youngs_modulus=1e13", ["wheel.youngs_modulus", "1.2e+12"]),
    ("test.load=1e9", ["test.load = 1e+09 N", "at most"]),
    ("output.frame_interval=1e-9", ["output.frame_interval = 1e-09 s", "output.sample_interval"]),
    ("output.checkpoint_interval=1e-4", ["output.checkpoint_interval", "output.sample_interval"]),
    ("wheel.element_size=1e-5", ["wheel.element_size = 1e-05 m", "GiB"]),
    ("soil.diameter_min=0.001", ["soil.diameter_min", "GiB"]),
    ("soil.time_step=1e-2", ["soil.time_step = 0.01 s exceeds the stable time step"]),
    ("output.sample_interval=1e-12", ["output.sample_interval = 1e-12 s is shorter than the run's DEM step"]),
])
def test_values_a_run_cannot_survive_are_refused_by_case_check(override, needles, capsys):
    big = override.startswith("soil.diameter_min")  # 1-1.5 mm in the smoke bin: ~2e8 spheres, ~900 GiB
    extra = ["--set", "soil.diameter_max=0.0015"] if big else []
    _refused(["case", "check", "smoke-1g-steer" if big else "mini-1g-steer", "--set", override, *extra], capsys,
             *needles)


def test_a_sample_shorter_than_the_dem_step_is_refused_before_the_drive(tmp_path, capsys):
    _refused(["run", "mini-1g-steer", "--set", "output.sample_interval=1e-12", "--set", "output.frame_interval=0",
              "--set", "output.checkpoint_interval=0", "--out", str(tmp_path / "run")], capsys,
             "output.sample_interval = 1e-12 s is shorter than the run's DEM step")


def test_render_and_report_places_are_checked_before_work(tmp_path, a_file, capsys):
    """The report folder is checked before the data are even read (the data path need not exist)."""
    from wheelsoil.granular import BedSpec, prepare_bed

    bed = prepare_bed(BedSpec(length=0.2, width=0.1, depth=0.03, diameter_min=0.01, diameter_max=0.012, periodic=False),
                      cache_dir=tmp_path / "cache")
    path = bed.save(tmp_path / "bed.h5")
    _refused(["render", str(path), "--out", str(tmp_path)], capsys, "is a folder; give a file name")
    _refused(["render", str(path), "--out", str(a_file / "x.png")], capsys, "is a file, not a folder")
    _refused(["validate", str(tmp_path / "no-data.csv"), "--report", str(a_file / "report")], capsys, "--report",
             "is a file")


@pytest.mark.parametrize("change, needle", [
    ("drop-responses", "no measured response in any row"),
    ("text-slip", "the condition 'slip' must be a number in every row; data row 4 holds 'abc'"),
    ("negative-loads", "no row to fit in the domain 'all': 27 of 27 rows lie outside it"),
    ("missing-load", "the condition 'load' is missing (empty or NaN) in data row(s) [3]"),
])
def test_measured_files_the_model_cannot_use(change, needle, measured_dir, tmp_path, capsys):
    import os

    import pandas as pd

    data = pd.read_csv(os.path.join(measured_dir, "digitised_single_wheel", "single_wheel_experiments.csv"))
    if change == "drop-responses":
        data = data.drop(columns=["meas_drawbar_pull_n", "meas_torque_nm", "meas_sinkage_m"])
    elif change == "text-slip":
        data["slip"] = data["slip"].astype(object)
        data.loc[3, "slip"] = "abc"
    elif change == "negative-loads":
        data["vertical_load_n"] = -data["vertical_load_n"]
    else:
        data.loc[2, "vertical_load_n"] = float("nan")
    path = tmp_path / "bad.csv"
    data.to_csv(path, index=False)
    _refused(["validate", str(path), "--report", str(tmp_path / "report")], capsys, needle)


@pytest.mark.parametrize("change, needle", [
    ("sideways-without-travel-slip", "column 'travel_slip' in data row 2 (slip 1, slip_angle 90 deg, travel_slip nan"),
    ("travel-slip-disagrees", "column 'slip' in data row 1 (slip 0.2, slip_angle 30 deg, travel_slip 0.5"),
    ("slip-out-of-range", "column 'slip' in data row 3 (slip -1.5"),
    ("angle-out-of-range", "column 'slip_angle' in data row 1 (slip 0.2, slip_angle 120 deg"),
])
def test_rows_whose_motion_the_model_cannot_be_told_are_refused(change, needle, tmp_path, capsys):
    """wheelsoil's CSV format: a 90 deg row needs the slip against the travel speed; the two slips must agree."""
    rows = {"slip": [0.2, 1.0, -0.5], "slip_angle_deg": [30.0, 90.0, 0.0], "vertical_load_N": [20.0, 20.0, 20.0],
            "wheel_radius_m": [0.058] * 3, "wheel_width_m": [0.05] * 3, "drawbar_pull_N": [1.0, 2.0, -3.0]}
    if change == "travel-slip-disagrees":
        rows["travel_slip"] = [0.5, 0.5, -0.5]
    elif change == "slip-out-of-range":
        rows["slip"][2], rows["travel_slip"] = -1.5, [float("nan"), 0.5, float("nan")]
    elif change == "angle-out-of-range":
        rows["slip_angle_deg"][0] = 120.0
    path = tmp_path / "rows.csv"
    path.write_text(",".join(rows) + "\n" + "\n".join(",".join(str(v[k]) for v in rows.values()) for k in range(3)) + "\n")
    _refused(["validate", str(path), "--report", str(tmp_path / "report")], capsys, needle)


def test_a_pour_friction_factor_outside_zero_to_three_is_refused(tmp_path, capsys):
    _refused(["soil-lab", "plate", "--pour-friction-factor", "3.5", "--out", str(tmp_path / "lab")], capsys,
             "pour_friction_factor = 3.5", "0 <= pour_friction_factor <= 3")
    _refused(["prepare-bed", "smoke-1g-steer", "--set", "soil.pour_friction_factor=-0.5", "--out",
              str(tmp_path / "bed")], capsys, "soil.pour_friction_factor")


def test_a_soil_lab_checkpoint_of_no_samples_or_of_a_test_that_keeps_none_is_refused(tmp_path, capsys):
    _refused(["soil-lab", "plate", "--checkpoint-every", "0", "--out", str(tmp_path / "lab")], capsys,
             "--checkpoint-every = 0", ">= 1")
    _refused(["soil-lab", "shear", "--checkpoint-every", "5", "--out", str(tmp_path / "lab")], capsys,
             "--checkpoint-every = 5", "plate and wheel tests only")


def test_a_box_for_a_soil_lab_test_with_its_own_apparatus_is_refused_and_the_poured_bed_takes_it(tmp_path, capsys):
    from wheelsoil.cases.cli import build_parser
    from wheelsoil.cases.commands import soil_lab

    _refused(["soil-lab", "repose", "--box", "0.6", "0.6", "0.12", "--out", str(tmp_path / "lab")], capsys,
             "--box 0.6 0.6 0.12", "the repose test has its own apparatus")
    _refused(["soil-lab", "shear", "--box", "0.6", "0.6", "0.12", "--out", str(tmp_path / "lab")], capsys,
             "the shear test has its own apparatus")
    args = build_parser().parse_args(["soil-lab", "poured", "--box", "0.3", "0.3", "0.24", "--seeds", "0"])
    _, bed, _ = soil_lab._specs(args)
    assert (bed.length, bed.width, bed.depth) == (0.3, 0.3, 0.24)  # a poured bed in the box asked for


def test_the_soil_labs_speed_sets_the_shear_box_or_the_press_and_is_refused_where_there_is_none(tmp_path, capsys):
    """--speed: the shear box's shear speed for the shear test, the pressing speed for plate and wheel, each test's own
    default without it; a test without a speed, or a speed outside the spec's range, is refused naming the value."""
    from wheelsoil.cases.cli import build_parser
    from wheelsoil.cases.commands import soil_lab
    from wheelsoil.parameters import soil_lab as lab

    def spec(*argv):
        return soil_lab._specs(build_parser().parse_args(["soil-lab", *argv]))[2]

    assert spec("shear", "--speed", "0.01").speed == 0.01
    assert spec("shear").speed == lab.SHEAR["speed"]
    assert [s.speed for s in spec("plate", "--speed", "0.015")] == [0.015] * len(lab.PLATE_DIAMETERS)
    assert [s.speed for s in spec("plate")] == [lab.PRESS["speed"]] * len(lab.PLATE_DIAMETERS)
    assert spec("wheel", "--speed", "0.02").speed == 0.02
    _refused(["soil-lab", "repose", "--speed", "0.01", "--out", str(tmp_path / "lab")], capsys,
             "--speed 0.01", "the repose test has no speed")
    _refused(["soil-lab", "shear", "--speed", "2", "--out", str(tmp_path / "lab")], capsys, "speed = 2")
