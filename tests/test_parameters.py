"""Named parameter sets and ranges: one source of truth for every default and every allowed range.

* the seed-004 set equals the seed's own Tables 1--2 (read from ``../shared/seeds``);
* the case schema, the solver's specs and the command line default to the same smoke run;
* a range declared by a spec is the range the case schema enforces, at both ends.
"""

import math
import os
import re
from pathlib import Path

import pytest

from wheelsoil.cases import build
from wheelsoil.cases.cli import build_parser
from wheelsoil.cases.commands.prepare_bed import spec_from_args as cli_bed_spec
from wheelsoil.cases.schema import SECTIONS, CaseError, CaseFile, validate_case
from wheelsoil.coupling.rig import TestbedSpec
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.flexwheel.geometry import LUNAR_ROVER, WheelGeometry
from wheelsoil.granular.bed_spec import BedSpec
from wheelsoil.material import Material, PairProperties
from wheelsoil.parameters import seed004
from wheelsoil.ranges import Range

SEEDS = Path(__file__).resolve().parents[2] / "shared" / "seeds"


def _seed_table_value(text: str, label: str) -> str:
    for line in text.splitlines():
        if line.startswith(label):
            return line.split("\t")[-1].strip()
    raise AssertionError(f"no row {label!r} in seed 004's tables")


def test_seed004_set_is_the_seeds_tables_1_and_2():
    files = sorted(SEEDS.glob("004_*.txt"))
    if not files:
        if os.environ.get("CI") == "true":
            pytest.fail(f"seed 004 is missing under {SEEDS}")
        pytest.skip("seed 004 text not available")
    text = files[0].read_text(encoding="utf-8")
    number = lambda label: float(_seed_table_value(text, label))  # noqa: E731
    assert seed004.SOIL.density == number("Particle density")
    assert seed004.SOIL.youngs_modulus == number("Young’s modulus of lunar soil simulant") * 1e6
    assert seed004.SOIL.poisson_ratio == number("Poisson’s ratio of lunar soil simulant")
    prefix = "Lunar soil simulant–lunar soil simulant "
    assert seed004.SOIL_SOIL == PairProperties(number(prefix + "coefficient of restitution"),
                                               number(prefix + "static friction"), number(prefix + "rolling friction"))
    prefix = "Lunar soil simulant–steel "
    assert seed004.SOIL_STEEL == PairProperties(number(prefix + "coefficient of restitution"),
                                                number(prefix + "static friction"), number(prefix + "rolling friction"))
    assert seed004.WHEEL_RADIUS == number("Wheel radius") and seed004.WHEEL_WIDTH == number("Wheel width")
    assert seed004.WHEEL_MATERIAL.youngs_modulus == number("Young’s modulus of FEM elements") * 1e6
    assert seed004.WHEEL_MATERIAL.poisson_ratio == number("Poisson’s ratio of FEM elements")
    assert seed004.WHEEL_MATERIAL.density == number("Density of FEM elements")
    assert (seed004.BIN_LENGTH, seed004.BIN_WIDTH, seed004.BIN_DEPTH) == (
        number("Length of soil bin"), number("Width of soil bin"), number("Height of soil bin"))
    lo, hi = (float(v) / 1000 for v in re.split("[–-]", _seed_table_value(text, "Particle diameter")))
    assert (seed004.PARTICLE_DIAMETER_MIN, seed004.PARTICLE_DIAMETER_MAX) == (lo, hi)
    assert seed004.PARTICLES == int(_seed_table_value(text, "Number of DEM elements").replace(" ", ""))
    loads = [float(v) for v in _seed_table_value(text, "Vertical load").split(",")]
    assert seed004.LOAD_EARTH in loads and seed004.LOAD_MOON in loads
    slips = [float(v) / 100 for v in _seed_table_value(text, "Slip ratio").split(",")]
    assert list(seed004.SLIPS) == pytest.approx(slips)
    assert seed004.ANGULAR_VELOCITY * seed004.WHEEL_RADIUS == pytest.approx(0.6)  # "wheel speed 0.6 m/s"


