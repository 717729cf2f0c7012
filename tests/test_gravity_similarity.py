"""Gravity similarity (wheelsoil.cases.similarity): at gravity g / tau^2 with every modulus divided by tau^2, time
stretched by tau (the DEM step too) and velocities divided by tau, the soil must trace the same path: positions equal
at corresponding steps, velocities in the ratio 1/tau. Newton's law, the Hertz--Mindlin law with its damping, Coulomb
friction and both rolling laws are homogeneous in these units, so only round-off separates the two runs; a constant
with a dimension hidden anywhere in the granular step (a damping or creep rate in absolute time, a floor in m/s)
breaks it. The case-level transform is checked here too: every key with a unit of time is scaled."""

import math

import numpy as np
import pytest

from wheelsoil.cases.schema import load_case
from wheelsoil.cases.similarity import TIME_EXPONENT, scaled_keys, similar_case
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.granular import Scene
from wheelsoil.material import Material, PairProperties

TAU = math.sqrt(6.0)
SOIL = Material("similarity soil", youngs_modulus=50e6, poisson_ratio=0.3, density=3200.0)
WALL = Material("similarity wall", youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)


def _scaled(m: Material, factor: float) -> Material:
    return Material(m.name, youngs_modulus=m.youngs_modulus * factor, poisson_ratio=m.poisson_ratio,
                    density=m.density)


def _dropped_box(seed: int, tau: float, rolling_model: str) -> Scene:
    """150 spheres thrown into a box, at gravity 9.81 / tau^2 with moduli / tau^2, DEM step and velocities scaled."""
    rng = np.random.default_rng(seed)
    grid = np.stack(np.meshgrid(np.arange(5), np.arange(5), np.arange(6), indexing="ij"), -1).reshape(-1, 3)
    x = 0.015 + grid * 0.021 + rng.uniform(-1e-3, 1e-3, grid.shape)
    r = rng.uniform(0.006, 0.0105, len(x))
    v = rng.normal(0.0, 0.3, x.shape) / tau
    w = rng.normal(0.0, 20.0, x.shape) / tau
    pair = PairProperties(0.5, 0.42, 0.11, rolling_model)
    s = Scene((0, 0, 0), (0.12, 0.12, 0.3), gravity=(0.0, 0.0, -9.81 / tau**2), material=_scaled(SOIL, tau**-2),
              pair=pair)
    s.add_box_walls(material=_scaled(WALL, tau**-2), pair=pair)
    s.add_spheres(x, r, velocities=v, angular_velocities=w)
    s.time_step = 5e-5 * tau
    return s


