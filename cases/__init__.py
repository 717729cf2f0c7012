"""Case files, runs, results, sweeps, renders and the ``wheelsoil`` command line.

* :mod:`.schema` -- the TOML case file and its pydantic schema (:func:`load_case`, :func:`case_to_toml`);
* :mod:`.units` -- values with units in case files;
* :mod:`.build` -- a case's solver specs: bed, wheel and rig (:func:`specs`), and its run plan (:func:`plan`);
* :mod:`.run` -- one run from a case: bed, testbed, result file, checkpoints (:func:`run_case`);
* :mod:`.results` -- the HDF5 result layout, its XDMF sidecar and the results API (:func:`load_result`);
* :mod:`.sweep` -- batch sweeps on local processes or a dask.distributed cluster;
* :mod:`.plots`, :mod:`.render` -- matplotlib plots and pyvista offscreen renders;
* :mod:`.cli` -- the ``wheelsoil`` command.

The names below are imported on first use, so that ``wheelsoil --help`` starts quickly.
"""

_EXPORTS = {
    "load_case": "schema", "case_to_toml": "schema", "case_from_toml": "schema", "CaseFile": "schema",
    "CaseError": "schema", "preset_names": "schema",
    "specs": "build", "plan": "build", "RunPlan": "build", "bed_spec": "build", "wheel_geometry": "build", "testbed_spec": "build",
    "run_case": "run",
    "load_result": "results", "Result": "results",
    "load_sweep": "sweep", "run_sweep": "sweep",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        from importlib import import_module

        return getattr(import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
