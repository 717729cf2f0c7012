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


def test_bad_case_is_refused_without_taichi():
    """The fit checks' errors (here a wheel wider than the bin) come before any engine is loaded."""
    done = _run("""
        from wheelsoil.cases import schema
        from wheelsoil.errors import WheelsoilInputError
        try:
            schema.load_case("mini-1g-steer", ["soil.width=0.05"])
        except WheelsoilInputError as exc:
            print("refused:", exc)
        assert "taichi" not in sys.modules
    """)
    assert done.returncode == 0, done.stderr
    assert "refused:" in done.stdout and "does not fit the bed width" in done.stdout


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
