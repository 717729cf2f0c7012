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
``length``              ``soil.length`` (on request: not among the default factors)      1, 2
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
steady levels are extrapolated to scale 0 (:func:`.convergence_report.extrapolation_rows`: a line in the scale weighted by each run's
standard error, :mod:`wheelsoil.scale_extrapolation`), and the factor is converged when the reference's error
against the extrapolated value, plus two standard errors, is within ``threshold`` (10 %) for every quantity: one
refinement that moves little is not convergence. Depth, width and length (doubled, not refined) are converged from
the level whose every quantity changes by less than the threshold to the next.

The bin's length matters where the wheel pushes soil along the travel: at a steering angle near 90° the wheel
ploughs sideways, its side face driving a passive zone ahead of it whose length (about the sinkage times
tan(45° + φ/2), 0.14-0.20 m for the CMU twin's 70-80 mm at φ = 39-45°) is that of the free soil a moving patch
keeps ahead (:mod:`wheelsoil.coupling.patch`). On a periodic bin the wheel starts near the rear end, its clearance
behind the same at every length, so the whole added length goes ahead of it: on the twin's 0.3 m bin at 90° the free
soil ahead of the wheel's face grows from about 0.15 m to 0.45 m.

The refined levels may drive up to twice the base case's ``test.drive_time`` (``--level-drive-time``): they
stop once steady, like the reference, but a finer bed's quantities settle more slowly per simulated second.

The time-step level runs after the reference, at ``scale`` times the DEM step the reference used (read from
its result); the bed is prepared with its own stable step either way. So do the particle-size levels
(``particle_step="common"``, the default): every one of them, the reference's particle size included (a case of
its own), runs at the reference's DEM step times the finest particle scale, the stable step of the finest level,
so that the particle-size series changes the particles and not the step with them (the stable step is
proportional to the particle size; ``particle_step="own"``: each level at its own stable step, as studies before
2026-11-26 ran). The run's step is :class:`~wheelsoil.coupling.testbed.TestbedSpec` ``time_step``, so a level tests
the step and not a new bed.

The report (changes, extrapolation, verdict, files) is :mod:`.convergence_report`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.granular.bed_spec import estimated_particles

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
    "length": (1.0, 2.0),
}
#: The factors a study runs unless told which: all but ``length`` (a check for ploughing wheels, on request).
DEFAULT_FACTORS = ("particle_size", "depth", "width", "time_step", "mesh")

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
    if factor == "length":
        return {"soil.length": s.length * scale}
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
    levels = {k: _check_levels(k, v) for k, v in (levels or {f: DEFAULT_LEVELS[f] for f in DEFAULT_FACTORS}).items()}
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
            study.levels[factor].append(lv)
            # a level that waits for the reference's DEM step (over None) is validated now on everything else (its
            # bed against the machine's memory, the wheel against the bin), so that no level the machine cannot hold
            # is found out only after the reference has run; a time-step level differs from it in the step alone
            keys = over if over is not None else level_overrides(base, factor, scale)
            if keys is None:
                continue
            extra = {"test.drive_time": level_drive_time} if scale != 1.0 else {}
            data = apply_overrides(base_data, [(k.split("."), v) for k, v in {**keys, **extra}.items()])
            case = validate_case(data, f"convergence study, {factor} x {scale:g} ({keys or 'reference'})")
            if over is None:
                continue
            if case.case_hash() == reference_hash:
                lv.case = reference_case  # every factor's scale 1 that changes nothing is the base case itself
                study.reference = lv
            else:
                data["case"]["name"] = f"{base.name}-{factor}x{scale:g}" + (
                    "-common-step" if factor == "particle_size" and scale == 1.0 else "")
                lv.case = validate_case(data, f"convergence study, {factor} x {scale:g} ({over})")
            lv.folder = out / "cases" / lv.case.case_hash()
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
    """Run every level (the levels that need the reference's DEM step after it, or with the others when the
    reference has finished before); returns the statuses. The report: :func:`.convergence_report.write_report`."""
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
    return status


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


__all__ = ["DEFAULT_FACTORS", "DEFAULT_LEVELS", "QUANTITIES", "ConvergenceStudy", "Level", "make_study", "run_study", "level_overrides",
           "parse_levels", "plan", "CaseError"]