def test_the_default_case_the_specs_and_the_command_line_agree():
    case = CaseFile()
    assert build.bed_spec(case) == BedSpec()
    assert build.testbed_spec(case) == TestbedSpec()
    assert build.wheel_geometry(case) == LUNAR_ROVER.with_element_size(case.wheel.element_size)
    args = build_parser().parse_args(["prepare-bed"])
    assert cli_bed_spec(args) == BedSpec()


# (schema section, key, spec class whose RANGES hold it, key there)
DELEGATED = [(s, k, TestbedSpec, k) for s in ("test", "output") for k in SECTIONS[s].model_fields
             if k in TestbedSpec.RANGES]
DELEGATED += [("soil", k, BedSpec, k) for k in SECTIONS["soil"].model_fields if k in BedSpec.RANGES]
DELEGATED += [("soil", k, Material, k) for k in ("youngs_modulus", "poisson_ratio", "density")]
DELEGATED += [(s, k, PairProperties, k) for s in ("soil", "contact") for k in PairProperties.RANGES]
DELEGATED += [("wheel", k, WheelGeometry, k) for k in SECTIONS["wheel"].model_fields if k in WheelGeometry.RANGES]
DELEGATED += [("wheel", k, Material, k) for k in ("youngs_modulus", "poisson_ratio", "density")]
DELEGATED += [("wheel", "damping", TestbedSpec, "damping"), ("soil", "time_step", TestbedSpec, "time_step"),
              ("case", "seed", BedSpec, "seed")]


def _outside(rng: Range) -> list:
    """Values just outside each bound (on it where the bound is open)."""
    out = []
    if rng.lo is not None:
        out.append(rng.lo if rng.lo_open else rng.lo - (1 if rng.integer else 1e-9 * max(1.0, abs(rng.lo))))
    if rng.hi is not None:
        out.append(rng.hi if rng.hi_open else rng.hi + (1 if rng.integer else 1e-9 * max(1.0, abs(rng.hi))))
    return out


@pytest.mark.parametrize("section, key, spec, spec_key", DELEGATED, ids=[f"{s}.{k}" for s, k, _, _ in DELEGATED])
def test_the_schema_enforces_the_specs_range(section, key, spec, spec_key):
    rng = spec.RANGES[spec_key]
    assert _outside(rng), f"{spec.__name__}.{spec_key} has no bound to test"
    for value in _outside(rng):
        assert not rng.contains(value)
        with pytest.raises(CaseError, match=re.escape(f"{section}.{key} = {value!r}")):
            validate_case({section: {key: value}}, "test")
    if rng.lo is not None and rng.hi is not None:  # the bounds themselves where closed
        for value in [v for v, closed in ((rng.lo, not rng.lo_open), (rng.hi, not rng.hi_open)) if closed]:
            assert rng.contains(value)


def test_a_range_names_the_key_the_value_and_the_bounds():
    with pytest.raises(WheelsoilInputError, match=re.escape("testbed slip = 1.0 is out of range: allowed -1 <= slip < 1")):
        TestbedSpec(slip=1.0)
    with pytest.raises(WheelsoilInputError, match=re.escape("bed length = -2.0 m is out of range: allowed 0 < length (m)")):
        BedSpec(length=-2.0)
    with pytest.raises(WheelsoilInputError, match=re.escape("an integer 1 <= steady_checks <= 10")):
        TestbedSpec(steady_checks=2.5)
    with pytest.raises(WheelsoilInputError, match=re.escape("testbed load = nan N is out of range")):
        TestbedSpec(load=math.nan)
    with pytest.raises(WheelsoilInputError, match="testbed slip = True"):  # a bool is not a number
        TestbedSpec(slip=True)
    assert Range(0.0, 1.0).contains(0.0) and not Range(0.0, 1.0, lo_open=True).contains(0.0)
    assert Range(0.0, 1.0, infinite=True).contains(math.inf) and not Range(0.0, 1.0).contains(math.inf)


def test_the_readme_s_python_example_builds_the_three_specs():
    from wheelsoil.cases import load_case, specs

    bed, wheel, test = specs(load_case("smoke-moon-steer", ["test.slip=0.4"]))
    assert isinstance(bed, BedSpec) and isinstance(wheel, WheelGeometry) and isinstance(test, TestbedSpec)
    assert test.slip == 0.4 and bed.gravity[2] == pytest.approx(-9.81 / 6) and wheel.name == "lunar-rover"
