"""Calibrate the classical model, find what it gets wrong, name the mechanisms, measure the gain.

Workflow (architecture, validation): measurements -> the classical model calibrated on the training rows with
every parameter the data can inform free (:data:`~.extensions.BASELINE_FREE`; unidentified and at-bound
parameters flagged, :mod:`.calibration`) -> **forward selection** over the candidate mechanisms the data can show
(:data:`~.extensions.EXTENSIONS`): at each step every remaining candidate is added in turn to the current model
and the whole model is recalibrated; the candidate that passes every check below with the lowest BIC is accepted,
the current model becomes that fit, and the remaining candidates are tested again, until none passes.

A candidate passes a step when

1. **evidence**: its fit lowers BIC by more than :data:`BIC_MARGIN` (strong evidence, Kass & Raftery 1995);
2. **prediction**: its gain in held-out RMSE over the current model is positive beyond :data:`GAIN_SIGMAS`
   bootstrap standard deviations;
3. **physical parameter**: none of its parameters sits at a bound of its range that the data push against (a
   bound that binds: the mechanism takes all it may), and each lies on the side of its off value that the
   mechanism's own description requires (:attr:`~.extensions.Parameter.sign`);
4. **signature**: it removes most of the current model's systematic residual in the responses it moves
   (:func:`~.residuals.systematic_residual`: at least :data:`MIN_EXPLAINED` of it). A mechanism that only
   resembles the cause takes part of the misfit and leaves the rest; this is what keeps an effect the catalogue
   does not hold from being given the nearest name.

When no single candidate passes and the current model still leaves a significant systematic residual, the
step looks one step ahead: every pair among the :data:`PAIR_POOL` best single fits is fitted together (from each
member's own fit with the other's parameters mid-range). A pair passes the same four checks, and its evidence also
needs each member: the pair's BIC must be lower by :data:`BIC_MARGIN` than each member's alone, so that no
passenger rides along. Two mechanisms that act together (a gravity-scaled cohesion and a sidewall term both
shaping lateral force at low gravity) can each fail alone and pass as a pair.

Two candidates that both pass and whose BICs are within :data:`AMBIGUITY_MARGIN` explain the same residual about
equally well: the model with both is fitted, and if the second adds nothing beyond the first (BIC not lower by
:data:`BIC_MARGIN`, or its parameter at a bound) the step reports an **ambiguity** between them and selection stops
there, instead of picking one. The best passing mechanism must also beat its **generic rivals**
(:func:`_drift_rivals`): each classical parameter drifting linearly with each condition the data vary (slip, slip
angle, gravity, pass, load, wheel radius and width; :func:`~.extensions.drift_rivals`), fitted in its place, so an
effect that follows a condition the mechanism does not act through (the load) is not read as the mechanism. A rival whose BIC is lower by more than
:data:`RIVAL_MARGIN` explains the residual better with a form outside the catalogue ("some soil property changes
with slip"): the mechanism is not named, the step reports an ambiguity between it and the rival, and selection
stops. A weak effect of an unknown form otherwise takes the name of the nearest catalogue mechanism
(docs/validation/campaigns.md: cohesion softening with slip named ``theta_m_slip``). What the final model still
leaves systematic is reported as **unexplained**
(:func:`~.residuals.unexplained_trends`), and an accepted mechanism that moves a response where a systematic
residual remains is reported as a **partial** explanation, not named as the cause: the misfit has a form the
mechanism does not hold. Residuals are normalised per response by the training data's spread.
"""

from dataclasses import dataclass, field, replace
from itertools import combinations

import numpy as np

from wheelsoil.errors import WheelsoilInputError

from .calibration import (
    RESPONSES,
    Fit,
    calibrate,
    calibrate_baseline,
    model_responses,
    normalised_residuals,
    response_scales,
)
from .extensions import (BASELINE_FREE, BASELINE_OFF, EXTENSIONS, Extension, drift_reference, drift_rival, drift_rivals,
                         varied_conditions)
from .measured import Measurements
from .residuals import CONDITIONS, residual_trends, systematic_residual, unexplained_trends
from .terramechanics import SoilParameters

__all__ = ["AMBIGUITY_MARGIN", "BIC_MARGIN", "CONDITIONS", "GAIN_SIGMAS", "MIN_EXPLAINED", "PAIR_POOL", "RESPONSES",
           "RIVAL_MARGIN", "Candidate",
           "Discovery", "Fit", "Step", "discover", "holdout_mask", "mechanism_effect", "model_responses",
           "normalised_residuals", "response_scales"]

