"""What a testbed run reports, as typed values: the series it records (:data:`SERIES_UNITS`) and its steady-state
summary (:class:`RunSummary`, one :class:`QuantityStats` per quantity), with no Taichi, so that results are read,
tabulated and compared without the engine.

The summary is what :class:`~.testbed.Testbed` returns, what the result writer stores (``summary.json`` and the HDF5
file's ``summary`` group, through :meth:`RunSummary.to_dict`) and what the command line, the result reader, the sweep
tables and the replica and convergence reports read, by attribute: ``summary.drawbar_pull.mean``,
``summary.quantity(name).sem``, ``summary.steady``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import ClassVar

from .force_balance import BALANCE_UNITS

#: Series recorded at every sample, with units.
SERIES_UNITS = {
    "t": "s",
    "drawbar_pull": "N",
    "lateral_force": "N",
    "vertical_force": "N",
    "torque": "N m",
    "sinkage": "m",
    "tread_sinkage": "m",
    "slip": "1",
    "slip_angle": "deg",
    "tread_slip": "1",
    "tread_slip_angle": "deg",
    "wind_up": "rad",
    "tread_omega": "rad/s",
    "slip_speed": "m/s",
    "load": "N",
    "omega": "rad/s",
    "travel": "m",
    "hub_x": "m",
    "hub_y": "m",
    "hub_z": "m",
    "contacts": "1",
    **BALANCE_UNITS,
}
#: Quantities whose drift the steady-state detector checks (the tread slip is checked on its own).
STEADY_CHECKED = ("drawbar_pull", "lateral_force", "vertical_force", "torque", "sinkage")
#: Quantities averaged over the steady window.
STEADY_QUANTITIES = STEADY_CHECKED + ("tread_sinkage", "slip", "slip_angle", "tread_slip_angle", "wind_up",
                                       "vertical_force_applied", "balance_residual")
#: Every quantity a summary holds: the averaged ones and the tread slip.
SUMMARY_QUANTITIES = STEADY_QUANTITIES + ("tread_slip",)


@dataclass(frozen=True)
class QuantityStats:
    """One quantity over the steady window (units :attr:`units`, those of :data:`SERIES_UNITS`).

    mean, std: the window's mean and the samples' standard deviation (the fluctuation).
    sem, ci95, dof: the mean's standard error from the pitch means, its 95 % half-interval and the noise estimate's
        degrees of freedom (:func:`~.steady.window_stats`); NaN where the window was not whole pitches.
    drift, drift_sem: the trend over the window and its standard error.
    zero_within_noise: the mean is zero within its noise (then only a trend makes it unsteady); None where not judged.
    """

    mean: float
    std: float
    sem: float = math.nan
    ci95: float = math.nan
    dof: float = math.nan
    drift: float = math.nan
    drift_sem: float = math.nan
    units: str = ""
    zero_within_noise: bool | None = None

    def to_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        if self.zero_within_noise is None:
            del d["zero_within_noise"]
        return d

    @classmethod
    def from_dict(cls, d: dict) -> QuantityStats:
        """From :meth:`to_dict`'s layout; keys a result written by an older version lacks are NaN."""
        known = {f.name for f in fields(cls)}
        values = {k: v for k, v in d.items() if k in known}
        values.setdefault("mean", math.nan)
        values.setdefault("std", math.nan)
        if "zero_within_noise" in values and values["zero_within_noise"] is not None:
            values["zero_within_noise"] = bool(values["zero_within_noise"])
        return cls(**values)


_MISSING = QuantityStats(math.nan, math.nan)


@dataclass(frozen=True)
class RunSummary:
    """A run's steady-state summary.

    steady: a steady window was found (at ``steady_checks`` checks in a row); otherwise the quantities are the last
        window's, for information only, and :attr:`reasons` says why.
    window: the averaging window (start, end) [s]; samples: the samples in it; pitches: the tread's pitches in it;
        pitch_deg: one pitch [deg]; period_pitches: pitches per period of the wheel.
    reasons: why the run is not steady (empty when steady).
    commanded_slip, commanded_slip_angle: the rig's command [-, deg].
    One :class:`QuantityStats` per quantity of :data:`SUMMARY_QUANTITIES`.
    """

    steady: bool
    window: tuple[float, float]
    samples: int
    pitches: int
    pitch_deg: float
    period_pitches: int
    reasons: tuple[str, ...]
    commanded_slip: float
    commanded_slip_angle: float
    drawbar_pull: QuantityStats = _MISSING
    lateral_force: QuantityStats = _MISSING
    vertical_force: QuantityStats = _MISSING
    torque: QuantityStats = _MISSING
    sinkage: QuantityStats = _MISSING
    tread_sinkage: QuantityStats = _MISSING
    slip: QuantityStats = _MISSING
    slip_angle: QuantityStats = _MISSING
    tread_slip_angle: QuantityStats = _MISSING
    wind_up: QuantityStats = _MISSING
    vertical_force_applied: QuantityStats = _MISSING
    balance_residual: QuantityStats = _MISSING
    tread_slip: QuantityStats = _MISSING

    QUANTITIES: ClassVar[tuple[str, ...]] = SUMMARY_QUANTITIES
    _SCALARS: ClassVar[tuple[str, ...]] = ("steady", "window", "samples", "pitches", "pitch_deg", "period_pitches",
                                           "reasons", "commanded_slip", "commanded_slip_angle")

    def quantity(self, name: str) -> QuantityStats:
        """The statistics of quantity ``name`` (one of :data:`SUMMARY_QUANTITIES`)."""
        if name not in self.QUANTITIES:
            raise KeyError(f"a run summary has no quantity {name!r}: it holds {', '.join(self.QUANTITIES)}")
        return getattr(self, name)

    def mean(self, name: str) -> float:
        """The steady mean of quantity ``name``."""
        return float(self.quantity(name).mean)

    def quantities(self) -> dict[str, QuantityStats]:
        """Name -> statistics, in :data:`SUMMARY_QUANTITIES`' order."""
        return {q: getattr(self, q) for q in self.QUANTITIES}

    def to_dict(self) -> dict:
        """The stored layout (``summary.json``'s ``summary``; the HDF5 ``summary`` group flattens it): the scalars,
        then one table of statistics per quantity."""
        d = {k: getattr(self, k) for k in self._SCALARS}
        d["window"], d["reasons"] = list(self.window), list(self.reasons)
        d.update({q: st.to_dict() for q, st in self.quantities().items()})
        return d

    @classmethod
    def from_dict(cls, d: dict) -> RunSummary:
        """From :meth:`to_dict`'s layout. Scalars a result written by an older version lacks take neutral values
        (no pitches, one pitch a period, no reasons, NaN), missing quantities NaN statistics."""
        window = d.get("window", (math.nan, math.nan))
        return cls(
            steady=bool(d["steady"]), window=(float(window[0]), float(window[1])), samples=int(d.get("samples", 0)),
            pitches=int(d.get("pitches", 0)), pitch_deg=float(d.get("pitch_deg", math.nan)),
            period_pitches=int(d.get("period_pitches", 1)), reasons=tuple(d.get("reasons", ())),
            commanded_slip=float(d.get("commanded_slip", math.nan)),
            commanded_slip_angle=float(d.get("commanded_slip_angle", math.nan)),
            **{q: QuantityStats.from_dict(d[q]) for q in cls.QUANTITIES if isinstance(d.get(q), dict)})
