"""Calibrate the classical model, find what it gets wrong, name the mechanisms, measure the gain.

Workflow (architecture, validation): measurements -> the classical model calibrated on the training rows with
every parameter the data can inform free (:data:`~.extensions.BASELINE_FREE`; unidentified and at-bound
parameters flagged, :mod:`.calibration`) -> **forward selection** over the candidate mechanisms the data can show
(:data:`~.extensions.EXTENSIONS`): at each step every remaining candidate is added in turn to the current model
and the whole model is recalibrated; the candidate that passes every check below with the lowest BIC is accepted,
the current model becomes that fit, and the remaining candidates are tested again, until none passes.

A candidate passes a step when

1. **evidence**: its fit lowers BIC by more than :data:`BIC_MARGIN` (strong evidence, Kass & Raftery 1995);
2. **prediction**: its held-out RMSE is not worse than the current model's by more than :data:`GAIN_SIGMAS`
   bootstrap standard deviations of the gain (:func:`~.selection.prediction_holds`; until 2026-11-29 the gain had to
   be positive beyond them, :data:`~.selection.PREDICTION_NOT_WORSE`);
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
with slip"): the mechanism is not named at that step.

An unresolved best mechanism is **deferred**, not the end of the search (:data:`~.selection.DEFER_UNRESOLVED`): the
next passing candidate that shares no mechanism with a deferred group and is itself resolved is accepted in its
place, and the deferred one is tried again at the next step, on a model that now holds the other; its rivals are
fitted again there. A residual that two causes share can favour a drift while one of them is missing from the model
(a grousered wheel's extra thrust, unmodelled, is partly absorbed by a pressure modulus drifting with the signed slip
in place of ``theta_m_slip``). Where no passing single is resolved, each withheld mechanism is fitted in pairs with
the other best singles (the look-ahead above, restricted to pairs that hold it; :meth:`_Search.withheld_pairs`): the
missing cause may not pass alone when the withheld mechanism carries most of the residual, and in a pair the rivals
are fitted with the partner in the model. Only when that finds no resolved pair either does the search stop, with
the **ambiguity** reported. A weak effect of an unknown form otherwise takes the name of the nearest catalogue mechanism
(docs/validation/campaigns.md: cohesion softening with slip named ``theta_m_slip``). What the final model still
leaves systematic is reported as **unexplained**
(:func:`~.residuals.unexplained_trends`), and an accepted mechanism that moves a response where a systematic
residual remains is reported as a **partial** explanation, not named as the cause: the misfit has a form the
mechanism does not hold. Residuals are normalised per response by the training data's spread.
"""

from dataclasses import replace
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
from .selection import (AMBIGUITY_MARGIN, BIC_MARGIN, DEFER_UNRESOLVED, GAIN_SIGMAS, MIN_EXPLAINED, PAIR_POOL,
                        RIVAL_MARGIN, Candidate, Discovery, Step)
from .terramechanics import SoilParameters

__all__ = ["AMBIGUITY_MARGIN", "BIC_MARGIN", "CONDITIONS", "GAIN_SIGMAS", "MIN_EXPLAINED", "PAIR_POOL", "RESPONSES",
           "RIVAL_MARGIN", "Candidate",
           "Discovery", "Fit", "Step", "discover", "holdout_mask", "mechanism_effect", "model_responses",
           "normalised_residuals", "response_scales"]

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
                        "against": best.name, "rate": fit.free["drift_rate"], "delta_bic": fit.bic - current.bic,
                        "bic_vs_accepted": fit.bic - best.fit.bic})
    return sorted(out, key=lambda r: r["bic_vs_accepted"])


def _mid(ext: Extension) -> dict:
    return {p.name: p.from_fit(0.5 * sum(p.fit_bounds)) for p in ext.parameters}


def _heldout(soil, test, responses, scales) -> np.ndarray:
    return normalised_residuals(soil, test, responses, scales)


def _checked_inputs(data: Measurements, responses, candidates) -> tuple[tuple, list]:
    """The responses to fit (default: those with data) and the candidates' names, refused with the allowed ones."""
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
    return responses, names