BIC_MARGIN = 10.0
#: The held-out check guards against a fit that predicts worse than the model it extends; the evidence is BIC's.
#: The held-out set is a third of the rows, so its bootstrap spread is wide: one standard deviation.
GAIN_SIGMAS = 1.0
#: When no single mechanism passes and a systematic residual remains, pairs among this many best single fits
#: (by BIC) are fitted together: two mechanisms that act together can each fail alone (a forward-selection
#: look-ahead of one step).
PAIR_POOL = 6
AMBIGUITY_MARGIN = 10.0
#: A generic rival (a classical parameter drifting with a condition the data vary) withholds the
#: mechanism's name when the data prefer it: its BIC lower than the mechanism's by more than this, the smallest
#: difference Kass & Raftery (1995) grade as evidence ("positive"; below 2 "not worth more than a bare mention").
#: Not :data:`AMBIGUITY_MARGIN`, which is for two mechanisms of equal standing: a drift names no physics, so a tie
#: goes to the mechanism, whose name then carries the rival beside it. (docs/validation/campaigns.md: with the
#: symmetric margin of 10, hidden gravity mechanisms lost their names in 5 of 44 draws to drifts that fit worse
#: by 3-10; with 0, to drifts that fit better by 0.5-0.8.)
RIVAL_MARGIN = 2.0
#: Share of the current model's systematic residual an accepted mechanism must remove.
MIN_EXPLAINED = 0.5
#: A mechanism "moves" a response when its effect's RMS there is at least this share of the response's spread.
MOVES_RESPONSE = 0.05


def holdout_mask(data: Measurements, *, fraction: float = 0.3, by: str | None = None, level=None,
                 seed: int = 0) -> np.ndarray:
    """Held-out rows: the rows where condition ``by`` equals ``level`` (leave one level out), or a random
    ``fraction`` of the rows (seeded)."""
    if by is not None:
        values = getattr(data, by)
        mask = np.isclose(values, level) if np.issubdtype(np.asarray(values).dtype, np.number) else values == level
        if not mask.any() or mask.all():
            raise WheelsoilInputError(f"holding out {by} = {level!r} leaves no training or no held-out rows")
        return mask
    rng = np.random.default_rng(seed)
    mask = np.zeros(len(data), bool)
    mask[rng.choice(len(data), size=max(1, int(round(fraction * len(data)))), replace=False)] = True
    return mask


def mechanism_effect(soil: SoilParameters, extension: Extension | tuple[Extension, ...], data: Measurements,
                     responses, scales, *, by_response: bool = False):
    """RMS over conditions and responses of what ``extension`` (one or several together) adds to the model
    ``soil`` (normalised); with ``by_response`` a dict of the RMS per response.

    Scale-type parameters (sidewall, grouser) multiply formulas that also hold cohesion and friction, so a
    fit may trade the scale against them; the mechanism's contribution to the responses is what the data
    fix, and what this measures.
    """
    exts = extension if isinstance(extension, tuple) else (extension,)
    on = model_responses(soil, data)
    off = model_responses(replace(soil, **{k: v for e in exts for k, v in e.off.items()}), data)
    parts = {q: (on[q] - off[q]) / scales[q] for q in responses}
    if by_response:
        return {q: float(np.sqrt(np.mean(v ** 2))) for q, v in parts.items()}
    return float(np.sqrt(np.mean(np.concatenate(list(parts.values())) ** 2)))


def _lack_of_fit(soil: SoilParameters, data: Measurements, responses, scales) -> tuple[dict, list[dict]]:
    """Systematic residual and Spearman trends of ``soil`` on ``data``."""
    res = normalised_residuals(soil, data, responses, scales, split=True)
    rows = {q: np.isfinite(data.responses[q]) for q in responses}
    return systematic_residual(res, data, rows), residual_trends(res, data, rows)


def _parameter_problems(exts: Extension | tuple[Extension, ...], fit: Fit) -> list[str]:
    """Why the fitted parameters of ``exts`` are not a physical instance of the mechanism (empty: they are): a
    bound the data push against (:meth:`~.calibration.Fit.binding_bounds`; a saturating parameter resting on
    its search bound is a one-sided estimate, not a problem), or the opposite sign to the mechanism's."""
    problems = []
    binding = fit.binding_bounds()
    exts = exts if isinstance(exts, tuple) else (exts,)
    for ext, p in ((e, p) for e in exts for p in e.parameters):
        v = fit.free[p.name]
        if p.name in binding:
            problems.append(f"{p.name} = {v:.4g} at its {binding[p.name]} bound, which the data push against")
        off = ext.off[p.name]
        if p.sign and np.sign(v - off) != p.sign:
            problems.append(f"{p.name} = {v:.4g}: the opposite of the mechanism ({'above' if p.sign > 0 else 'below'}"
                            f" {off:g} expected)")
    return problems


