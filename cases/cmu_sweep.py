"""The CMU trials as sweeps of the rig presets: one case per measured trial, at the trial's steering angle, slip and
load, on the preset of its wheel (``cmu-grouser``'s base, with the smooth wheel where the trial's is), with the
trial's repeat at its condition (wheel, steering angle, commanded rim speed; 1, 2, 3 in file order) as the bed's seed, so that the repeats of a condition are the simulation's replicas as they are the
rig's.

Written from the measured files (``../shared/data/measured/cmu_3d_terramechanics``) by::

    python -m wheelsoil.cases.cmu_sweep ../shared/data/measured/cmu_3d_terramechanics

into ``presets/sweeps/cmu-trials.toml`` (all 297 trials) and ``presets/sweeps/cmu-trials-subset.toml`` (the subset
named by :data:`SUBSET`, fixed before any DEM--FEM result: the grouser wheel at 0, 45 and 90 deg and the smooth one
at 0 and 90 deg, each at the dragged wheel, braking 0.5, free rolling, driving 0.5 and 0.9, first repeat: 25 cases
spanning every response's range of steering and slip), ``presets/sweeps/cmu-replicas.toml`` (the other repeats of one
subset trial: the twin's run-to-run spread) and one ``presets/sweeps/cmu-candidate-<name>.toml`` per DEM-side
candidate of :data:`CANDIDATES` (issue 34 item 3: the twin changed, on the trials that judge it).
"""

from __future__ import annotations

import csv
import math
import sys
from pathlib import Path

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.parameters import cmu_sand

#: The files of the trials, one per wheel.
TRIAL_FILES = {"smooth": "smooth_wheel_trials.csv", "grouser": "grouser_wheel_trials.csv"}
#: The subset: wheel -> steering angles [deg]; the commanded slips (each trial nearest to one, within 0.05); repeat 1.
SUBSET = {"grouser": (0.0, 45.0, 90.0), "smooth": (0.0, 90.0)}
SUBSET_SLIPS = (-1.0, -0.5, 0.0, 0.5, 0.9)
SUBSET_TRIAL = 1

def _particles(pair, material) -> dict:
    """The case overrides that give the twin's soil another calibrated particle set: its sliding and rolling friction
    and the density that packs it to the sand's bulk density (the restitution, stiffness and sizes stay the twin's)."""
    return {"soil.static_friction": pair.static_friction, "soil.rolling_friction": pair.rolling_friction,
            "soil.density": material.density}


