"""Measured single-wheel data: CSV files whose column names carry their units, read into SI NumPy arrays.

A column named ``<quantity>_<unit>`` (``drawbar_pull_N``, ``sinkage_mm``, ``rim_speed_mm_s``,
``vertical_load_n``, ``meas_torque_nm``) is converted to SI by its unit suffix (:data:`UNITS`); angles stay
in degrees (``_deg``), as in case files and reports. Columns without a known unit (``wheel``, ``slip``,
``trial``, ``source``) are kept as they are: numbers as floats, the rest as strings.

:func:`load_table` reads any such file; :func:`load_cmu_trials` and :func:`load_digitised` turn the two
datasets in ``../shared/data/measured`` into :class:`Measurements` with the standard names the model uses
(slip, slip_angle [deg], load [N], drawbar_pull, lateral_force, sinkage, torque and their standard
deviations where measured) and the wheel of every row.
"""

import csv
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.gravity import EARTH_GRAVITY, gravity_label
from wheelsoil.parameters import cmu_k10
from wheelsoil.slip import heading_slip_from_travel, travel_slip_from_heading

from .cmu_rows import check_cmu_rows

#: unit suffix -> (SI unit, factor to SI); longest suffix wins (``_mm_s`` before ``_s``).
UNITS = {
    "_m_s2": ("m/s^2", 1.0),
    "_mm_s": ("m/s", 1e-3),
    "_m_s": ("m/s", 1.0),
    "_kg_m3": ("kg/m^3", 1.0),
    "_nm": ("N m", 1.0),
    "_Nm": ("N m", 1.0),
    "_mm": ("m", 1e-3),
    "_m": ("m", 1.0),
    "_N": ("N", 1.0),
    "_n": ("N", 1.0),
    "_kPa": ("Pa", 1e3),
    "_Pa": ("Pa", 1.0),
    "_deg": ("deg", 1.0),
    "_s": ("s", 1.0),
    "_kg": ("kg", 1.0),
}


def split_unit(column: str) -> tuple[str, str | None, float]:
    """(quantity name, SI unit or None, factor to SI) of a column name."""
    for suffix in sorted(UNITS, key=len, reverse=True):
        if column.endswith(suffix) and len(column) > len(suffix):
            unit, factor = UNITS[suffix]
            return column[: -len(suffix)], unit, factor
    return column, None, 1.0


@dataclass
class Table:
    """Columns of one measured file: ``columns[name]`` is a float array in SI (or a string array)."""

    path: Path
    columns: dict[str, np.ndarray]
    units: dict[str, str | None]

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def require(self, *names: str) -> None:
        missing = [n for n in names if n not in self.columns]
        if missing:
            raise WheelsoilInputError(
                f"{self.path}: missing column(s) {missing}; it has {sorted(self.columns)} (units from the name "
                f"suffix, e.g. drawbar_pull_N, sinkage_mm)")


def load_table(path: str | Path) -> Table:
    """Read a CSV file with units in its column names (see the module docstring)."""
    path = Path(path)
    if not path.is_file():
        raise WheelsoilInputError(f"measured data file {str(path)!r} does not exist")
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    if len(rows) < 2:
        raise WheelsoilInputError(f"{path}: needs a header row and at least one data row")
    header, body = rows[0], rows[1:]
    for k, row in enumerate(body, start=2):
        if len(row) != len(header):
            raise WheelsoilInputError(f"{path}, line {k}: {len(row)} fields, the header has {len(header)}")
    columns, units = {}, {}
    for j, raw in enumerate(header):
        name, unit, factor = split_unit(raw.strip())
        values = [row[j].strip() for row in body]
        try:
            numbers = np.array([float(v) if v != "" else np.nan for v in values])
        except ValueError:
            if unit is not None:
                bad = next(v for v in values if not _is_float(v))
                raise WheelsoilInputError(f"{path}: column {raw!r} has unit {unit} but holds {bad!r}") from None
            columns[name], units[name] = np.array(values), None
            continue
        columns[name], units[name] = numbers * factor, unit
    return Table(path, columns, units)


def _is_float(v: str) -> bool:
    try:
        float(v)
    except ValueError:
        return False
    return True