@dataclass
class Candidate:
    """A mechanism tested at one selection step: its fit added to the current model, the evidence and checks."""

    extension: Extension
    step: int
    fit: Fit
    heldout_rmse: float
    gain: float  # current model's held-out RMSE - this fit's (normalised units)
    gain_std: float
    delta_bic: float  # against the current model
    effect: float  # RMS of the normalised responses the mechanism adds to the fitted model
    explained: float  # share of the current model's systematic residual this fit removes
    problems: list[str] = field(default_factory=list)  # parameter at a bound / opposite sign
    accepted: bool = False
    effect_by_response: dict = field(default_factory=dict)
    #: accepted by the selection, but the final model still leaves a systematic residual in a response this
    #: mechanism moves: it explains part of the misfit and is not named as its cause
    partial: list[str] = field(default_factory=list)
    #: a pair step (:data:`PAIR_POOL`): the second mechanism fitted together with ``extension``
    partner: Extension | None = None
    #: a pair's BIC against each member alone, by the member it adds ({b: joint - (current + a)}): each must
    #: lower BIC by :data:`BIC_MARGIN`, or the pair holds a passenger
    needs: dict = field(default_factory=dict)

    @property
    def extensions(self) -> tuple[Extension, ...]:
        return (self.extension,) if self.partner is None else (self.extension, self.partner)

    @property
    def names(self) -> list[str]:
        return [e.name for e in self.extensions]

    @property
    def name(self) -> str:
        return " + ".join(self.names)

    def moves(self) -> list[str]:
        """The responses this mechanism changes by at least :data:`MOVES_RESPONSE` of their spread."""
        return [q for q, v in self.effect_by_response.items() if v >= MOVES_RESPONSE]

    @property
    def checks(self) -> dict[str, bool]:
        return {"evidence": bool(self.delta_bic < -BIC_MARGIN and all(v < -BIC_MARGIN for v in self.needs.values())),
                "prediction": bool(self.gain > 0 and self.gain > GAIN_SIGMAS * self.gain_std),
                "physical_parameter": not self.problems,
                "signature": bool(self.explained >= MIN_EXPLAINED)}

    @property
    def passes(self) -> bool:
        return all(self.checks.values())

    def reasons(self) -> list[str]:
        """Why it did not pass (empty when it did)."""
        c, out = self.checks, []
        if not c["evidence"]:
            out.append(f"ΔBIC {self.delta_bic:+.1f} (needs < -{BIC_MARGIN:g})")
            out += [f"{n} adds ΔBIC {v:+.1f} to the other alone" for n, v in self.needs.items() if v >= -BIC_MARGIN]
        if not c["prediction"]:
            out.append(f"held-out gain {self.gain:+.4f} ± {self.gain_std:.4f}")
        out += self.problems
        if not c["signature"]:
            out.append(f"removes {100 * self.explained:.0f} % of the systematic residual (needs "
                       f"{100 * MIN_EXPLAINED:.0f} %)")
        return out

    def parameters(self) -> dict[str, float]:
        return {p.name: self.fit.free[p.name] for e in self.extensions for p in e.parameters}

    def to_dict(self) -> dict:
        table = {r["name"]: r for r in self.fit.parameter_table()}
        return {"name": self.name, "names": self.names,
                "mechanism": "; ".join(e.mechanism for e in self.extensions),
                "source": "; ".join(e.source for e in self.extensions), "step": self.step,
                "parameters": {p.name: {"value": table[p.name]["value"], "std_error": table[p.name]["std_error"],
                                        "unit": p.unit, "at_bound": table[p.name]["at_bound"]}
                               for e in self.extensions for p in e.parameters},
                "needs": self.needs,
                "train_rmse": self.fit.rmse, "heldout_rmse": self.heldout_rmse, "gain": self.gain,
                "gain_std": self.gain_std, "delta_bic": self.delta_bic, "effect": self.effect,
                "explained": self.explained, "checks": self.checks, "passes": self.passes,
                "accepted": bool(self.accepted), "named": bool(self.accepted and not self.partial),
                "moves": self.moves(), "partial_because": self.partial, "why_not": self.reasons()}