class _Search:
    """The forward selection's state (module docstring): the training and held-out rows, the model accepted so far,
    its free parameters and lack of fit, the steps taken, and the random stream of the held-out bootstraps (drawn in
    the order the candidates are tried)."""

    def __init__(self, data, train, test, responses, scales, base_start, baseline: Fit, lack: dict, bootstrap: int,
                 seed: int, progress) -> None:
        self.data, self.train, self.test = data, train, test
        self.responses, self.scales, self.base_start, self.bootstrap = responses, scales, base_start, bootstrap
        self.rng = np.random.default_rng(seed)
        self.current, self.names, self.free = baseline, (), BASELINE_FREE
        self.lack = lack
        self.steps: list[Step] = []
        self.progress = progress

    def _fit(self, exts, current=None, free=None, **kw) -> Fit:
        current = self.current if current is None else current
        free = self.free if free is None else free
        model = " + ".join(["classical", *self.names, *(e.name for e in exts)])
        self.progress(f"step {len(self.steps) + 1}: fitting {model}")
        return _fit_extended(self.train, current, free, self.base_start, exts, self.responses, self.scales, **kw)

    def heldout_error(self, soil) -> np.ndarray:
        return _heldout(soil, self.test, self.responses, self.scales)

    def trial(self, exts, fit: Fit, cur_err, cur_rmse, needs=None) -> Candidate:
        """A candidate's evidence against the current model: held-out gain (paired bootstrap), BIC, effect, the
        systematic residual it removes, its parameters' problems."""
        err = self.heldout_error(fit.soil)
        rmse = float(np.sqrt(np.mean(err ** 2)))
        idx = self.rng.integers(0, err.size, size=(self.bootstrap, err.size))  # paired bootstrap of the RMSE difference
        diffs = np.sqrt(np.mean(cur_err[idx] ** 2, axis=1)) - np.sqrt(np.mean(err[idx] ** 2, axis=1))
        lack_new, _ = _lack_of_fit(fit.soil, self.train, self.responses, self.scales)
        before = self.lack["systematic"]
        explained = 1.0 - lack_new["systematic"] / before if before > 0 else 0.0
        data, responses, scales = self.data, self.responses, self.scales
        return Candidate(exts[0], len(self.steps), fit, rmse, cur_rmse - rmse, float(np.std(diffs)),
                         fit.bic - self.current.bic, mechanism_effect(fit.soil, exts, data, responses, scales),
                         float(explained), _parameter_problems(exts, fit),
                         effect_by_response=mechanism_effect(fit.soil, exts, data, responses, scales,
                                                             by_response=True),
                         partner=exts[1] if len(exts) > 1 else None, needs=needs or {})

    def step(self, remaining: list, max_steps: int) -> tuple[Step, list]:
        """Try every remaining mechanism alone; where none passes and a trend is unexplained, the best pairs
        (look-ahead). Returns the last step taken and its passing candidates, best first."""
        cur_err = self.heldout_error(self.current.soil)
        cur_rmse = float(np.sqrt(np.mean(cur_err ** 2)))
        singles = [self.trial((EXTENSIONS[name],), self._fit((EXTENSIONS[name],)), cur_err, cur_rmse)
                   for name in remaining]
        singles.sort(key=lambda c: c.fit.bic)
        step = Step(len(self.steps), self.names, cur_rmse, self.lack["systematic"], singles)
        self.steps.append(step)
        passing = [c for c in singles if c.passes]
        if not passing and self._looks_ahead(singles, max_steps):
            step = self._pair_step(singles, cur_err, cur_rmse)
            passing = [c for c in step.candidates if c.passes]
        return step, passing

    def _looks_ahead(self, singles: list, max_steps: int) -> bool:
        """Whether pairs of ``singles`` may be fitted: room for two more mechanisms, two singles to pair, and a
        significant systematic residual left."""
        return len(self.names) + 2 <= max_steps and len(singles) >= 2 and bool(unexplained_trends(self.lack, []))

    def _pair_step(self, singles: list, cur_err, cur_rmse, withheld: tuple[str, ...] = ()) -> Step:
        """Look-ahead: two mechanisms that act together can each fail alone; the best :data:`PAIR_POOL` singles are
        fitted in pairs, each started from either member's own fit. ``withheld``: only the pairs holding one of
        these mechanisms (:meth:`withheld_pairs`)."""
        by_name = {c.extension.name: c for c in singles}
        pool = [c.extension for c in singles[:PAIR_POOL]]
        pool += [by_name[n].extension for n in withheld if by_name[n].extension not in pool]
        pairs = []
        for a, b in combinations(pool, 2):
            if withheld and a.name not in withheld and b.name not in withheld:
                continue
            fa, fb = by_name[a.name].fit, by_name[b.name].fit
            joint = self._fit((a, b), starts=[replace(fa.soil, **_mid(b)), replace(fb.soil, **_mid(a))])
            pairs.append(self.trial((a, b), joint, cur_err, cur_rmse,
                                    needs={b.name: joint.bic - fa.bic, a.name: joint.bic - fb.bic}))
        pairs.sort(key=lambda c: c.fit.bic)
        step = Step(len(self.steps), self.names, cur_rmse, self.lack["systematic"], pairs, pairs=True)
        self.steps.append(step)
        return step

    def withheld_pairs(self, step: Step, max_steps: int) -> tuple[Step, list] | None:
        """Where every passing single of ``step`` is unresolved (:meth:`choose` found none to accept), each withheld
        mechanism fitted in pairs with the other :data:`PAIR_POOL` best singles (:data:`DEFER_UNRESOLVED`): a cause
        that is missing from the model can make a drift fit better than the mechanism, and then it may not pass
        alone either (most of the residual is the mechanism's). None where the look-ahead does not apply."""
        withheld = tuple(g[0] for g in [step.ambiguity] + step.deferred if g and " + " not in g[0])
        if not DEFER_UNRESOLVED or step.pairs or not withheld or not self._looks_ahead(step.candidates, max_steps):
            return None
        cur_err = self.heldout_error(self.current.soil)
        pair_step = self._pair_step(step.candidates, cur_err, step.heldout_rmse, withheld)
        return pair_step, [c for c in pair_step.candidates if c.passes]

    def unresolved(self, step: Step, best: Candidate, passing: list) -> list[str]:
        """The rivals ``best`` does not beat: the other passing candidates within :data:`AMBIGUITY_MARGIN` of it that
        add nothing joined to it, then (where none) the generic drifts that fit better by :data:`RIVAL_MARGIN` (added
        to ``step.rivals``)."""
        unresolved = []
        for rival in passing:
            if rival is best or abs(rival.fit.bic - best.fit.bic) >= AMBIGUITY_MARGIN:
                continue
            if rival.partner is not None:  # two pairs about equally good
                unresolved.append(rival.name)
                continue
            joint = self._fit((rival.extension,), current=best.fit, free=self.free + best.extension.parameters)
            if joint.bic - best.fit.bic >= -BIC_MARGIN or _parameter_problems((rival.extension,), joint):
                unresolved.append(rival.name)
        if not unresolved:
            rivals = _drift_rivals(self.train, self.current, self.free, best, self.responses, self.scales)
            step.rivals = step.rivals + rivals
            unresolved = [r["name"] for r in rivals if r["bic_vs_accepted"] < -RIVAL_MARGIN]
        return unresolved

    def choose(self, step: Step, passing: list) -> Candidate | None:
        """The passing candidate to accept: the best one its rivals do not beat (:meth:`unresolved`). With
        :data:`DEFER_UNRESOLVED`, a better one that is unresolved is deferred (``step.deferred``) and the next one
        sharing no mechanism with a deferred group is checked; otherwise (or where none is resolved) the first
        unresolved group becomes ``step.ambiguity`` and None is returned: selection stops."""
        held, taken = [], set()
        for cand in passing:
            if taken & set(cand.names):
                continue
            unresolved = self.unresolved(step, cand, passing)
            if not unresolved:
                step.deferred = held
                return cand
            held.append([cand.name] + unresolved)
            taken |= {n for name in held[-1] for n in name.split(" + ") if n in EXTENSIONS}
            if not DEFER_UNRESOLVED:
                break
        step.ambiguity = held[0]
        step.deferred = held[1:]
        return None

    def select(self, step: Step, passing: list, max_steps: int) -> tuple[Step, Candidate | None]:
        """The step whose candidate is accepted and that candidate (None: the search stops on the step's ambiguity):
        :meth:`choose` on ``step``, then, where it finds none, on the withheld mechanisms' pairs
        (:meth:`withheld_pairs`); a pair resolved there turns the singles' ambiguity into a deferral."""
        chosen = self.choose(step, passing)
        if chosen is None and (ahead := self.withheld_pairs(step, max_steps)) is not None and ahead[1]:
            pair_step, pair_passing = ahead
            chosen = self.choose(pair_step, pair_passing)
            if chosen is not None:  # resolved in context: the singles' ambiguity was a deferral
                step.deferred = [step.ambiguity] + step.deferred
                step.ambiguity = []
            step = pair_step
        return step, chosen

    def accept(self, step: Step, best: Candidate, remaining: list) -> None:
        best.accepted = True
        step.accepted = best.name
        self.current, self.names = best.fit, self.names + tuple(best.names)
        self.free = self.free + tuple(p for e in best.extensions for p in e.parameters)
        for n in best.names:
            remaining.remove(n)
        self.lack, _ = _lack_of_fit(self.current.soil, self.train, self.responses, self.scales)


