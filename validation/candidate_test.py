"""A change of the DEM--FEM twin judged on trials not used to choose it (issue 34 item 3).

The twin's runs (``baseline``) and the same trials run again with one change (``candidate``: other particles,
another scale, ...) are each paired with the measured trials (:func:`~.compare.match_conditions`). On the
``held_out`` trials -- those not used to choose the change -- the error of each is the RMS, over the trials that both
ran to a steady state and over the responses, of the residual (simulated - measured) divided by the response's
spread over every measured row (:func:`~.calibration.response_scales`, the normalisation ``validate --model`` and the
semi-empirical model get). The change is **accepted** when it lowers that error by more than the twin's own
run-to-run spread in the same units: the standard deviation of the simulated response over replica runs (other
seeds of one trial's condition, each at its own measured load), RMS-pooled over the responses. Without two replicas
the gain is reported as provisional; without a held-out trial that both ran, nothing is judged.

Plain NumPy on :class:`~.measured.Measurements`; the study that runs it on the CMU sweeps is
``docs/cmu_twin_candidates.py``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .calibration import response_scales
from .compare import match_conditions
from .measured import Measurements

#: The responses a candidate is judged on by default (the trials' sinkage has another zero than the twin's).
JUDGED_RESPONSES = ("drawbar_pull", "lateral_force")


@dataclass(frozen=True)
class TrialValues:
    """One measured trial with the baseline's and the candidate's value of each response (NaN where not run)."""

    row: int  # index into the measured data
    slip_angle: float  # [deg]
    slip: float  # along the heading [1]
    load: float  # [N]
    held_out: bool
    measured: dict[str, float]
    baseline: dict[str, float]
    candidate: dict[str, float]


@dataclass(frozen=True)
class CandidateVerdict:
    """What the judgement found (module docstring); errors are in units of each response's measured spread."""

    responses: tuple[str, ...]
    judged_trials: int  # held-out trials that both the baseline and the candidate ran steadily
    baseline_error: float  # RMS normalised residual over the judged trials and responses (NaN if none)
    candidate_error: float
    replica_spread: float | None  # RMS-pooled std of the normalised simulated responses over the replicas
    replicas: int
    verdict: str  # "accepted", "not accepted", "provisional: ...", "not judged: ..."
    trials: list[TrialValues] = field(default_factory=list)
    scales: dict[str, float] = field(default_factory=dict)

    @property
    def gain(self) -> float:
        """Fall of the error, baseline - candidate (positive: the candidate is closer to the trials)."""
        return self.baseline_error - self.candidate_error

    @property
    def gain_percent(self) -> float:
        """The fall as a percentage of the baseline's error."""
        return 100.0 * self.gain / self.baseline_error if self.baseline_error > 0 else float("nan")


def _values(data: Measurements, simulated: Measurements | None, responses) -> dict[int, dict[str, float]]:
    """Measured row -> the simulated responses of its partner (no entry where it has none)."""
    if simulated is None or len(simulated) == 0:
        return {}
    pairs, _ = match_conditions(data, simulated)
    return {int(k): {q: float(simulated.responses[q][j]) for q in responses} for k, j in pairs}


def replica_spread(replicas: Measurements | None, scales: dict[str, float], responses) -> float | None:
    """RMS over ``responses`` of the standard deviation (ddof 1) of the simulated response over the replica runs,
    each divided by its scale; None with fewer than two runs."""
    if replicas is None or len(replicas) < 2:
        return None
    var = [np.var(np.asarray(replicas.responses[q], float) / scales[q], ddof=1) for q in responses]
    return float(np.sqrt(np.mean(var)))


def concat_runs(name: str, parts) -> Measurements:
    """The rows of ``parts`` (runs of the same responses, e.g. replicas gathered from several sweeps) one after
    another, as dataset ``name``; the standard deviations where every part gives them."""
    parts = list(parts)
    cat = lambda key: np.concatenate([np.asarray(getattr(p, key)) for p in parts])  # noqa: E731
    return Measurements(name, *(cat(k) for k in Measurements.ROW_FIELDS),
                        responses={q: np.concatenate([p.responses[q] for p in parts]) for q in parts[0].responses},
                        std={q: np.concatenate([p.std[q] for p in parts]) for q in parts[0].std
                             if all(q in p.std for p in parts)},
                        notes=parts[0].notes, sinkage_relative=parts[0].sinkage_relative, passes=cat("passes"),
                        travel_slip=cat("travel_slip"))


def judge_candidate(data: Measurements, baseline: Measurements, candidate: Measurements, held_out,
                    replicas: Measurements | None = None, responses=JUDGED_RESPONSES) -> CandidateVerdict:
    """Judge ``candidate`` against ``baseline`` on the measured rows where ``held_out`` (a boolean mask over
    ``data``, or a function of ``data`` returning one) is true (module docstring)."""
    responses = tuple(responses)
    mask = np.asarray(held_out(data) if callable(held_out) else held_out, bool)
    if mask.shape != (len(data),):
        raise ValueError(f"held_out has shape {mask.shape}; the data have {len(data)} rows")
    scales = response_scales(data, responses)
    base, cand = _values(data, baseline, responses), _values(data, candidate, responses)
    trials = []
    for k in sorted(set(base) | set(cand)):
        nan = {q: float("nan") for q in responses}
        trials.append(TrialValues(
            row=k, slip_angle=float(data.slip_angle[k]), slip=float(data.slip[k]), load=float(data.load[k]),
            held_out=bool(mask[k]), measured={q: float(data.responses[q][k]) for q in responses},
            baseline=base.get(k, nan), candidate=cand.get(k, nan)))
    judged = [t for t in trials if t.held_out and all(np.isfinite(t.baseline[q]) and np.isfinite(t.candidate[q])
                                                       for q in responses)]

    def error(which: str) -> float:
        res = [(getattr(t, which)[q] - t.measured[q]) / scales[q] for t in judged for q in responses
               if np.isfinite(t.measured[q])]
        return float(np.sqrt(np.mean(np.square(res)))) if res else float("nan")

    spread = replica_spread(replicas, scales, responses)
    b, c = error("baseline"), error("candidate")
    n_rep = 0 if replicas is None else len(replicas)
    if not judged:
        verdict = "not judged: no held-out trial has a steady run of both the baseline and the candidate"
    elif spread is None:
        verdict = (f"provisional: the error falls by {b - c:+.3f} of the spread, and the twin's run-to-run spread is "
                   f"not yet known ({n_rep} replica run{'s' if n_rep != 1 else ''}, two needed)")
    else:
        verdict = "accepted" if b - c > spread else "not accepted"
    return CandidateVerdict(responses, len(judged), b, c, spread, n_rep, verdict, trials, scales)