@dataclass
class Step:
    """One round of forward selection: the model it started from and every candidate tried on it."""

    index: int
    model: tuple[str, ...]
    heldout_rmse: float
    systematic: float
    candidates: list[Candidate]
    accepted: str | None = None
    ambiguity: list[str] = field(default_factory=list)
    #: a look-ahead step: its candidates are pairs of mechanisms fitted together
    pairs: bool = False
    #: the generic drifts fitted in place of the best passing mechanism (:func:`_drift_rivals`), best first
    rivals: list[dict] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"step": self.index, "model": list(self.model), "heldout_rmse": self.heldout_rmse,
                "systematic_residual": self.systematic, "accepted": self.accepted, "ambiguity": self.ambiguity,
                "pairs": self.pairs, "rivals": self.rivals,
                "candidates": [c.to_dict() for c in self.candidates]}


@dataclass
class Discovery:
    """What the workflow found: the calibrated baseline, each selection step, the accepted mechanisms, any
    ambiguity, and what the final model leaves unexplained."""

    baseline: Fit
    baseline_heldout_rmse: float
    steps: list[Step]
    final: Fit
    final_heldout_rmse: float
    trends: list[dict]  # the baseline's residual trends (training rows)
    lack_of_fit: dict  # {"baseline": ..., "final": ...}
    unexplained: list[dict]
    responses: tuple
    scales: dict
    n_train: int
    n_heldout: int
    skipped: dict = field(default_factory=dict)

    @property
    def accepted(self) -> list[Candidate]:
        """Every mechanism the selection accepted (named or partial), in the order accepted."""
        return [c for s in self.steps for c in s.candidates if c.accepted]

    @property
    def found(self) -> list[str]:
        """Names of the mechanisms named as causes: accepted, and the final model leaves no systematic residual
        in a response they move."""
        return [n for c in self.accepted if not c.partial for n in c.names]

    @property
    def partial(self) -> list[Candidate]:
        """Accepted mechanisms not named: the final model still leaves a systematic residual where they act."""
        return [c for c in self.accepted if c.partial]

    @property
    def ambiguities(self) -> list[list[str]]:
        return [s.ambiguity for s in self.steps if s.ambiguity]

    @property
    def candidates(self) -> list[Candidate]:
        """The first step's candidates (every mechanism tried on the classical model), best BIC first."""
        return self.steps[0].candidates if self.steps else []

    def explained_share(self) -> float:
        """Share of the baseline's systematic residual (training rows) the final model removes."""
        before = self.lack_of_fit["baseline"]["systematic"]
        return 1.0 - self.lack_of_fit["final"]["systematic"] / before if before > 0 else 1.0

    def to_dict(self) -> dict:
        def model(fit, heldout):
            return {"parameters": fit.free, "parameter_table": fit.parameter_table(), "train_rmse": fit.rmse,
                    "heldout_rmse": heldout, "at_bounds": fit.at_bounds(), "unidentified": sorted(fit.unidentified())}

        return {
            "responses": list(self.responses), "scales": self.scales, "n_train": self.n_train,
            "n_heldout": self.n_heldout,
            "found": self.found,
            "accepted": [c.to_dict() for c in self.accepted if not c.partial],
            "partial": [c.to_dict() for c in self.partial],
            "ambiguities": self.ambiguities,
            "unexplained": self.unexplained,
            "baseline": model(self.baseline, self.baseline_heldout_rmse),
            "final": {"mechanisms": [n for c in self.accepted for n in c.names], **model(self.final, self.final_heldout_rmse),
                      "explained_share": self.explained_share()},
            "steps": [s.to_dict() for s in self.steps],
            "residual_trends": self.trends[:12],
            "lack_of_fit": {k: {q: {"p_value": r["p_value"], "systematic": r["systematic"]}
                                for q, r in v["responses"].items()} for k, v in self.lack_of_fit.items()},
            "not_applicable": self.skipped,
        }


def _fit_extended(train, current: Fit, free, start: SoilParameters, exts: tuple[Extension, ...], responses,
                  scales, starts: list[SoilParameters] | None = None) -> Fit:
    """The current model plus ``exts`` fitted from the current fit, and from the current fit with the cohesion
    of ``start`` and the new parameters mid-range (a fit can park a parameter where a mechanism has no gradient:
    cohesion 0 for a gravity-scaled cohesion), or from ``starts`` when given; the lowest error wins."""
    params = tuple(p for e in exts for p in e.parameters)
    if starts is None:
        mid = {p.name: p.from_fit(0.5 * sum(p.fit_bounds)) for p in params}
        starts = [current.soil, replace(current.soil, cohesion=max(current.soil.cohesion, start.cohesion), **mid)]
    fits = []
    for s in starts:
        try:
            fits.append(calibrate(train, s, free + params, responses=responses, scales=scales))
        except WheelsoilInputError:  # a mid-range start outside the model's domain (a1 + a2 > 1)
            continue
    return min(fits, key=lambda f: f.sse)


