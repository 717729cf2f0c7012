"""The soil's own measurements: the CMU plate- and wheel-sinkage tests (force against sinkage), read into typed
curves in SI units.

Files (``../shared/data/measured/cmu_3d_terramechanics/force_displacement/``, MIT licence, see its README):
``plate_sinkage.csv`` (``box, plate_diameter_mm, trial, sinkage_mm, force_N, ...``) and ``wheel_sinkage.csv``
(``box, wheel, trial, sinkage_mm, force_N, ...``). A file without a needed column is refused with the columns it
has and the ones it needs.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from wheelsoil.errors import WheelsoilInputError

PLATE_COLUMNS = ("box", "plate_diameter_mm", "trial", "sinkage_mm", "force_N")
WHEEL_COLUMNS = ("box", "wheel", "trial", "sinkage_mm", "force_N")


@dataclass(frozen=True)
class LoadCurve:
    """Force against sinkage of one pressing test (measured or simulated).

    kind: ``"plate"`` or ``"wheel"``; size: plate diameter [m] (plates) or wheel radius [m] (wheels);
    label: e.g. ``"large box, 60 mm plate, trial 2"``; sinkage: (n,) [m], + down from first contact;
    force: (n,) the soil's vertical reaction [N]; area: the plate's area [m^2] (None for a wheel);
    wheel: ``"smooth"`` / ``"grouser"`` for a wheel; box and trial where measured.
    """

    kind: str
    size: float
    label: str
    sinkage: np.ndarray
    force: np.ndarray
    area: float | None = None
    wheel: str | None = None
    box: str | None = None
    trial: int | None = None

    @property
    def pressure(self) -> np.ndarray:
        """Mean pressure under a plate, force / area [Pa]."""
        if self.area is None:
            raise WheelsoilInputError(f"{self.label}: a wheel curve has no plate area; use the wheel's chord pressure")
        return self.force / self.area


def plate_area(diameter: float) -> float:
    """A circular plate's area [m^2] as the CMU lab computes it, (D/2)^2 * 3.14159 (read_force_displacement.m)."""
    return (0.5 * diameter) ** 2 * 3.14159


def default_data_dir() -> Path:
    """``../shared/data/measured/cmu_3d_terramechanics/force_displacement`` beside the current directory."""
    return Path.cwd().parent / "shared" / "data" / "measured" / "cmu_3d_terramechanics" / "force_displacement"


def _read(path: Path, needed: tuple[str, ...]) -> pd.DataFrame:
    path = Path(path)
    if not path.is_file():
        raise WheelsoilInputError(f"measured file {str(path)!r} does not exist")
    table = pd.read_csv(path)
    missing = [c for c in needed if c not in table.columns]
    if missing:
        raise WheelsoilInputError(f"measured file {str(path)!r} lacks the column(s) {missing}: it has "
                                  f"{list(table.columns)}, a sinkage test needs {list(needed)}")
    if table.empty:
        raise WheelsoilInputError(f"measured file {str(path)!r} has no rows")
    return table


def load_plate_curves(path: str | Path | None = None, *, box: str | None = None) -> list[LoadCurve]:
    """Every plate test of ``plate_sinkage.csv`` (default: :func:`default_data_dir`), one curve per box, plate and
    trial (``box``: only that box, ``"large"`` or ``"small"``)."""
    table = _read(Path(path) if path is not None else default_data_dir() / "plate_sinkage.csv", PLATE_COLUMNS)
    if box is not None:
        if box not in set(table["box"]):
            raise WheelsoilInputError(f"box = {box!r} is not in the plate file; it has {sorted(set(table['box']))}")
        table = table[table["box"] == box]
    curves = []
    for (b, d_mm, trial), rows in table.groupby(["box", "plate_diameter_mm", "trial"], sort=True):
        d = 1e-3 * float(d_mm)
        curves.append(LoadCurve("plate", d, f"{b} box, {d_mm:g} mm plate, trial {trial}",
                                1e-3 * rows["sinkage_mm"].to_numpy(float), rows["force_N"].to_numpy(float),
                                area=plate_area(d), box=str(b), trial=int(trial)))
    return curves


def load_wheel_curves(path: str | Path | None = None, *, box: str | None = None,
                      wheel_radius: float = 0.058) -> list[LoadCurve]:
    """Every wheel test of ``wheel_sinkage.csv``, one curve per box, wheel and trial."""
    table = _read(Path(path) if path is not None else default_data_dir() / "wheel_sinkage.csv", WHEEL_COLUMNS)
    if box is not None:
        table = table[table["box"] == box]
    curves = []
    for (b, wheel, trial), rows in table.groupby(["box", "wheel", "trial"], sort=True):
        curves.append(LoadCurve("wheel", wheel_radius, f"{b} box, {wheel} wheel, trial {trial}",
                                1e-3 * rows["sinkage_mm"].to_numpy(float), rows["force_N"].to_numpy(float),
                                wheel=str(wheel), box=str(b), trial=int(trial)))
    return curves


def mean_curve(curves: list[LoadCurve], sinkage: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean force, its standard deviation and the count of curves at each ``sinkage`` [m] (each curve linearly
    interpolated where it reaches; NaN where none does)."""
    stack = np.full((len(curves), len(sinkage)), np.nan)
    for k, c in enumerate(curves):
        order = np.argsort(c.sinkage)
        z, f = c.sinkage[order], c.force[order]
        inside = (sinkage >= z[0]) & (sinkage <= z[-1])
        stack[k, inside] = np.interp(sinkage[inside], z, f)
    count = np.sum(np.isfinite(stack), axis=0)
    mean = np.full(len(sinkage), np.nan)
    std = np.full(len(sinkage), np.nan)
    some, several = count > 0, count > 1
    mean[some] = np.nanmean(stack[:, some], axis=0)
    std[several] = np.nanstd(stack[:, several], axis=0, ddof=1)
    return mean, std, count


def wheel_chord_pressure(force: np.ndarray, sinkage: np.ndarray, radius: float, width: float) -> np.ndarray:
    """The CMU lab's wheel "pressure" F / (b 2 r sin theta), theta = acos((r - z)/r) (chord x width) [Pa]."""
    theta = np.arccos(np.clip((radius - sinkage) / radius, -1.0, 1.0))
    chord = 2.0 * radius * np.sin(theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(chord > 0, force / (width * chord), np.nan)


__all__ = ["LoadCurve", "PLATE_COLUMNS", "WHEEL_COLUMNS", "default_data_dir", "load_plate_curves",
           "load_wheel_curves", "mean_curve", "plate_area", "wheel_chord_pressure"]