@dataclass
class Measurements:
    """Steady-state single-wheel measurements, one row per test (SI; slip_angle in degrees).

    Conditions: slip, slip_angle, load, gravity, the pass number over the same soil (``passes``, 1 unless
    given: undisturbed soil), and the wheel of each row (radius, width, grouser_height, grouser_count) plus a
    ``group`` label (e.g. wheel type or source). Responses: ``responses[name]``
    for drawbar_pull, lateral_force, sinkage, torque (NaN where not measured) and ``std[name]`` where the
    data give a standard deviation. ``sinkage_relative``: the sinkage's zero is not the soil surface
    (e.g. the wheel's start position), so only its changes are comparable with a model.

    ``slip`` is along the heading (architecture). ``travel_slip`` is the slip against the whole travel speed (the
    CMU rig's), which alone describes a wheel at 90 deg (:class:`wheelsoil.slip.WheelSpeeds`); where a source does
    not give it, it is derived from ``slip`` (NaN at 90 deg, where it cannot be).
    """

    name: str
    slip: np.ndarray
    slip_angle: np.ndarray
    load: np.ndarray
    gravity: np.ndarray
    radius: np.ndarray
    width: np.ndarray
    grouser_height: np.ndarray
    grouser_count: np.ndarray
    group: np.ndarray
    responses: dict[str, np.ndarray]
    std: dict[str, np.ndarray] = field(default_factory=dict)
    notes: str = ""
    sinkage_relative: bool = False
    passes: np.ndarray | None = None
    travel_slip: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.passes is None:
            self.passes = np.ones(len(self.slip))
        if self.travel_slip is None:  # a condition holding text is named by check_measurements, not here
            numeric = all(np.asarray(getattr(self, k)).dtype.kind in "fiu" for k in ("slip", "slip_angle"))
            self.travel_slip = (travel_slip_from_heading(self.slip, self.slip_angle) if numeric
                                else np.full(len(self.slip), np.nan))

    def __len__(self) -> int:
        return len(self.slip)

    #: The per-row condition arrays after ``name``, in the constructor's order.
    ROW_FIELDS = ("slip", "slip_angle", "load", "gravity", "radius", "width", "grouser_height", "grouser_count", "group")

    def select(self, mask) -> "Measurements":
        mask = np.asarray(mask)
        pick = lambda a: a[mask]  # noqa: E731
        return Measurements(self.name, *(pick(getattr(self, k)) for k in self.ROW_FIELDS),
            responses={k: pick(v) for k, v in self.responses.items()}, std={k: pick(v) for k, v in self.std.items()},
            notes=self.notes, sinkage_relative=self.sinkage_relative, passes=pick(self.passes),
            travel_slip=pick(self.travel_slip))

    def kinds(self) -> np.ndarray:
        """Each row's kind of motion (:data:`ROW_KINDS`): "dragged" (the wheel does not turn, travel slip -1),
        "braking" (it turns slower than it travels, -1 < travel slip < :data:`FREE_ROLLING_SLIP`) or "driving"
        (faster, or free rolling), by the slip against the whole travel speed, as the rig sets it."""
        s = self.travel_slip
        return np.where(s <= -1.0, "dragged", np.where(s < FREE_ROLLING_SLIP, "braking", "driving"))


#: The kinds of motion a row may hold (:meth:`Measurements.kinds`).
ROW_KINDS = ("driving", "braking", "dragged")
#: A row whose travel slip is above this is free rolling or driving, not braking: the CMU rig's free-rolling rows
#: (rim speed set equal to the carriage's) record -0.003 to +0.003 from the carriage's speed jitter.
FREE_ROLLING_SLIP = -0.01


#: The columns of a CMU trial file (after the unit suffix is split off).
CMU_COLUMNS = ("wheel", "steering_angle", "slip", "drawbar_pull", "lateral_force", "vertical_load", "sinkage")
#: What every CMU dataset says of itself.
CMU_NOTES = "Pavlov (CMU), MIT licence; sinkage zero is the wheel's start position"


