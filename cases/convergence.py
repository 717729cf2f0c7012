"""Convergence study of a case: how far its reported numbers move when the scale is refined.

The "double the box and rerun" check, done for every numerical parameter a testbed result depends on.
From a base case (a preset or a case file, with overrides) the study makes the reference case and one case
per refined level of each factor, runs them as a sweep (:mod:`.sweep`: each case in its own process,
finished cases skipped when the study runs again), and writes a report:

======================  ===============================================================  =================
factor                  what changes (``scale`` multiplies the reference value)          default levels
======================  ===============================================================  =================
``particle_size``       ``soil.diameter_min`` and ``soil.diameter_max`` (finer: < 1),    1, 0.8, 0.64
                        every level at one DEM step (the finest level's: see below)
``depth``               ``soil.depth``                                                   1, 2
``width``               ``soil.width``                                                   1, 2
``time_step``           ``soil.time_step`` (of the reference run: the same bed)          1, 0.5
``mesh``                ``wheel.element_size``                                           1, 0.5
======================  ===============================================================  =================

For every factor and each pair of neighbouring levels (coarse -> fine) and for each reported quantity
(:data:`QUANTITIES`) the report gives the change Delta = q_fine - q_coarse, its relative size
Delta / max(|q_fine|, floor) (floors as the steady-state detector's: 5 % of W for forces, 5 % of W r for the
torque, half a mean particle diameter for sinkage, 0.01 for slip) and its standard error
sqrt(sem_fine^2 + sem_coarse^2) from the batch means over whole pitches of each run's steady window; a run that
did not reach a steady state makes its changes unreportable, and the report says so.

"Converged" is the project's definition: for the factors refined towards zero (particle size, time step, mesh) the
steady levels are extrapolated to scale 0 (:func:`extrapolation_rows`: a line in the scale weighted by each run's
standard error, :mod:`wheelsoil.scale_extrapolation`), and the factor is converged when the reference's error
against the extrapolated value, plus two standard errors, is within ``threshold`` (10 %) for every quantity: one
refinement that moves little is not convergence. Depth and width (doubled, not refined) are converged from the
level whose every quantity changes by less than the threshold to the next.

The refined levels may drive up to twice the base case's ``test.drive_time`` (``--level-drive-time``): they
stop once steady, like the reference, but a finer bed's quantities settle more slowly per simulated second.

The time-step level runs after the reference, at ``scale`` times the DEM step the reference used (read from
its result); the bed is prepared with its own stable step either way. So do the particle-size levels
(``particle_step="common"``, the default): every one of them, the reference's particle size included (a case of
its own), runs at the reference's DEM step times the finest particle scale, the stable step of the finest level,
so that the particle-size series changes the particles and not the step with them (the stable step is
proportional to the particle size; ``particle_step="own"``: each level at its own stable step, as studies before
2026-11-26 ran) (:class:`~wheelsoil.coupling.testbed.
TestbedSpec` ``time_step``), so the level tests the step and not a new bed.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path


from wheelsoil.errors import WheelsoilInputError
from wheelsoil.granular.bed import estimated_particles
from wheelsoil.provenance import atomic_output

from . import build
from .results import load_result
from .run import RESULT_NAME
from .schema import CaseError, CaseFile, apply_overrides, validate_case
from .sweep import Sweep, SweepCase, run_sweep

#: Factor -> default scales, reference (1) first, then finer levels (for depth and width: larger).
DEFAULT_LEVELS = {
    "particle_size": (1.0, 0.8, 0.64),
    "depth": (1.0, 2.0),
    "width": (1.0, 2.0),
    "time_step": (1.0, 0.5),
    "mesh": (1.0, 0.5),
}

#: Reported quantities: summary key -> (label, unit, scale to the printed unit).
QUANTITIES = {
    "drawbar_pull": ("drawbar pull", "N", 1.0),
    "lateral_force": ("lateral force", "N", 1.0),
    "vertical_force": ("vertical force", "N", 1.0),
    "torque": ("torque", "N m", 1.0),
    "sinkage": ("sinkage", "mm", 1e3),
    "tread_slip": ("tread slip", "1", 1.0),
}


@dataclass
class Level:
    """One level of one factor: its scale and the case overrides that make it."""

    factor: str
    scale: float
    overrides: dict
    case: CaseFile | None = None
    folder: Path | None = None


#: How the particle-size levels choose their DEM step.
PARTICLE_STEPS = ("common", "own")


@dataclass
class ConvergenceStudy:
    base: CaseFile
    out: Path
    levels: dict[str, list[Level]]
    threshold: float = 0.10
    reference: Level | None = field(default=None)
    level_drive_time: float | None = None
    particle_step: str = "common"

    def cases(self) -> list[Level]:
        """The distinct levels (the reference once)."""
        seen, out = set(), []
        for levels in self.levels.values():
            for lv in levels:
                if lv.case is not None and lv.folder.name not in seen:
                    seen.add(lv.folder.name)
                    out.append(lv)
        return out


def plan(study: ConvergenceStudy) -> list[dict]:
    """Before anything runs: each level's estimated particle count (:func:`~wheelsoil.granular.bed.
    estimated_particles`) and the soil's cost per simulated second relative to the reference (particles x steps per second;
    the stable DEM step is proportional to the smallest radius, and a time-step level's step is its scale)."""
    ref = build.bed_spec(study.base)
    n_ref = estimated_particles(ref)
    out = []
    finest = min(lv.scale for lv in study.levels.get("particle_size", [])) if "particle_size" in study.levels else 1
    for lv in study.cases() + [lv for lvs in study.levels.values() for lv in lvs if lv.case is None]:
        spec = build.bed_spec(lv.case or study.base)
        if lv.factor == "particle_size":
            spec = replace(ref, diameter_min=ref.diameter_min * lv.scale, diameter_max=ref.diameter_max * lv.scale)
        n = estimated_particles(spec)
        if lv.factor == "time_step":
            steps = 1.0 / lv.scale
        elif lv.factor == "particle_size" and study.particle_step == "common":
            steps = 1.0 / finest
        else:
            steps = ref.diameter_min / spec.diameter_min
        out.append({"factor": lv.factor, "scale": lv.scale, "particles": int(round(n)),
                    "relative_soil_cost": n / n_ref * steps,
                    "drive_time": study.base.test.drive_time if lv.scale == 1.0 else study.level_drive_time})
    return out


def _check_levels(factor: str, scales) -> tuple[float, ...]:
    scales = tuple(float(s) for s in scales)
    if factor not in DEFAULT_LEVELS:
        raise WheelsoilInputError(f"convergence factor {factor!r} is not one of {', '.join(DEFAULT_LEVELS)}")
    if len(scales) < 2 or scales[0] != 1.0:
        raise WheelsoilInputError(f"convergence levels of {factor} = {list(scales)}: give the reference 1 first and "
                                  "at least one more level")
    if not all(math.isfinite(s) and s > 0 for s in scales) or len(set(scales)) != len(scales):
        raise WheelsoilInputError(f"convergence levels of {factor} = {list(scales)} must be distinct numbers > 0")
    return scales


def level_overrides(case: CaseFile, factor: str, scale: float, reference_time_step: float | None = None,
                    common_step_scale: float | None = None) -> dict | None:
    """The case keys that make ``factor`` at ``scale`` times the reference value; None while they need the
    reference's DEM step and it is not known. ``common_step_scale``: the particle-size levels all run at the
    reference's step times this (the finest particle scale); None: each at its own stable step."""
    s, w = case.soil, case.wheel
    if factor == "particle_size":
        sizes = {"soil.diameter_min": s.diameter_min * scale, "soil.diameter_max": s.diameter_max * scale}
        if common_step_scale is None:
            return sizes
        if reference_time_step is None:
            return None  # known once the reference has run
        return {**sizes, "soil.time_step": reference_time_step * common_step_scale}
    if factor == "depth":
        return {"soil.depth": s.depth * scale}
    if factor == "width":
        return {"soil.width": s.width * scale}
    if factor == "mesh":
        size = w.element_size if w.element_size is not None else build.wheel_geometry(case).element_size
        return {"wheel.element_size": size * scale}
    if factor == "time_step":
        if scale == 1.0:
            return {}
        if reference_time_step is None:
            return None  # known once the reference has run
        return {"soil.time_step": reference_time_step * scale}
    raise WheelsoilInputError(f"convergence factor {factor!r} is not one of {', '.join(DEFAULT_LEVELS)}")


def make_study(base: CaseFile, out: str | Path, levels: dict | None = None, threshold: float = 0.10,
               reference_time_step: float | None = None, level_drive_time: float | None = None,
               particle_step: str = "common") -> ConvergenceStudy:
    """The study's cases, each validated before anything runs (errors name the factor, level and key).

    level_drive_time: the longest drive of the refined levels [s] (default: twice the base case's
    ``test.drive_time`` when the base stops once steady, else the base's). A finer or larger bed is noisier
    per pitch or slower to settle; a run stops once it is steady, so the longer limit changes nothing for a
    level that would have been steady within the base's, and the reference keeps the base case unchanged.
    particle_step: ``"common"`` or ``"own"`` (see the module docstring)."""
    out = Path(out)
    if particle_step not in PARTICLE_STEPS:
        raise WheelsoilInputError(f"particle_step = {particle_step!r}: choose {' or '.join(PARTICLE_STEPS)}")
    levels = {k: _check_levels(k, v) for k, v in (levels or DEFAULT_LEVELS).items()}
    if not 0 < threshold < 1:
        raise WheelsoilInputError(f"threshold = {threshold!r} must lie in (0, 1)")
    if level_drive_time is None:
        level_drive_time = base.test.drive_time * (2.0 if base.test.stop_when_steady else 1.0)
    if not (math.isfinite(level_drive_time) and level_drive_time >= base.test.drive_time):
        raise WheelsoilInputError(f"level drive time = {level_drive_time!r} s must be at least the case's "
                                  f"test.drive_time = {base.test.drive_time} s")
    base_data = base.model_dump(mode="json")
    study = ConvergenceStudy(base=base, out=out, levels={}, threshold=threshold, level_drive_time=level_drive_time,
                             particle_step=particle_step)
    if reference_time_step is None and base.soil.time_step is not None:
        reference_time_step = base.soil.time_step
    common = min(levels["particle_size"]) if particle_step == "common" and "particle_size" in levels else None
    reference_data = dict(base_data, case=dict(base_data["case"], name=f"{base.name}-reference"))
    reference_case = validate_case(reference_data, "convergence study, reference")
    reference_hash = reference_case.case_hash()
    for factor, scales in levels.items():
        study.levels[factor] = []
        for scale in scales:
            over = level_overrides(base, factor, scale, reference_time_step,
                                   common if factor == "particle_size" else None)
            lv = Level(factor, scale, over or {})
            if over is not None:
                extra = {"test.drive_time": level_drive_time} if scale != 1.0 else {}
                data = apply_overrides(base_data, [(k.split("."), v) for k, v in {**over, **extra}.items()])
                case = validate_case(data, f"convergence study, {factor} x {scale:g} ({over or 'reference'})")
                if case.case_hash() == reference_hash:
                    lv.case = reference_case  # every factor's scale 1 that changes nothing is the base case itself
                    study.reference = lv
                else:
                    data["case"]["name"] = f"{base.name}-{factor}x{scale:g}" + (
                        "-common-step" if factor == "particle_size" and scale == 1.0 else "")
                    lv.case = validate_case(data, f"convergence study, {factor} x {scale:g} ({over})")
                lv.folder = out / "cases" / lv.case.case_hash()
            study.levels[factor].append(lv)
    if study.reference is None:  # no factor's scale 1 is the base case: the reference runs on its own
        study.reference = Level("reference", 1.0, {}, reference_case, out / "cases" / reference_hash)
    return study


def _sweep_of(study: ConvergenceStudy, levels: list[Level]) -> Sweep:
    cases = [SweepCase(values={"factor": lv.factor, "scale": lv.scale, **lv.overrides}, case=lv.case, folder=lv.folder)
             for lv in levels]
    return Sweep(name=f"convergence-{study.base.name}", cases=cases, out=study.out,
                 swept_keys=["factor", "scale"])


def _unresolved(study: ConvergenceStudy) -> bool:
    return any(lv.case is None for lvs in study.levels.values() for lv in lvs)


def resolve_time_step_levels(study: ConvergenceStudy) -> bool:
    """Make the levels that need the reference's DEM step (the time-step levels, and the particle-size levels at
    a common step) from the finished reference's; False while it has not run."""
    if not _unresolved(study):
        return True
    ref = study.reference
    if ref is None or not (ref.folder / RESULT_NAME).is_file():
        return False
    dt = float(load_result(ref.folder / RESULT_NAME).info["dem_time_step"])
    levels = {k: [lv.scale for lv in v] for k, v in study.levels.items()}
    study.levels = make_study(study.base, study.out, levels, study.threshold, reference_time_step=dt,
                              level_drive_time=study.level_drive_time, particle_step=study.particle_step).levels
    return True


def run_study(study: ConvergenceStudy, *, workers: int = 1, arch: str | None = None, timeout: float | None = None,
              progress: bool = False, console=None) -> dict:
    """Run every level (the time-step level after the reference, or with the others when the reference has
    finished before) and write the report; returns the statuses."""
    resolve_time_step_levels(study)
    first = study.cases() if study.reference in study.cases() else [study.reference] + study.cases()
    status = run_sweep(_sweep_of(study, first), workers=workers, arch=arch, timeout=timeout,
                       progress=progress, console=console)
    if _unresolved(study):
        if not resolve_time_step_levels(study):
            raise WheelsoilInputError("the time-step and common-step particle levels need the reference run's DEM "
                                      f"step; the reference failed (see {study.out / 'status.json'})")
        status.update(run_sweep(_sweep_of(study, study.cases()), workers=workers, arch=arch, timeout=timeout,
                                progress=progress, console=console))
    write_report(study)
    return status


# -------------------------------------------------------------------- report
def _floors(case: CaseFile) -> dict:
    w = case.test.load
    r = build.wheel_geometry(case).radius
    d = 0.5 * (case.soil.diameter_min + case.soil.diameter_max)
    return {"drawbar_pull": 0.05 * w, "lateral_force": 0.05 * w, "vertical_force": 0.05 * w, "torque": 0.05 * w * r,
            "sinkage": 0.5 * d, "tread_slip": 0.01}


def _level_values(lv: Level) -> dict | None:
    if lv.folder is None or not (lv.folder / RESULT_NAME).is_file():
        return None
    r = load_result(lv.folder / RESULT_NAME)
    out = {"steady": bool(r.summary["steady"]), "wall_seconds": float(r.info.get("wall_seconds", math.nan)),
           "particles": int(r.info.get("particles", 0)), "dem_time_step": float(r.info.get("dem_time_step", math.nan))}
    for q in QUANTITIES:
        st = r.summary.get(q, {})
        out[q] = (float(st.get("mean", math.nan)), float(st.get("sem", math.nan)))
    return out


def comparison_rows(study: ConvergenceStudy) -> list[dict]:
    """One row per factor, neighbouring pair of levels and quantity: the two means, their change, relative change
    and its standard error, and whether both runs were steady."""
    floors = _floors(study.base)
    rows = []
    for factor, levels in study.levels.items():
        values = [_level_values(lv) for lv in levels]
        for k in range(len(levels) - 1):
            a, b = values[k], values[k + 1]
            for q in QUANTITIES:
                row = {"factor": factor, "coarse_scale": levels[k].scale, "fine_scale": levels[k + 1].scale,
                       "quantity": q, "finished": a is not None and b is not None}
                if row["finished"]:
                    (ma, sa), (mb, sb) = a[q], b[q]
                    ref = max(abs(mb), floors[q])
                    delta = mb - ma
                    sigma = math.hypot(sa, sb) if math.isfinite(sa) and math.isfinite(sb) else math.nan
                    row.update(coarse_mean=ma, coarse_sem=sa, fine_mean=mb, fine_sem=sb, change=delta,
                               change_sem=sigma, relative_change=delta / ref, relative_change_sem=sigma / ref,
                               steady=a["steady"] and b["steady"])
                    row["converged"] = bool(row["steady"] and abs(row["relative_change"]) < study.threshold)
                rows.append(row)
    return rows


def coarsest_converged(study: ConvergenceStudy, rows: list[dict]) -> dict:
    """Per factor: the coarsest scale from which every quantity changes by less than the threshold to the next
    finer level (and on through the finer pairs), or None."""
    verdict = {}
    for factor, levels in study.levels.items():
        pairs = [[r for r in rows if r["factor"] == factor and r["coarse_scale"] == lv.scale] for lv in levels[:-1]]
        ok = [bool(p) and all(r.get("converged", False) for r in p) for p in pairs]
        found = None
        for k in range(len(ok)):
            if all(ok[k:]):
                found = levels[k].scale
                break
        verdict[factor] = found
    return verdict


#: Factors refined towards zero (scale < 1), whose series is extrapolated to scale 0 (the reference is scale 1).
REFINED_TOWARDS_ZERO = ("particle_size", "time_step", "mesh")


def extrapolation_rows(study: ConvergenceStudy) -> list[dict]:
    """Per refined factor (:data:`REFINED_TOWARDS_ZERO`) and quantity, :func:`extrapolate_levels` of the study's
    levels."""
    floors = _floors(study.base)
    rows = []
    for factor in REFINED_TOWARDS_ZERO:
        levels = study.levels.get(factor, [])
        if len(levels) >= 2:
            rows += extrapolate_levels(factor, [(lv.scale, _level_values(lv)) for lv in levels], floors,
                                       study.threshold)
    return rows


def extrapolate_levels(factor: str, levels: list[tuple[float, dict | None]], floors: dict,
                       threshold: float) -> list[dict]:
    """One row per quantity: the steady levels' means (``levels``: (scale, values) with values as a result's
    summary gives them, ``None`` for a level not run) against their scale, extrapolated to scale 0
    (:func:`wheelsoil.scale_extrapolation.extrapolate_to_zero_size`, weighted by each run's standard error, the
    Birge ratio scaling them where the levels scatter beyond them), and the reference's (scale 1) error against
    it with its standard error. Converged (the project's definition): that error plus two standard errors
    within ``threshold`` times max(|extrapolated|, floor). Needs every level run and steady, with finite errors;
    else the row says why (``reason``)."""
    from wheelsoil.errors import WheelsoilInputError as _Input
    from wheelsoil.scale_extrapolation import extrapolate_to_zero_size

    done = [(s, v) for s, v in levels if v is not None]
    steady = [(s, v) for s, v in done if v["steady"]]
    rows = []
    for q in QUANTITIES:
        row = {"factor": factor, "quantity": q, "levels": [s for s, _ in steady]}
        if len(done) < len(levels):
            row["reason"] = f"{len(levels) - len(done)} of {len(levels)} levels have not run"
        elif len(steady) < len(done):
            row["reason"] = "not every level reached a steady state"
        else:
            try:
                fit = extrapolate_to_zero_size([s for s, _ in steady], [v[q][0] for _, v in steady],
                                               [v[q][1] for _, v in steady])
            except _Input as exc:
                row["reason"] = str(exc)
            else:
                ref = max(abs(fit.value), floors[q])
                error, error_se = fit.change(1.0)
                row.update(value=fit.value, value_se=fit.value_se, reference_error=error, reference_error_se=error_se,
                           relative_error=error / ref, relative_error_se=error_se / ref, birge=fit.birge, dof=fit.dof,
                           converged=bool(abs(error) + 2.0 * error_se <= threshold * ref))
        rows.append(row)
    return rows


def write_report(study: ConvergenceStudy) -> list[Path]:
    """convergence.csv, convergence.json, convergence.md and convergence.png in the study folder."""
    import pandas as pd

    rows = comparison_rows(study)
    verdict = coarsest_converged(study, rows)
    extrapolated = extrapolation_rows(study)
    study.out.mkdir(parents=True, exist_ok=True)
    table = pd.DataFrame(rows)
    written = []
    with atomic_output(study.out / "convergence.csv") as tmp:
        table.to_csv(tmp, index=False)
    written.append(study.out / "convergence.csv")
    levels = {f: [{"scale": lv.scale, "overrides": lv.overrides, "case_hash": lv.folder.name if lv.folder else None,
                   "values": _level_values(lv)} for lv in lvs] for f, lvs in study.levels.items()}
    with atomic_output(study.out / "convergence.json") as tmp:
        tmp.write_text(json.dumps({"base": study.base.name, "threshold": study.threshold, "coarsest_converged": verdict,
                                   "levels": levels, "comparisons": rows, "extrapolated": extrapolated}, indent=2,
                                  default=float))
    written.append(study.out / "convergence.json")
    with atomic_output(study.out / "convergence.md") as tmp:
        tmp.write_text(report_markdown(study, rows, verdict, levels, extrapolated))
    written.append(study.out / "convergence.md")
    written.append(_plot(study, rows))
    return written


def report_markdown(study: ConvergenceStudy, rows: list[dict], verdict: dict, levels: dict,
                    extrapolated: list[dict] | None = None) -> str:
    pct = int(round(100 * study.threshold))
    lines = [f"# Convergence study: {study.base.name}", "",
             f"Each factor's levels against the reference; a change is the finer level's mean minus the coarser's, "
             f"relative to the finer mean (or the floor), ± one standard error (batch means over whole pitches). "
             f"Converged: every quantity changes by less than {pct} % and both runs were steady.", "",
             "## Levels", "", "| factor | scale | changes | particles | DEM step [s] | steady | wall [s] | "
             + " | ".join(f"{v[0]} [{v[1]}]" for v in QUANTITIES.values()) + " |",
             "|" + "---|" * (7 + len(QUANTITIES))]
    for factor, lvs in levels.items():
        for lv in lvs:
            v = lv["values"]
            over = ", ".join(f"{k} = {x:.4g}" for k, x in lv["overrides"].items()) or "reference"
            if v is None:
                lines.append(f"| {factor} | {lv['scale']:g} | {over} | not run | | | | " + " | " * (len(QUANTITIES) - 1)
                             + " |")
                continue
            cells = [f"{s * v[q][0]:.4g} ± {s * v[q][1]:.2g}" for q, (_, _, s) in QUANTITIES.items()]
            lines.append(f"| {factor} | {lv['scale']:g} | {over} | {v['particles']} | {v['dem_time_step']:.3g} | "
                         f"{'yes' if v['steady'] else '**no**'} | {v['wall_seconds']:.0f} | " + " | ".join(cells) + " |")
    lines += ["", "## Changes between neighbouring levels", "",
              "| factor | levels | " + " | ".join(v[0] for v in QUANTITIES.values()) + " |",
              "|" + "---|" * (2 + len(QUANTITIES))]
    for factor, lvs in study.levels.items():
        for k in range(len(lvs) - 1):
            cells = []
            for q in QUANTITIES:
                r = next(r for r in rows if r["factor"] == factor and r["coarse_scale"] == lvs[k].scale
                         and r["quantity"] == q)
                if not r["finished"]:
                    cells.append("not run")
                    continue
                text = f"{100 * r['relative_change']:+.1f} ± {100 * r['relative_change_sem']:.1f} %"
                if not r["steady"]:
                    text += " (not steady)"
                elif not r["converged"]:
                    text = f"**{text}**"
                cells.append(text)
            lines.append(f"| {factor} | {lvs[k].scale:g} → {lvs[k + 1].scale:g} | " + " | ".join(cells) + " |")
    lines += _extrapolation_markdown(study, extrapolated or [])
    lines += ["", "## Verdict", ""]
    for factor, scale in verdict.items():
        mine = [r for r in rows if r["factor"] == factor]
        scales = ", ".join(f"{lv.scale:g}" for lv in study.levels[factor])
        ext = [r for r in (extrapolated or []) if r["factor"] == factor]
        neighbours = f" (neighbouring levels change by less than {pct} % from scale {scale:g} on)" if scale else ""
        if ext and all("value" in r for r in ext):
            bad = [QUANTITIES[r["quantity"]][0] for r in ext if not r["converged"]]
            if bad:
                lines.append(f"- {factor}: **not converged**: extrapolated to scale 0, the reference's error with two "
                             f"standard errors exceeds {pct} % for {', '.join(bad)}{neighbours}.")
            else:
                lines.append(f"- {factor}: converged: extrapolated to scale 0, the reference's error with two standard "
                             f"errors is within {pct} % for every quantity{neighbours}.")
        elif scale is not None and factor in REFINED_TOWARDS_ZERO:
            why = next((r["reason"] for r in ext if "reason" in r), "no extrapolation")
            lines.append(f"- {factor}: **undecided**: neighbouring levels change by less than {pct} % from scale "
                         f"{scale:g} on, but the series could not be extrapolated ({why}), and one refinement moving "
                         "little is not convergence.")
        elif scale is not None:
            lines.append(f"- {factor}: converged within {pct} % from scale {scale:g} on.")
        elif not all(r["finished"] for r in mine):
            lines.append(f"- {factor}: **undecided**: not every level ({scales}) has finished.")
        elif not all(r["steady"] for r in mine):
            unsteady = sorted({lv.scale for lv in study.levels[factor]
                               if (v := _level_values(lv)) is not None and not v["steady"]})
            big = [r for r in mine if r["steady"] and not r["converged"]]
            lines.append(f"- {factor}: **undecided**: the level(s) at scale {', '.join(f'{x:g}' for x in unsteady)} "
                         "did not reach a steady state, so their changes are not reportable"
                         + (f"; between steady levels {len(big)} change(s) exceed {pct} %" if big else "") + ".")
        else:
            lines.append(f"- {factor}: **not converged** within {pct} % over the levels run ({scales}); refine further.")
    lines.append("")
    return "\n".join(lines)


def _extrapolation_markdown(study: ConvergenceStudy, extrapolated: list[dict]) -> list[str]:
    """The extrapolated values and the reference's error against them, one line per refined factor."""
    if not extrapolated:
        return []
    pct = int(round(100 * study.threshold))
    lines = ["", "## Extrapolated to zero scale", "",
             "Each refined factor's steady levels against their scale, a line weighted by the runs' standard errors "
             "(scaled by the Birge ratio where the levels scatter beyond them), extrapolated to scale 0; below each "
             f"value, the reference's error against it. Converged: that error plus two standard errors within {pct} %.",
             "", "| factor | " + " | ".join(f"{v[0]} [{v[1]}]" for v in QUANTITIES.values()) + " |",
             "|" + "---|" * (1 + len(QUANTITIES))]
    for factor in dict.fromkeys(r["factor"] for r in extrapolated):
        cells = []
        for q, (_, _, scale) in QUANTITIES.items():
            r = next(r for r in extrapolated if r["factor"] == factor and r["quantity"] == q)
            if "value" not in r:
                cells.append(r["reason"])
                continue
            text = (f"{scale * r['value']:.4g} ± {scale * r['value_se']:.2g}; reference "
                    f"{100 * r['relative_error']:+.1f} ± {100 * r['relative_error_se']:.1f} %")
            cells.append(text if r["converged"] else f"**{text}**")
        lines.append(f"| {factor} | " + " | ".join(cells) + " |")
    return lines


def _plot(study: ConvergenceStudy, rows: list[dict]) -> Path:
    from wheelsoil.plotting import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(12, 6.5), sharey=True)
    pairs = [(f, lvs[k].scale, lvs[k + 1].scale) for f, lvs in study.levels.items() for k in range(len(lvs) - 1)]
    labels = [f"{f}\n{a:g}→{b:g}" for f, a, b in pairs]
    for ax, (q, (label, _, _)) in zip(axes.ravel(), QUANTITIES.items()):
        for k, (f, a, b) in enumerate(pairs):
            r = next(r for r in rows if r["factor"] == f and r["coarse_scale"] == a and r["quantity"] == q)
            if not r["finished"]:
                continue
            colour = "C0" if r["steady"] else "0.6"
            ax.errorbar([k], [100 * r["relative_change"]], yerr=[100 * r["relative_change_sem"]], marker="o",
                        color=colour, capsize=3)
        ax.axhspan(-100 * study.threshold, 100 * study.threshold, color="C2", alpha=0.12)
        ax.axhline(0, color="0.5", lw=0.6)
        ax.set_title(label)
        ax.set_xticks(range(len(pairs)))
        ax.set_xticklabels(labels, fontsize=7)
    for ax in axes[:, 0]:
        ax.set_ylabel("change under refinement [%]")
    fig.suptitle(f"{study.base.name}: change between levels (band: ±{100 * study.threshold:.0f} %; grey: a run "
                 "not steady)")
    fig.tight_layout()
    path = study.out / "convergence.png"
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
    return path


def parse_levels(text: str | None, factor: str) -> tuple[float, ...]:
    """``"1,0.8,0.64"`` -> (1.0, 0.8, 0.64), checked."""
    if text is None:
        return DEFAULT_LEVELS[factor]
    try:
        values = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise WheelsoilInputError(f"--{factor.replace('_', '-')}-levels {text!r}: give numbers separated by commas, "
                                  "e.g. 1,0.8,0.64") from None
    return _check_levels(factor, values)


__all__ = ["DEFAULT_LEVELS", "QUANTITIES", "ConvergenceStudy", "Level", "make_study", "run_study", "write_report",
           "comparison_rows", "coarsest_converged", "level_overrides", "parse_levels", "CaseError"]