def discover(data: Measurements, *, start: SoilParameters | None = None, responses=None, heldout=None,
             candidates=None, bootstrap: int = 400, seed: int = 0, max_steps: int = 4, progress=None) -> Discovery:
    """Run the workflow on ``data`` (see the module docstring).

    start: parameters to start from; the baseline's extension parameters are switched off
        (:data:`~.extensions.BASELINE_OFF`). responses: which measured responses to fit (default: those
        with data). heldout: boolean mask of held-out rows (default: a seeded random 30 %). candidates:
        extension names to try (default: all that the data can show). max_steps: most mechanisms accepted.
        progress: called with a line saying what is being fitted, before each fit (e.g. a command's status line).
    """
    responses, names = _checked_inputs(data, responses, candidates)
    heldout = holdout_mask(data, seed=seed) if heldout is None else np.asarray(heldout, bool)
    train, test = data.select(~heldout), data.select(heldout)
    scales = response_scales(train, responses)
    base_start = replace(start or SoilParameters(), **BASELINE_OFF)
    progress = progress or (lambda message: None)
    progress(f"fitting the classical model to {len(train)} rows (three starts)")
    baseline = calibrate_baseline(train, base_start, responses, scales)
    lack_base, trends = _lack_of_fit(baseline.soil, train, responses, scales)

    skipped = {n: "the data cannot show it" for n in names if not EXTENSIONS[n].applies(data)}
    remaining = [n for n in names if n not in skipped]
    search = _Search(data, train, test, responses, scales, base_start, baseline, lack_base, bootstrap, seed, progress)
    while remaining and len(search.names) < max_steps:
        step, passing = search.step(remaining, max_steps)
        if not passing:
            break
        step, chosen = search.select(step, passing, max_steps)
        if chosen is None:
            break
        search.accept(step, chosen, remaining)
    current, steps = search.current, search.steps
    final_err = search.heldout_error(current.soil)
    _, final_trends = _lack_of_fit(current.soil, train, responses, scales)
    unexplained = unexplained_trends(search.lack, final_trends)
    for s in steps:
        for c in s.candidates:
            if c.accepted:
                c.partial = [u["text"] for u in unexplained if u["response"] in c.moves()]
    return Discovery(baseline, float(np.sqrt(np.mean(search.heldout_error(baseline.soil) ** 2))), steps,
                     current, float(np.sqrt(np.mean(final_err ** 2))), trends,
                     {"baseline": lack_base, "final": search.lack}, unexplained, responses, scales, len(train), len(test),
                     skipped)