def load_cmu_file(path: str | Path, *, domain: str = "all") -> Measurements:
    """One CMU trial file (``grouser_wheel_trials.csv``, ``smooth_wheel_trials.csv`` or a file of the same
    columns): the wheel of each row from its ``wheel`` column (``grouser`` or ``smooth``).

    Slip is converted to wheelsoil's convention (:func:`wheelsoil.slip.heading_slip_from_travel`): the rig takes
    slip against the carriage's whole speed V, wheelsoil and its model against V's component along the heading,
    V cos(beta). At 60 deg the rig's 0.5 is 0.75 here; at 90 deg a turning wheel has slip 1 (it does not advance
    along its heading) and a dragged one -1, as at every angle.

    The soil carries ``vertical_load``; sinkage is kept as recorded (the lab's zero is the wheel's start
    position, not the soil surface, so only its changes are comparable). ``domain`` (:data:`DOMAINS`): "all" keeps
    every row; "driving" keeps rows with 0 <= slip < 1 below 90 deg (the classical driving branch, the subset
    validated before braking and 90 deg were in the model): rows braking along the heading (r omega < V cos beta),
    dragged wheels and every 90 deg row are dropped.
    The grouser count is not in the files: 0 for both (grousers enter through their height only where a
    model asks for it).

    Lateral force: the lab's sign is positive for a positive steering angle, i.e. it points along the
    lateral slip's resistance as the lab defines it. In wheelsoil's frame (v_y = v_x tan beta) the soil
    resists the lateral slip with a force of the opposite sign to beta, so the loader flips the lab's sign.
    """
    t = load_table(path)
    t.require(*CMU_COLUMNS)
    group = np.asarray(t.columns["wheel"]).astype(str)
    unknown = sorted(set(group) - set(cmu_k10.GROUSER_HEIGHT))
    if unknown:
        raise WheelsoilInputError(f"{path}: column 'wheel' holds {unknown}; the CMU rig's wheels are "
                                  f"{sorted(cmu_k10.GROUSER_HEIGHT)}")
    n = len(group)
    col = lambda key: np.asarray(t.columns[key], float)  # noqa: E731
    opt = lambda key: col(key) if key in t.columns else np.full(n, np.nan)  # noqa: E731
    check_cmu_rows(t, path)
    data = Measurements(
        name=Path(path).stem,
        slip=heading_slip_from_travel(col("slip"), col("steering_angle")), slip_angle=col("steering_angle"),
        load=col("vertical_load"),
        gravity=np.full(n, EARTH_GRAVITY), radius=np.full(n, cmu_k10.RADIUS), width=np.full(n, cmu_k10.WIDTH),
        grouser_height=np.array([cmu_k10.GROUSER_HEIGHT[g] for g in group]), grouser_count=np.zeros(n),
        group=group,
        responses={"drawbar_pull": col("drawbar_pull"), "lateral_force": -col("lateral_force"),
                   "sinkage": col("sinkage"), "torque": np.full(n, np.nan)},
        std={"drawbar_pull": opt("drawbar_pull_std"), "lateral_force": opt("lateral_force_std"),
             "vertical_load": opt("vertical_load_std")},
        notes=CMU_NOTES,
        sinkage_relative=True,
        travel_slip=col("slip"),
    )
    data, counts = in_domain(data, domain)
    data.notes = f"{CMU_NOTES}; {counts}"
    return data


#: The row sets ``wheelsoil validate --domain`` may keep: every row, or the classical driving branch.
DOMAINS = ("all", "driving")


def row_counts(data: Measurements) -> str:
    """A sentence counting the rows by kind of motion (:meth:`Measurements.kinds`) and those at 90 deg."""
    kinds = data.kinds()
    counts = ", ".join(f"{int((kinds == k).sum())} {k}" for k in ROW_KINDS)
    return f"{len(data)} rows: {counts}; {int((np.abs(data.slip_angle) >= 90.0).sum())} of them at 90 deg"


def in_domain(data: Measurements, domain: str) -> tuple[Measurements, str]:
    """The rows of ``domain`` (:data:`DOMAINS`) and a sentence counting what was kept and left out."""
    if domain not in DOMAINS:
        raise WheelsoilInputError(f"domain {domain!r}: choose one of {list(DOMAINS)}")
    if domain == "all":
        return data, f"every row kept ({row_counts(data)})"
    keep, counts = _driving_rows(data)
    return data.select(keep), counts


def _driving_rows(data: Measurements) -> tuple[np.ndarray, str]:
    """The rows on the classical driving branch (0 <= slip < 1 along the heading, below 90 deg) and a sentence
    counting the rows left out, by kind."""
    sideways = np.abs(data.slip_angle) >= 90.0
    braking = ~sideways & (data.slip < 0.0)
    keep = ~sideways & ~braking & (data.slip < 1.0)
    counts = (f"{int(keep.sum())} of {len(data)} rows kept: driving along the heading below 90 deg; left out: "
              f"{int(braking.sum())} braking along the heading (of them {int((braking & (data.slip <= -1.0)).sum())} "
              f"dragged), {int(sideways.sum())} at 90 deg, {int((~sideways & ~braking & ~keep).sum())} spinning "
              "in place")
    return keep, counts