@pytest.mark.parametrize("rolling_model", ["cdt", "epsd"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_granular_run_at_a_sixth_of_gravity_with_scaled_units_traces_the_same_path(seed, rolling_model):
    earth, moon = _dropped_box(seed, 1.0, rolling_model), _dropped_box(seed, TAU, rolling_model)
    for _ in range(4):  # 800 steps: the spheres fall, collide and pile up on the floor (many contacts made and lost)
        earth.step(200)
        moon.step(200)
        x_e, x_m = earth.positions, moon.positions
        # round-off amplified by the pile's collisions, against mm-sized paths: 1e-9 m is far below any physics
        assert np.abs(x_m - x_e).max() < 1e-9
        np.testing.assert_allclose(moon.velocities * TAU, earth.velocities, rtol=0, atol=1e-7)
    assert np.abs(earth.positions[:, 2] - earth.positions[:, 2].min()).max() > 0.02  # a pile, not a point
    assert np.abs(earth.velocities).max() > 0.05  # still moving: the comparison was made in motion


def test_the_case_transform_scales_every_key_with_a_time_and_keeps_lengths():
    base = load_case("smoke-1g-steer")
    moon = similar_case(base, "moon")
    tau = math.sqrt(9.81 / moon.soil.gravity_vector[2] * -1)
    assert tau == pytest.approx(TAU)
    data, scaled = base.model_dump(), moon.model_dump()
    keys = scaled_keys(base)
    # every key the schema gives a unit: scaled by tau to its time exponent, the rest unchanged
    for dotted, exponent in keys.items():
        section, key = dotted.split(".")
        assert scaled[section][key] == pytest.approx(data[section][key] * TAU**exponent), dotted
    assert {"test.angular_velocity", "test.load", "soil.youngs_modulus", "output.sample_interval",
            "test.windup_filter", "wheel.damping"} <= set(keys)
    assert scaled["soil"]["diameter_min"] == data["soil"]["diameter_min"]
    assert scaled["test"]["slip"] == data["test"]["slip"]
    # the defaults computed at run time, made explicit and scaled: the wheel's modulus (800 MPa, seed 004) and the
    # slide damper (wheel mass / 0.1 s)
    assert moon.wheel.youngs_modulus == pytest.approx(800e6 / 6)
    assert moon.test.load == pytest.approx(500.0)
    assert moon.test.axle_damping > 0
    kept = similar_case(base, "moon", keep=("soil.youngs_modulus", "wheel.youngs_modulus"))
    assert kept.soil.youngs_modulus == 50e6 and kept.wheel.youngs_modulus == 800e6
    assert kept.test.angular_velocity == pytest.approx(1.0 / TAU)
    assert kept.case_hash() != moon.case_hash() != base.case_hash()
    with pytest.raises(WheelsoilInputError, match="soil.density"):
        similar_case(base, "moon", keep=("soil.density",))


def test_every_unit_of_the_case_schema_has_a_time_exponent():
    """A key added with a new unit must say how it scales, or the transform would skip it silently."""
    from wheelsoil.cases.case_model import CaseFile

    units = set()
    for section in CaseFile.model_fields.values():
        for field in section.annotation.model_fields.values():
            extra = field.json_schema_extra
            if isinstance(extra, dict) and extra.get("unit"):
                units.add(extra["unit"])
    assert units <= set(TIME_EXPONENT), units - set(TIME_EXPONENT)


@pytest.mark.slow  # two runs of the mini testbed, ~2 min
def test_the_coupled_testbed_at_a_sixth_of_gravity_with_scaled_units_is_the_same_run(bed_cache):
    """The mini case and its similar case at 1/6 g (``similar_case``) on the same bed (velocities / tau, rolling
    torques / 6; the bin walls' modulus / 6 too, which the case cannot reach): the wheel pressed into the soil gives the
    same forces times 6 at the same rows. The wheel in dense soil amplifies round-off fast (a 1e-15 change of the bed's
    velocities grows to 1e-9 of the load by 0.04 s and to the load's own size by 0.3 s), so the rows up to 0.04 s are
    held to 1e-7 of the largest force: the scaled run stayed within 6e-10 of it; with the walls left at 210 GPa it is
    6e-7 off, with the wheel's damping unscaled 1e-2."""
    import dataclasses

    from wheelsoil.cases import build
    from wheelsoil.coupling.testbed import Testbed
    from wheelsoil.granular import prepare_bed

    settings = ["soil.periodic=false", "soil.time_step=4e-5", "test.drive_time=0.08", "test.stop_when_steady=false",
                "output.average_time=0.02", "output.frame_interval=0", "output.checkpoint_interval=0",
                "output.render=false"]  # the DEM step set: the stable estimate binds differently at each gravity
    base = load_case("mini-1g-steer", settings)
    moon = similar_case(base, "moon")
    bed_e, wheel_e, run_e = build.specs(base)
    bed_m, wheel_m, run_m = build.specs(moon)
    walls = _scaled(bed_m.wall_material, 1 / 6)
    bed = prepare_bed(bed_e, cache_dir=bed_cache)
    history = dataclasses.replace(bed.history, pair_roll=bed.history.pair_roll / 6,
                                  roll_wall=bed.history.roll_wall / 6)
    bed_moon = dataclasses.replace(bed, spec=dataclasses.replace(bed_m, wall_material=walls),
                                   velocities=bed.velocities / TAU, angular_velocities=bed.angular_velocities / TAU,
                                   history=history)
    earth = Testbed(bed, wheel_e, run_e).run()
    scaled = Testbed(bed_moon, wheel_m, run_m).run()
    assert scaled.info["dem_time_step"] == pytest.approx(earth.info["dem_time_step"] * TAU, rel=1e-12)
    assert scaled.info["dem_steps"] == earth.info["dem_steps"]
    t = earth.series["t"]
    np.testing.assert_allclose(scaled.series["t"] / TAU, t, rtol=1e-12, atol=1e-12)
    early = t <= 0.04 + 1e-9
    assert early.sum() >= 8
    assert earth.series["vertical_force"][early].max() > 5.0  # the wheel is in the soil within the rows compared
    for name in ("vertical_force", "drawbar_pull", "lateral_force", "torque"):
        a, b = earth.series[name], scaled.series[name] * 6.0
        scale = np.abs(a).max()
        assert np.abs(b[early] - a[early]).max() <= 1e-7 * scale, name
    np.testing.assert_allclose(scaled.series["sinkage"][early], earth.series["sinkage"][early], rtol=0, atol=1e-9)


def test_the_case_command_prints_the_similar_case_and_refuses_bad_input(tmp_path, capsys):
    from wheelsoil.cases.cli import EXIT_INPUT, EXIT_OK, main

    assert main(["case", "similar", "smoke-1g-steer", "--gravity", "moon", "--keep", "soil.youngs_modulus"]) == EXIT_OK
    text = capsys.readouterr().out
    path = tmp_path / "moon.toml"
    path.write_text(text)
    printed = load_case(str(path))
    expected = similar_case(load_case("smoke-1g-steer"), "moon", keep=("soil.youngs_modulus",))
    assert printed.case_hash() == expected.case_hash()
    for argv, needle in ((["case", "similar", "smoke-1g-steer"], "needs --gravity"),
                         (["case", "similar", "smoke-1g-steer", "--gravity", "2000"], "(0, 1000)"),
                         (["case", "similar", "smoke-1g-steer", "--gravity", "moon", "--keep", "soil.density"],
                          "soil.density")):
        assert main(argv) == EXIT_INPUT
        err = capsys.readouterr().err
        assert needle in err and "Traceback" not in err, err