def _drift_rivals(train, current: Fit, free, best: Candidate, responses, scales) -> list[dict]:
    """Each generic drift that rivals a member of ``best`` (:func:`~.extensions.drift_rivals`, along every condition
    the training rows vary), fitted in that member's place on the current model (every other parameter free again):
    its BIC against the current model and against ``best``. A rival lower by more than :data:`RIVAL_MARGIN`
    explains the residual better with a form outside the catalogue: the data do not single out the mechanism."""
    out = []
    varied = varied_conditions(train)
    for member in best.extensions:
        others = tuple(e for e in best.extensions if e is not member)
        base = current.soil if not others else replace(best.fit.soil, **member.off)
        for field_, condition in drift_rivals(member, varied):
            rival = drift_rival(field_, condition)
            start = replace(base, drift_field=field_, drift_condition=condition, drift_rate=0.0,
                            drift_reference=drift_reference(train, condition))
            fit = calibrate(train, start, free + tuple(p for e in others for p in e.parameters) + rival.parameters,
                            responses=responses, scales=scales)
            out.append({"name": rival.name, "description": rival.mechanism, "replaces": member.name,
                        "rate": fit.free["drift_rate"], "delta_bic": fit.bic - current.bic,
                        "bic_vs_accepted": fit.bic - best.fit.bic})
    return sorted(out, key=lambda r: r["bic_vs_accepted"])


def _mid(ext: Extension) -> dict:
    return {p.name: p.from_fit(0.5 * sum(p.fit_bounds)) for p in ext.parameters}


def _heldout(soil, test, responses, scales) -> np.ndarray:
    return normalised_residuals(soil, test, responses, scales)