def load_cmu_trials(folder: str | Path, *, domain: str = "all") -> Measurements:
    """The CMU 3D-terramechanics trials of a folder: both wheels' files (``grouser_wheel_trials.csv``,
    ``smooth_wheel_trials.csv``) read by :func:`load_cmu_file` into one set."""
    folder = Path(folder)
    parts, notes = [], [CMU_NOTES]
    for wheel in ("grouser", "smooth"):
        part, counts = in_domain(load_cmu_file(folder / f"{wheel}_wheel_trials.csv"), domain)
        notes.append(f"{wheel} wheel: {counts}")
        parts.append(part)
    cat = lambda key: np.concatenate([getattr(m, key) for m in parts])  # noqa: E731
    return Measurements(
        "cmu_3d_terramechanics", *(cat(k) for k in ("slip", "slip_angle", "load", "gravity", "radius", "width",
                                                    "grouser_height", "grouser_count", "group")),
        responses={q: np.concatenate([m.responses[q] for m in parts]) for q in parts[0].responses},
        std={q: np.concatenate([m.std[q] for m in parts]) for q in parts[0].std},
        notes="; ".join(notes), sinkage_relative=True, passes=cat("passes"), travel_slip=cat("travel_slip"))


def load_digitised(path: str | Path) -> Measurements:
    """The digitised single-wheel points (Ding 2011, Wang & Han 2016, Hurrell 2025), one row per point."""
    t = load_table(path)
    t.require("source", "wheel_radius", "wheel_width", "grouser_height", "grouser_count", "vertical_load", "slip",
              "meas_drawbar_pull", "meas_sinkage", "meas_torque")
    n = len(t)
    return Measurements(
        name="digitised_single_wheel",
        slip=t.columns["slip"], slip_angle=np.zeros(n), load=t.columns["vertical_load"], gravity=np.full(n, EARTH_GRAVITY),
        radius=t.columns["wheel_radius"], width=t.columns["wheel_width"],
        grouser_height=t.columns["grouser_height"], grouser_count=t.columns["grouser_count"],
        group=np.array([f"{s}:{'lug' if h > 0 else 'smooth'}" for s, h in zip(t.columns["source"],
                                                                               t.columns["grouser_height"])]),
        responses={"drawbar_pull": t.columns["meas_drawbar_pull"], "sinkage": t.columns["meas_sinkage"],
                   "torque": t.columns["meas_torque"], "lateral_force": np.full(n, np.nan)},
        notes="values read off published figures (approximate); cite the original papers",
    )


#: Columns of wheelsoil's own measurement format (:func:`save_measurements`, :func:`load_generic`).
GENERIC_COLUMNS = {
    "slip": "slip", "slip_angle": "slip_angle_deg", "load": "vertical_load_N", "gravity": "gravity_m_s2",
    "radius": "wheel_radius_m", "width": "wheel_width_m", "grouser_height": "grouser_height_m",
    "grouser_count": "grouser_count", "drawbar_pull": "drawbar_pull_N", "lateral_force": "lateral_force_N",
    "sinkage": "sinkage_m", "torque": "torque_Nm", "passes": "passes", "travel_slip": "travel_slip",
}


def save_measurements(data: Measurements, path: str | Path) -> Path:
    """Write measurements in wheelsoil's CSV format (units in the column names; readable by
    :func:`load_generic` and by any spreadsheet)."""
    from wheelsoil.provenance import atomic_output

    cols = {GENERIC_COLUMNS[k]: getattr(data, k) for k in ("slip", "slip_angle", "load", "gravity", "passes", "radius",
                                                           "width", "grouser_height", "grouser_count", "travel_slip")}
    cols |= {GENERIC_COLUMNS[q]: data.responses[q] for q in ("drawbar_pull", "lateral_force", "sinkage", "torque")}
    cols["group"] = data.group
    rows = [",".join(cols)] + [",".join(str(v[k]) if isinstance(v[k], str) else f"{float(v[k]):.10g}"
                                        for v in cols.values()) for k in range(len(data))]
    with atomic_output(path) as tmp:
        tmp.write_text("\n".join(rows) + "\n")
    return Path(path)


