"""The plain descriptions load without the engine (issue 38 item 1): a case file is read, validated and checked
against the machine (``check_fits``: memory, time step, load, the bin's fit and drive) with Taichi unimportable, and
the engine's names still load on first use from ``wheelsoil.granular``."""

import subprocess
import sys
import textwrap

import pytest

from wheelsoil.cases.schema import preset_names

BLOCK_TAICHI = textwrap.dedent("""
    import importlib.abc, sys
    class _NoTaichi(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path, target=None):
            if name == "taichi" or name.startswith("taichi."):
                raise ImportError("taichi is blocked in this check")
    sys.meta_path.insert(0, _NoTaichi())
""")


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", BLOCK_TAICHI + textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=120)


@pytest.mark.parametrize("preset", preset_names())
def test_case_is_checked_without_taichi(preset):
    done = _run(f"""
        from wheelsoil.cases import build, schema
        from wheelsoil.coupling.rig import check_fits
        case = schema.load_case({preset!r})
        start_x = check_fits(*build.specs(case))
        assert start_x > 0, start_x
        assert "taichi" not in sys.modules
        print("checked", start_x)
    """)
    assert done.returncode == 0, done.stderr
    assert "checked" in done.stdout


def _refusal(preset: str, overrides: list[str]) -> str:
    """The error the case check gives ``preset`` with ``overrides``, checked in a process where Taichi is blocked."""
    done = _run(f"""
        from wheelsoil.cases import schema
        from wheelsoil.errors import WheelsoilInputError
        try:
            schema.load_case({preset!r}, {overrides!r})
        except WheelsoilInputError as exc:
            print("refused:", exc)
        assert "taichi" not in sys.modules
    """)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("refused:"), done.stdout
    return done.stdout


def test_bad_case_is_refused_without_taichi():
    """The fit checks' errors (here a wheel wider than the bin) come before any engine is loaded."""
    assert "does not fit the bed width" in _refusal("mini-1g-steer", ["soil.width=0.05"])


def test_a_load_no_bed_could_carry_is_refused_before_any_work():
    """A load beyond the bed's bearing bound (``coupling.rig.load_bound``: 5 kN on the CMU wheel, a smoke rig's load
    in the wrong unit) is refused by the case check, naming the key, the value and the bound, with Taichi
    unloaded; the presets' own loads pass (``test_case_is_checked_without_taichi``)."""
    said = _refusal("cmu-grouser", ["test.load=5000"])
    assert "test.load = 5000 N is more than this bed can carry" in said
    assert "at most 3" in said  # about 3.6 kN for the grousered wheel


def test_the_load_bound_is_above_what_the_measured_sand_carried(measured_dir):
    """The bound is an upper one: for both CMU wheels it exceeds the largest force the measured sand carried when the
    same wheels were pressed to the bound's depth (``force_displacement/wheel_sinkage.csv``, every box and repeat,
    sinkage from first contact), and the CMU trials' loads (22-26 N) lie far below it."""
    import csv
    from pathlib import Path

    from wheelsoil.cases import build, schema
    from wheelsoil.coupling.rig import load_bound

    path = Path(measured_dir) / "cmu_3d_terramechanics" / "force_displacement" / "wheel_sinkage.csv"
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    for preset, wheel in (("cmu-grouser", "grouser"), ("cmu-smooth", "smooth")):
        bed, geometry, test = build.specs(schema.load_case(preset))
        bound, _, depth = load_bound(bed, geometry)
        pressed = [float(r["force_N"]) for r in rows
                   if r["wheel"] == wheel and r["branch"] == "loading" and float(r["sinkage_mm"]) <= 1e3 * depth]
        assert len(pressed) > 100, preset
        assert bound > max(pressed), (preset, bound, max(pressed))
        assert bound > 100 * test.load, (preset, bound, test.load)


def test_engine_names_load_on_first_use():
    from wheelsoil import granular
    from wheelsoil.granular.scene import Scene

    assert granular.Scene is Scene
    assert "prepare_bed" in granular.__all__ and callable(granular.prepare_bed)
    with pytest.raises(AttributeError, match="no attribute 'not_a_name'"):
        granular.not_a_name  # noqa: B018


def test_scene_plain_parts_load_without_taichi():
    """The scene's box, input checks and checkpoint are plain NumPy (issue 38 item 5)."""
    done = _run("""
        import numpy as np
        from wheelsoil.granular.scene_checkpoint import SceneCheckpoint
        from wheelsoil.granular.scene_domain import SceneDomain
        from wheelsoil.granular.scene_input import checked_spheres
        x, r, v, w = checked_spheres([[0.5, 0.5, 0.5]], 0.01)
        assert SceneDomain.of((0, 0, 0), (1, 1, 1)).outside(x).size == 0
        assert "taichi" not in sys.modules
        print("plain")
    """)
    assert done.returncode == 0, done.stderr
    assert "plain" in done.stdout