#: The DEM-side candidates for what the twin gets wrong, each a name -> (case overrides, why), calibrated on the soil
#: lab alone and fixed before their runs (docs/cmu-twin/README.md, "Candidates").
CANDIDATES = {
    "plate-soil": (
        _particles(cmu_sand.PLATE_FIT_PAIR, cmu_sand.PLATE_FIT_MATERIAL),
        "The soil calibrated on the sand's plates alone (wheelsoil.parameters.cmu_sand.PLATE_FIT_PAIR): the shear\n"
        "box's peak 39 deg and 0.9 kPa against the chosen soil's 45 deg and 2.9 kPa."),
    "rolling-fit": (
        _particles(cmu_sand.MID_FIT_PAIR, cmu_sand.MID_FIT_MATERIAL),
        "Between the two lab soils (wheelsoil.parameters.cmu_sand.MID_FIT_PAIR): sliding 0.51 and rolling 0.22, the\n"
        "fraction 0.69 of the way from the chosen soil to the plate-only one fitted on the seen 0-deg driving trial."),
    "particle-scale": (
        {"soil.diameter_min": round(0.8 * cmu_sand.TWIN_DIAMETERS[0], 9),
         "soil.diameter_max": round(0.8 * cmu_sand.TWIN_DIAMETERS[1], 9)},
        "The chosen soil's particles at x0.64 of the calibration's (x0.8 of the twin's): 4.1-6.1 mm, the grousers\n"
        "1.0 mean grain high instead of 0.8; about twice the particles and an hour a case on 2 cores."),
}
#: Candidates that change the twin's wheel, not its soil: name -> (case overrides, why). Chosen after the twin's runs
#: at 45 and 90 deg had been seen, so they are judged on steering angles no twin run has seen
#: (:data:`WHEEL_CANDIDATE_TRIALS`), against the twin's own runs of those trials (the ``cmu-held-out-angles`` sweep).
WHEEL_CANDIDATES = {
    "closed-wheel": (
        {"wheel.side_walls": True},
        "The wheel closed by a flat disc on each side (wheel.side_walls). The twin's wheel is an open drum: in its\n"
        "steady runs soil filled 7 % (45 deg) and 39 % (90 deg) of the drum's volume as solid grains, entering\n"
        "through the open sides and, at 90 deg, streaming through the wheel along its axle instead of being pushed\n"
        "aside. The lab's own model gives the wheel a side face that bulldozes the soil (R_b.m)."),
}
#: The trials a wheel candidate and its baseline run: the grousered wheel at 30 and 75 deg, driving 0.5, first repeat.
WHEEL_CANDIDATE_TRIALS = {"grouser": (30.0, 75.0)}
WHEEL_CANDIDATE_SLIPS = (0.5,)
#: The trials a wheel candidate's sweep holds besides, run once it is accepted: the angles whose twin runs it was chosen
#: on (45 and 90 deg, so they cannot judge it), for information and as the closed twin's runs there, which the soil
#: candidates and the bin checks are then owed against (docs/cmu-twin/README.md, the closed wheel's verdict).
WHEEL_CANDIDATE_SEEN_TRIALS = {"grouser": (45.0, 90.0)}
#: The trials a candidate runs: the grousered wheel at 0 deg (the trial whose twin showed the overprediction) and at
#: the held-out 45 and 90 deg (no twin result seen when this was fixed), driving 0.5 and 0.9, first repeat.
CANDIDATE_TRIALS = {"grouser": (0.0, 45.0, 90.0)}
CANDIDATE_SLIPS = (0.5, 0.9)
#: The replicas' condition: the twin's first steady trial (grousered wheel, 0 deg, driving 0.5); its other repeats,
#: each at its own measured load and seed, give the twin's run-to-run spread (docs/cmu-twin/README.md, rule 4).
REPLICA_CONDITION = ("grouser", 0.0, 0.5)
#: Runs again with a longer drive [s], per sweep: (wheel, steering angle [deg], commanded slip, drive [s]). A run that
#: the steady detector found drifting "within its own noise: a longer window would tell" at the end of its
#: :data:`TWIN_DRIVE_TIME` is run again, once, with the drive this names; its first run stays recorded as not steady.
#: The closed wheel at 75 deg (2026-11-29): the drawbar pull drifted +2.0 +- 1.2 N over 11.2-20.3 s (allowed 1.1 N).
LONGER_DRIVES = {"cmu-candidate-closed-wheel": (("grouser", 75.0, 0.5, 30.0),)}


#: The twin's drive [s]: what the steady detector needs in the twin's noise (the drawbar pull's pitch means scatter by
#: about 2.5 N against the 0.9 N of drift it allows): on synthetic runs of that regime (docs/steady_twin_regime.py,
#: docs/cmu-twin/steady-regime.md) a 6 s drive calls a stationary run steady in 25 % of seeds and a run drifting by
#: 10 % of its mean per second in 22 %, no better than chance; 20 s calls 97 % of stationary runs steady. Fixed on
#: 2026-11-27 from that campaign, before any twin run at 45 or 90 deg was steady.
TWIN_DRIVE_TIME = 20.0


def drive_time(slip: float, test) -> float:
    """The drive [s] of a trial's case: :data:`TWIN_DRIVE_TIME`, or longer where a braked wheel turns too slowly.

    The steady detector judges a run by pitches of the tread's rotation: one revolution first, then a window of at
    least ``output.average_time`` checked twice half a revolution apart (the wheel's period), so about 3 pi / omega
    of drive. Braking at travel slip i the hub turns at omega_0 (1 + i): at i = -0.5, 10.9 s; a dragged wheel does
    not turn (its pitches are those of its travel). ``test``: the ``[test]`` section of the sweeps' base preset
    (``cmu-grouser``)."""
    if -1.0 < slip < 0.0:
        need = 3.0 * math.pi / (test.angular_velocity * (1.0 + slip)) + test.spin_up_time
        return max(TWIN_DRIVE_TIME, round(need, 1))
    return TWIN_DRIVE_TIME


