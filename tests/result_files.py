"""Finished result files written without the engine, as :func:`wheelsoil.cases.run.run_case` writes them (the
resolved case, a summary per stage, short series, no frames): for tests of what reads results (result readers, sweep
tables, the docs' scripts)."""

from pathlib import Path

import numpy as np

from wheelsoil.cases.results import ResultWriter
from wheelsoil.cases.run import RESULT_NAME
from wheelsoil.cases.schema import case_to_toml
from wheelsoil.coupling.run_summary import SERIES_UNITS, QuantityStats, RunSummary


def summary(slip: float, *, steady: bool = True, window: tuple = (1.0, 2.0), slip_angle: float = 10.0,
            **quantities: tuple) -> RunSummary:
    """A run summary at commanded ``slip`` with ``quantities`` given as name=(mean, sem) (the rest NaN)."""
    stats = {q: QuantityStats(mean, 1.0, sem, 2.0 * sem, 7.0, 0.0, 0.5 * sem) for q, (mean, sem) in quantities.items()}
    return RunSummary(steady=steady, window=window, samples=40, pitches=8, pitch_deg=45.0, period_pitches=1,
                      reasons=() if steady else ("a stand-in run, not steady",), commanded_slip=slip,
                      commanded_slip_angle=slip_angle, **stats)


def write_result(folder: Path, case, stages, wall_seconds: float = 1.0) -> Path:
    """``folder/result.h5`` of ``case`` whose drive's stages have the summaries ``stages`` (the last is the run's),
    run in ``wall_seconds``."""
    writer = ResultWriter(folder / RESULT_NAME, {"case_toml": case_to_toml(case), "case_name": case.name,
                                                 "case_hash": case.case_hash()},
                          {"nodes0": np.zeros((3, 3)), "triangles": np.zeros((1, 3)), "beams": np.zeros((0, 2))})
    series = {k: np.linspace(0.0, 1.0, 5) for k in SERIES_UNITS}
    return writer.finish(series, SERIES_UNITS, stages[-1], {"wall_seconds": wall_seconds, "simulated_seconds": 1.0},
                         tuple(stages))