def discover(data: Measurements, *, start: SoilParameters | None = None, responses=None, heldout=None,
             candidates=None, bootstrap: int = 400, seed: int = 0, max_steps: int = 4) -> Discovery:
    """Run the workflow on ``data`` (see the module docstring).

    start: parameters to start from; the baseline's extension parameters are switched off
        (:data:`~.extensions.BASELINE_OFF`). responses: which measured responses to fit (default: those
        with data). heldout: boolean mask of held-out rows (default: a seeded random 30 %). candidates:
        extension names to try (default: all that the data can show). max_steps: most mechanisms accepted.
    """
    if len(data) < 8:
        raise WheelsoilInputError(f"{data.name}: {len(data)} measurements are too few to calibrate and hold out")
    responses = tuple(responses or [q for q in RESPONSES if np.isfinite(data.responses.get(q, np.nan * data.slip)).any()])
    unknown = [q for q in responses if q not in RESPONSES]
    if unknown:
        raise WheelsoilInputError(f"unknown response(s) {unknown}; choose from {list(RESPONSES)}")
    names = list(candidates or EXTENSIONS)
    bad = [n for n in names if n not in EXTENSIONS]
    if bad:
        raise WheelsoilInputError(f"unknown candidate(s) {bad}; choose from {sorted(EXTENSIONS)}")
    heldout = holdout_mask(data, seed=seed) if heldout is None else np.asarray(heldout, bool)
    train, test = data.select(~heldout), data.select(heldout)
    scales = response_scales(train, responses)
    base_start = replace(start or SoilParameters(), **BASELINE_OFF)
    baseline = calibrate_baseline(train, base_start, responses, scales)
    lack_base, trends = _lack_of_fit(baseline.soil, train, responses, scales)

    skipped = {n: "the data cannot show it" for n in names if not EXTENSIONS[n].applies(data)}
    remaining = [n for n in names if n not in skipped]
    rng = np.random.default_rng(seed)
    current, current_names, free = baseline, (), BASELINE_FREE
    lack_cur = lack_base
    steps: list[Step] = []

    def trial(exts, fit, cur_err, cur_rmse, needs=None) -> Candidate:
        err = _heldout(fit.soil, test, responses, scales)
        rmse = float(np.sqrt(np.mean(err ** 2)))
        idx = rng.integers(0, err.size, size=(bootstrap, err.size))  # paired bootstrap of the RMSE difference
        diffs = np.sqrt(np.mean(cur_err[idx] ** 2, axis=1)) - np.sqrt(np.mean(err[idx] ** 2, axis=1))
        lack_new, _ = _lack_of_fit(fit.soil, train, responses, scales)
        before = lack_cur["systematic"]
        explained = 1.0 - lack_new["systematic"] / before if before > 0 else 0.0
        return Candidate(exts[0], len(steps), fit, rmse, cur_rmse - rmse, float(np.std(diffs)),
                         fit.bic - current.bic, mechanism_effect(fit.soil, exts, data, responses, scales),
                         float(explained), _parameter_problems(exts, fit),
                         effect_by_response=mechanism_effect(fit.soil, exts, data, responses, scales,
                                                             by_response=True),
                         partner=exts[1] if len(exts) > 1 else None, needs=needs or {})

    while remaining and len(current_names) < max_steps:
        cur_err = _heldout(current.soil, test, responses, scales)
        cur_rmse = float(np.sqrt(np.mean(cur_err ** 2)))
        singles = []
        for name in remaining:
            ext = EXTENSIONS[name]
            singles.append(trial((ext,), _fit_extended(train, current, free, base_start, (ext,), responses, scales),
                                 cur_err, cur_rmse))
        singles.sort(key=lambda c: c.fit.bic)
        tried = singles
        step = Step(len(steps), current_names, cur_rmse, lack_cur["systematic"], tried)
        steps.append(step)
        passing = [c for c in tried if c.passes]
        if (not passing and len(current_names) + 2 <= max_steps and len(singles) >= 2
                and unexplained_trends(lack_cur, [])):
            # look-ahead: two mechanisms that act together can each fail alone
            by_name = {c.extension.name: c for c in singles}
            pool = [c.extension for c in singles[:PAIR_POOL]]
            pairs = []
            for a, b in combinations(pool, 2):
                fa, fb = by_name[a.name].fit, by_name[b.name].fit
                joint = _fit_extended(train, current, free, base_start, (a, b), responses, scales,
                                      starts=[replace(fa.soil, **_mid(b)), replace(fb.soil, **_mid(a))])
                pairs.append(trial((a, b), joint, cur_err, cur_rmse,
                                   needs={b.name: joint.bic - fa.bic, a.name: joint.bic - fb.bic}))
            pairs.sort(key=lambda c: c.fit.bic)
            step = Step(len(steps), current_names, cur_rmse, lack_cur["systematic"], pairs, pairs=True)
            steps.append(step)
            tried, passing = pairs, [c for c in pairs if c.passes]
        if not passing:
            break
        best = passing[0]
        unresolved = []
        for rival in passing[1:]:
            if rival.fit.bic - best.fit.bic >= AMBIGUITY_MARGIN:
                continue
            if rival.partner is not None:  # two pairs about equally good
                unresolved.append(rival.name)
                continue
            joint = _fit_extended(train, best.fit, free + best.extension.parameters, base_start,
                                  (rival.extension,), responses, scales)
            if joint.bic - best.fit.bic >= -BIC_MARGIN or _parameter_problems((rival.extension,), joint):
                unresolved.append(rival.name)
        if not unresolved:
            step.rivals = _drift_rivals(train, current, free, best, responses, scales)
            unresolved = [r["name"] for r in step.rivals if r["bic_vs_accepted"] < -RIVAL_MARGIN]
        if unresolved:
            step.ambiguity = [best.name] + unresolved
            break
        best.accepted = True
        step.accepted = best.name
        current, current_names = best.fit, current_names + tuple(best.names)
        free = free + tuple(p for e in best.extensions for p in e.parameters)
        for n in best.names:
            remaining.remove(n)
        lack_cur, _ = _lack_of_fit(current.soil, train, responses, scales)
    final_err = _heldout(current.soil, test, responses, scales)
    _, final_trends = _lack_of_fit(current.soil, train, responses, scales)
    unexplained = unexplained_trends(lack_cur, final_trends)
    for s in steps:
        for c in s.candidates:
            if c.accepted:
                c.partial = [u["text"] for u in unexplained if u["response"] in c.moves()]
    return Discovery(baseline, float(np.sqrt(np.mean(_heldout(baseline.soil, test, responses, scales) ** 2))), steps,
                     current, float(np.sqrt(np.mean(final_err ** 2))), trends,
                     {"baseline": lack_base, "final": lack_cur}, unexplained, responses, scales, len(train), len(test),
                     skipped)