def trial_rows(folder: str | Path) -> list[dict]:
    """One sweep row per measured trial: ``wheel.preset``, ``case.seed`` (the repeat at its condition), ``test.slip``,
    ``test.slip_angle`` and ``test.load`` (the trial's measured mean load [N]), and for a braked or dragged trial
    ``test.drive_time`` (:func:`drive_time`)."""
    from .schema import load_case

    folder = Path(folder)
    base = load_case("cmu-grouser").test  # the sweeps' base, read once
    rows = []
    for wheel, name in TRIAL_FILES.items():
        path = folder / name
        if not path.is_file():
            raise WheelsoilInputError(f"{path} does not exist: the CMU trials are in "
                                      "../shared/data/measured/cmu_3d_terramechanics")
        repeats: dict[tuple, int] = {}
        with open(path, newline="") as fh:
            for row in csv.DictReader(fh):
                # the files' 'trial' column is not the repeat (mostly 1): a condition is the wheel, steering angle
                # and commanded rim speed, its repeats the rows in file order
                condition = (float(row["steering_angle_deg"]), float(row["rim_speed_mm_s"]))
                repeats[condition] = repeats.get(condition, 0) + 1
                rows.append({"wheel.preset": f"cmu-k10-{wheel}", "case.seed": repeats[condition],
                             "test.slip": float(row["slip"]), "test.slip_angle": float(row["steering_angle_deg"]),
                             "test.load": float(row["vertical_load_N"])})
                rows[-1]["test.drive_time"] = drive_time(float(row["slip"]), base)
    return rows


def _at(row: dict, wheel: str, angle: float, slip: float) -> bool:
    """Whether a sweep row is the ``wheel``'s ("grouser", "smooth") at that steering angle [deg] and commanded slip
    (within 0.05)."""
    return (row["wheel.preset"] == f"cmu-k10-{wheel}" and row["test.slip_angle"] == angle
            and abs(row["test.slip"] - slip) <= 0.05)


def _pick(rows: list[dict], wheels: dict, slips: tuple) -> list[dict]:
    """Per wheel, steering angle and commanded slip of ``wheels`` x ``slips``, the first repeat's trial."""
    out = []
    for wheel, angles in wheels.items():
        for angle in angles:
            for slip in slips:
                hits = [r for r in rows if _at(r, wheel, angle, slip) and r["case.seed"] == SUBSET_TRIAL]
                if len(hits) != 1:
                    raise WheelsoilInputError(f"the {wheel} wheel at {angle:g} deg, slip {slip:g}, repeat "
                                              f"{SUBSET_TRIAL} matches {len(hits)} trials, not one")
                out.extend(hits)
    return out


def subset(rows: list[dict]) -> list[dict]:
    """The rows of :data:`SUBSET`, the free-rolling and driving ones first, the braked and dragged ones after them:
    the order is the sweep's schedule only."""
    picked = _pick(rows, SUBSET, SUBSET_SLIPS)
    return [r for r in picked if r["test.slip"] >= 0.0] + [r for r in picked if r["test.slip"] < 0.0]


def replica_rows(rows: list[dict]) -> list[dict]:
    """The repeats other than the subset's of :data:`REPLICA_CONDITION`'s trial."""
    wheel, angle, slip = REPLICA_CONDITION
    out = [r for r in rows if _at(r, wheel, angle, slip) and r["case.seed"] != SUBSET_TRIAL]
    if not out:
        raise WheelsoilInputError(f"the {wheel} wheel at {angle:g} deg, slip {slip:g} has no repeat but the subset's")
    return out


def candidate_rows(rows: list[dict]) -> list[dict]:
    """The trials every candidate runs (:data:`CANDIDATE_TRIALS`); its overrides go in the sweep's ``[sweep.set]``."""
    return _pick(rows, CANDIDATE_TRIALS, CANDIDATE_SLIPS)


def longer_drives(rows: list[dict], longer: tuple) -> list[dict]:
    """Copies of the ``rows`` that ``longer`` names (:data:`LONGER_DRIVES`' entries: wheel, steering angle [deg],
    commanded slip within 0.05, drive [s]) with that ``test.drive_time``; each entry must name exactly one row."""
    out = []
    for wheel, angle, slip, drive in longer:
        hits = [r for r in rows if _at(r, wheel, angle, slip)]
        if len(hits) != 1:
            raise WheelsoilInputError(f"a longer drive of the {wheel} wheel at {angle:g} deg, slip {slip:g} matches "
                                      f"{len(hits)} rows of its sweep, not one")
        out.append({**hits[0], "test.drive_time": float(drive)})
    return out