def load_generic(path: str | Path, name: str | None = None) -> Measurements:
    """Measurements in wheelsoil's CSV format (see :data:`GENERIC_COLUMNS`; slip, load, wheel radius and width
    required; slip angle 0, gravity 9.81, first pass, smooth wheel and missing responses (NaN) by default)."""
    t = load_table(path)
    t.require("slip", "vertical_load", "wheel_radius", "wheel_width")
    n = len(t)
    get = lambda key, default: t.columns.get(key, np.full(n, default))  # noqa: E731
    return Measurements(
        name=name or Path(path).stem, slip=t.columns["slip"], slip_angle=get("slip_angle", 0.0),
        load=t.columns["vertical_load"], gravity=get("gravity", EARTH_GRAVITY), radius=t.columns["wheel_radius"],
        width=t.columns["wheel_width"], grouser_height=get("grouser_height", 0.0), grouser_count=get("grouser_count", 0.0),
        group=t.columns["group"] if "group" in t.columns else np.full(n, "all"),
        responses={q: get(q, np.nan) for q in ("drawbar_pull", "lateral_force", "sinkage", "torque")},
        notes=f"read from {path}", passes=get("passes", 1.0),
        travel_slip=t.columns["travel_slip"] if "travel_slip" in t.columns else None,
    )


def load_sweep_summary(path: str | Path) -> Measurements:
    """The DEM--FEM runs of a wheelsoil sweep as a dataset, from its ``summary.csv`` (or the sweep folder):
    the rig settings and wheel of each case and its steady-state means and standard deviations.

    Sinkage is the tread sinkage (the rut depth below the levelled surface, without the wheel's
    deflection), the quantity the rigid-wheel model predicts; the lateral force keeps wheelsoil's sign
    (it opposes the lateral slip). Groups are the gravity levels ("1g", "moon" or the value). A case run with
    ``test.slip_speed = "travel"`` (the CMU rig's convention) has its slip converted to the heading's, as
    :func:`load_cmu_file` converts the rig's, so simulated and measured rows pair at the same slip. A run that did
    not reach a detected steady state (``steady`` false) reports no number: it is left out, and ``notes`` says how
    many were.
    """
    import pandas as pd

    path = Path(path)
    if path.is_dir():
        path = path / "summary.csv"
    if not path.is_file():
        raise WheelsoilInputError(f"{path} does not exist: a sweep folder has summary.csv once 'wheelsoil batch' "
                                  "has finished cases")
    t = pd.read_csv(path)
    not_steady = []
    if "steady" in t.columns:
        steady = t["steady"].astype(str).str.lower().isin(("true", "1", "1.0"))
        names = t["case"] if "case" in t.columns else "row " + t.index.astype(str)
        not_steady = [str(v) for v in names[~steady]]
        t = t.loc[steady].reset_index(drop=True)
        if t.empty:
            raise WheelsoilInputError(f"{path}: none of its {len(not_steady)} runs reached a steady state; there is "
                                      "no simulated number to compare")
    needed = ["slip_set", "slip_angle_set", "load_set", "gravity", "wheel_radius", "wheel_width", "grouser_count",
              "grouser_height"] + [f"{src}_{k}" for src in SIMULATED_RESPONSES.values() for k in ("mean", "std")]
    missing = [c for c in needed if c not in t.columns]
    if missing:
        raise WheelsoilInputError(f"{path} is not a wheelsoil sweep summary: columns {missing} are missing")
    g = t["gravity"].to_numpy(float)
    group = np.array([gravity_label(v, moon="moon", other="g{g:.3g}") for v in g])
    col = lambda key: t[key].to_numpy(float)  # noqa: E731
    slip = col("slip_set")
    travel_slip = None
    if "slip_speed" in t.columns:
        travel = t["slip_speed"].astype(str).to_numpy() == "travel"
        travel_slip = np.where(travel, slip, travel_slip_from_heading(slip, col("slip_angle_set")))
        slip = np.where(travel, heading_slip_from_travel(slip, col("slip_angle_set")), slip)
    return Measurements(
        name=path.parent.name, slip=slip, slip_angle=col("slip_angle_set"), load=col("load_set"),
        gravity=g, radius=col("wheel_radius"), width=col("wheel_width"), grouser_height=col("grouser_height"),
        grouser_count=col("grouser_count"), group=group.astype(str),
        responses={q: col(f"{src}_mean") for q, src in SIMULATED_RESPONSES.items()},
        std={q: col(f"{src}_std") for q, src in SIMULATED_RESPONSES.items()},
        notes=f"{len(t)} steady DEM-FEM runs of the wheelsoil sweep summarised in {path}"
              + (f" ({len(not_steady)} not steady, left out: {', '.join(not_steady)})" if not_steady else "")
              + "; sinkage is the tread sinkage",
        travel_slip=travel_slip,
    )


