"""The README's Python blocks are tests (issue 38 item 7), so a documented example cannot rot: every block compiles
and every name it imports exists; the blocks that run in seconds run here as written, the others (a whole run, a
full-size bed, a plate test: minutes each) are the commands the slow tier and the run tests already cover, so only
their names are checked."""

import ast
import builtins
import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
#: Blocks that run in seconds, by a line each holds (so a reordered README keeps them); the wheel's (10 s, a
#: 0.01 m ExoMars mesh) runs in the slow tier.
QUICK = ("scene = Scene(domain_min", pytest.param("mesh, hub = build_wheel_mesh(EXOMARS", marks=pytest.mark.slow),
         "from wheelsoil.parameters import cmu_sand")
MARKERS = ("scene = Scene(domain_min", "mesh, hub = build_wheel_mesh(EXOMARS", "from wheelsoil.parameters import cmu_sand")


def _imports(tree: ast.Module):
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            for alias in node.names:
                yield node.module, alias.name
        elif isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, None


def test_the_readme_has_its_examples():
    assert len(BLOCKS) >= 5
    assert all(any(marker in block for block in BLOCKS) for marker in MARKERS)


def _undefined(tree: ast.Module) -> set[str]:
    """Names a block reads but never binds (a script's blocks bind by assignment, import, loop or comprehension)."""
    bound = set(dir(builtins))
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            bound.add(node.id)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            bound.update((a.asname or a.name).split(".")[0] for a in node.names)
        elif isinstance(node, ast.arg):
            bound.add(node.arg)
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)} - bound


@pytest.mark.parametrize("k", range(len(BLOCKS)))
def test_every_block_compiles_and_imports_names_that_exist(k):
    import importlib

    tree = ast.parse(BLOCKS[k], filename=f"README block {k}")
    assert not _undefined(tree), f"README block {k} reads names it never defines: {sorted(_undefined(tree))}"
    for module, name in _imports(tree):
        mod = importlib.import_module(module)
        if name is not None:
            assert hasattr(mod, name) or importlib.util.find_spec(f"{module}.{name}") is not None, \
                f"README block {k}: {module} has no {name}"


@pytest.mark.parametrize("marker", QUICK)
def test_the_quick_blocks_run_as_written(marker, tmp_path, monkeypatch):
    block = next(b for b in BLOCKS if marker in b)
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(block, f"README block ({marker})", "exec"), namespace)
    assert len(namespace) > 1
