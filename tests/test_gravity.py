"""One place names the gravity levels; every layer that names one agrees with it."""

import pytest

from wheelsoil.gravity import EARTH_GRAVITY, GRAVITY_PRESETS, MOON_GRAVITY, gravity_label, gravity_name


def test_the_levels_and_their_names():
    assert MOON_GRAVITY == pytest.approx(EARTH_GRAVITY / 6)  # seed 004: 1/6 g
    assert gravity_name(9.81) == "earth" and gravity_name(-1.635) == "moon" and gravity_name(3.71) is None
    assert gravity_label(9.8) == "1g" and gravity_label(1.64) == "1/6 g" and gravity_label(3.71) == "3.71 m/s²"
    assert gravity_label(1.635, moon="moon", other="g={g:.3g}") == "moon"


def test_case_files_and_the_command_line_use_the_same_presets():
    from wheelsoil.cases import case_model
    from wheelsoil.cases.commands import prepare_bed
    from wheelsoil.cases.schema import load_case

    assert prepare_bed.GRAVITY_PRESETS is GRAVITY_PRESETS and case_model.GRAVITY_PRESETS is GRAVITY_PRESETS
    case = load_case("smoke-moon-steer")
    assert -case.soil.gravity_vector[2] == pytest.approx(MOON_GRAVITY)