#: Dataset response -> the steady quantity of a wheelsoil result it is read from.
SIMULATED_RESPONSES = {"drawbar_pull": "drawbar_pull", "lateral_force": "lateral_force",
                       "sinkage": "tread_sinkage", "torque": "torque"}


#: The conditions every row needs as numbers.
CONDITIONS = ("slip", "slip_angle", "load", "gravity", "radius", "width", "grouser_height", "grouser_count")


def check_measurements(data: Measurements, source) -> Measurements:
    """Refuse a dataset the model cannot be fitted to, naming the file, column and rows: a condition that
    holds text or is missing in some rows, or no measured response at all."""
    for key in CONDITIONS:
        values = np.asarray(getattr(data, key))
        if values.dtype.kind not in "fiu":
            bad = [(k, v) for k, v in enumerate(values) if not _is_float(str(v))]
            k, v = bad[0][0], str(bad[0][1])
            raise WheelsoilInputError(f"{source}: the condition {key!r} must be a number in every row; data row "
                                      f"{k + 1} holds {v!r} ({len(bad)} such row(s))")
        missing = np.flatnonzero(~np.isfinite(values.astype(float)))
        if missing.size:
            raise WheelsoilInputError(f"{source}: the condition {key!r} is missing (empty or NaN) in data row(s) "
                                      f"{(missing + 1)[:10].tolist()}{' ...' if missing.size > 10 else ''}")
    _check_motion(data, source)
    measured = [q for q, v in data.responses.items() if np.isfinite(np.asarray(v, float)).any()]
    if not measured:
        raise WheelsoilInputError(f"{source}: no measured response in any row (columns such as drawbar_pull_N, "
                                  "lateral_force_N, sinkage_m, torque_Nm): nothing to validate against")
    return data


def _check_motion(data: Measurements, source) -> None:
    """Refuse rows whose motion the model cannot be told: slip or steering angle out of range, a row at 90 deg
    without the slip against the travel speed (``travel_slip``), or a travel slip that disagrees with the heading
    slip of the same row."""
    slip, beta, travel = (np.asarray(getattr(data, k), float) for k in ("slip", "slip_angle", "travel_slip"))
    given = np.isfinite(travel)
    heading = np.where(given, heading_slip_from_travel(np.where(given, travel, 0.0), beta), np.nan)
    for column, bad, allowed in (
        ("slip_angle", ~(np.abs(beta) <= 90.0), "-90 <= slip_angle <= 90 deg"),
        ("slip", ~((slip >= -1.0) & (slip <= 1.0)), "-1 <= slip <= 1"),
        ("travel_slip", given & ~((travel >= -1.0) & (travel < 1.0)), "-1 <= travel_slip < 1"),
        ("travel_slip", ~given & (np.abs(beta) >= 90.0),
         "a number at 90 deg: the slip along the heading cannot say how fast the wheel slides sideways"),
        ("slip", ~given & (slip >= 1.0), "slip < 1 (a wheel spinning in place) unless travel_slip says it travels"),
        ("slip", given & ~(np.abs(slip - heading) <= 1e-6),
         "the heading slip of the row's travel_slip and steering angle"),
    ):
        rows = np.flatnonzero(bad)
        if rows.size:
            k = rows[0]
            raise WheelsoilInputError(
                f"{source}: column {column!r} in data row {k + 1} (slip {slip[k]:g}, slip_angle {beta[k]:g} deg, "
                f"travel_slip {travel[k]:g}; {rows.size} such row(s)): allowed {allowed}")


def load_measurements(path: str | Path) -> Measurements:
    """Any supported dataset: a folder of CMU trial files, a wheelsoil sweep folder or its summary.csv
    (simulated), the digitised-points CSV, or wheelsoil's CSV format; checked by :func:`check_measurements`."""
    return check_measurements(_load_any(path), path)


def _load_any(path: str | Path) -> Measurements:
    path = Path(path)
    if path.is_dir():
        if (path / "grouser_wheel_trials.csv").is_file():
            return load_cmu_trials(path)
        if (path / "summary.csv").is_file():
            return load_sweep_summary(path)
        raise WheelsoilInputError(f"{path} is neither a folder of CMU trials (grouser_wheel_trials.csv / "
                                  "smooth_wheel_trials.csv) nor a wheelsoil sweep folder (summary.csv)")
    header = load_table(path).columns
    if all(c in header for c in CMU_COLUMNS):
        return load_cmu_file(path)
    if "tread_sinkage_mean" in header:
        return load_sweep_summary(path)
    if "meas_drawbar_pull" in header:
        return load_digitised(path)
    return load_generic(path)