def sweep_toml(rows: list[dict], description: str, common: dict | None = None) -> str:
    """A sweep file on the ``cmu-grouser`` base with one ``[[sweep.rows]]`` table per row and ``common``'s keys, if
    any, in ``[sweep.set]`` (every case's)."""
    def table(name: str, values: dict) -> list[str]:
        lines = [name]
        for key, value in values.items():
            text = f'"{value}"' if isinstance(value, str) else str(value).lower() if isinstance(value, bool) else repr(value)
            lines.append(f'"{key}" = {text}')
        return lines

    lines = [f"# {line}" if line else "#" for line in description.splitlines()]
    lines += ['[sweep]', 'base = "cmu-grouser"', '']
    if common:
        lines += table("[sweep.set]", common) + [""]
    for r in rows:
        lines += table("[[sweep.rows]]", r)
    return "\n".join(lines) + "\n"


def write_presets(folder: str | Path, presets: str | Path | None = None) -> list[Path]:
    """Write ``cmu-trials.toml`` and ``cmu-trials-subset.toml`` from the trials in ``folder``."""
    presets = Path(presets) if presets is not None else Path(__file__).parent / "presets" / "sweeps"
    rows = trial_rows(folder)
    common = ("Written by `python -m wheelsoil.cases.cmu_sweep ../shared/data/measured/cmu_3d_terramechanics`\n"
              "(wheelsoil.cases.cmu_sweep): one case per trial at its steering angle, slip and measured mean load;\n"
              "its repeat at its condition is the bed's seed; TWIN_DRIVE_TIME (20 s) of drive, stopped once steady: up to\n"
              "about 80 min a case on 2 cores, one at a time (--workers 1; benchmarks/README.md); a GPU: wheelsoil batch --arch.")
    paths = []
    sweeps = [("cmu-trials", rows, f"The CMU single-wheel trials, all {len(rows)}, as DEM-FEM cases.", None),
              ("cmu-trials-subset", subset(rows), "A subset of the CMU trials fixed before any result (cases/cmu_sweep.py "
               "SUBSET): 25 cases,\nthe free-rolling and driving ones first.", None),
              ("cmu-replicas", replica_rows(rows), "The other repeats of the subset's grousered wheel at 0 deg, driving 0.5 "
               "(cases/cmu_sweep.py REPLICA_CONDITION),\neach at its own load and seed: the twin's run-to-run spread.", None)]
    for name, (overrides, why) in CANDIDATES.items():
        sweeps.append((f"cmu-candidate-{name}", candidate_rows(rows),
                       f"DEM-side candidate '{name}' of the CMU twin (cases/cmu_sweep.py CANDIDATES; docs/cmu-twin/README.md).\n"
                       f"{why}\nThe grousered wheel at 0 deg (seen) and 45 and 90 deg (held out), driving 0.5 and 0.9.",
                       overrides))
    held_out = _pick(rows, WHEEL_CANDIDATE_TRIALS, WHEEL_CANDIDATE_SLIPS)
    sweeps.append(("cmu-held-out-angles", held_out, "The twin as it is at steering angles none of its runs has seen "
                   "(cases/cmu_sweep.py WHEEL_CANDIDATE_TRIALS):\nthe baseline of the wheel candidates, the grousered "
                   "wheel at 30 and 75 deg, driving 0.5.", None))
    seen = _pick(rows, WHEEL_CANDIDATE_SEEN_TRIALS, WHEEL_CANDIDATE_SLIPS)
    for name, (overrides, why) in WHEEL_CANDIDATES.items():
        sweeps.append((f"cmu-candidate-{name}", held_out + seen,
                       f"Wheel candidate '{name}' of the CMU twin (cases/cmu_sweep.py WHEEL_CANDIDATES; "
                       f"docs/cmu-twin/README.md).\n{why}\nThe grousered wheel at 30 and 75 deg (held out), driving "
                       "0.5; at 45 and 90 deg (seen), run once it is accepted.", overrides))
    for name, chosen, what, overrides in sweeps:
        chosen = chosen + longer_drives(chosen, LONGER_DRIVES.get(name, ()))
        path = presets / f"{name}.toml"
        path.write_text(sweep_toml(chosen, f"{what}\n{common}", overrides))
        paths.append(path)
    return paths


if __name__ == "__main__":
    for written in write_presets(sys.argv[1] if len(sys.argv) > 1 else "../shared/data/measured/cmu_3d_terramechanics"):
        print(written)
