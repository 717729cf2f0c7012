"""The scripts under docs/ that regenerate the studies (issue 38 item 7): each loads, and every wheelsoil name it
imports -- at the top or inside a function, where most import the engine -- exists, so a moved or renamed name
breaks a test here instead of the next campaign. (Running them is hours of DEM each; their commands are in docs/.)"""

import ast
import importlib
import importlib.util
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
SCRIPTS = sorted(DOCS.glob("*.py"))


def test_the_docs_have_their_scripts():
    assert len(SCRIPTS) >= 10


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_a_docs_script_loads_and_its_wheelsoil_imports_exist(script, monkeypatch):
    monkeypatch.syspath_prepend(str(DOCS))  # the scripts import their siblings, as when run from the repository root
    spec = importlib.util.spec_from_file_location(f"docs_{script.stem}", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for node in ast.walk(ast.parse(script.read_text(), filename=str(script))):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("wheelsoil"):
            target = importlib.import_module(node.module)
            for alias in node.names:
                assert hasattr(target, alias.name) or importlib.util.find_spec(f"{node.module}.{alias.name}"), \
                    f"{script.name} line {node.lineno}: {node.module} has no {alias.name}"
    sys.modules.pop(f"docs_{script.stem}", None)


def _load(name: str):
    spec = importlib.util.spec_from_file_location(f"docs_{name}", DOCS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_twin_queue_links_a_finished_run_as_a_bin_checks_reference(tmp_path):
    """The CMU twin's queue (docs/cmu_twin_queue.py) gives a convergence study the sweep's finished run of the same
    case as its reference, and nothing unfinished or already there."""
    from wheelsoil.cases.run import RESULT_NAME
    from wheelsoil.cases.schema import load_case

    queue = _load("cmu_twin_queue")
    case = DOCS / "cmu-twin" / "bin-check" / "cmu-90-driving.toml"
    digest = load_case(case).case_hash()
    runs, out = tmp_path / "runs", tmp_path / "runs" / "bin-check"
    run = runs / "some-sweep" / "cases" / digest
    run.mkdir(parents=True)
    assert queue.link_reference(runs, out, str(case)) is None  # not finished: nothing to link
    (run / RESULT_NAME).write_bytes(b"")
    assert queue.link_reference(runs, out, str(case)) == run
    assert (out / "cases" / digest).resolve() == run.resolve()
    assert queue.link_reference(runs, out, str(case)) is None  # linked before: kept as it is
    other = runs / "some-sweep" / "cases" / "0123456789abcdef"
    other.mkdir()
    (other / RESULT_NAME).write_bytes(b"")
    assert sorted(p.name for p in (out / "cases").iterdir()) == [digest]  # only the case's own hash
