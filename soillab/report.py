"""What each lab test writes: a CSV of its curves, a JSON of its figures (with the measured values beside them where
the sand's own data have them) and a PNG, all written atomically into one folder."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from wheelsoil.parameters import cmu_k10
from wheelsoil.plotting import pyplot
from wheelsoil.provenance import atomic_output, provenance

from wheelsoil.bearing import circular_footing
from .bekker import PowerFit, common_exponent, fit_k_at_n, fit_power_law, split_k
from .measured import LoadCurve, mean_curve
from .penetration import PenetrationResult
from .poured import PouredBedResult
from .repose import ReposeResult
from .shear import ShearResult


def _write(folder: Path, name: str, table: pd.DataFrame, figures: dict, fig) -> dict[str, Path]:
    folder.mkdir(parents=True, exist_ok=True)
    paths = {ext: folder / f"{name}.{ext}" for ext in ("csv", "json", "png")}
    with atomic_output(paths["csv"]) as tmp:
        table.to_csv(tmp, index=False)
    with atomic_output(paths["json"]) as tmp:
        tmp.write_text(json.dumps({"test": name, **figures, "provenance": provenance()}, indent=2, default=float))
    with atomic_output(paths["png"]) as tmp:
        fig.savefig(tmp, dpi=120, bbox_inches="tight", format="png")
    pyplot().close(fig)
    return paths


def write_poured(result: PouredBedResult, folder: Path) -> tuple[dict, dict[str, Path]]:
    table = pd.DataFrame([b.__dict__ for b in result.beds])
    mean, sd = result.bulk_density
    phi, phi_sd = result.packing_fraction
    figures = {"bulk_density_kg_m3": mean, "bulk_density_sd_kg_m3": sd, "packing_fraction": phi,
               "packing_fraction_sd": phi_sd, "measured_bulk_density_kg_m3": cmu_k10.BULK_DENSITY,
               "relative_error": mean / cmu_k10.BULK_DENSITY - 1.0, "seeds": [b.seed for b in result.beds]}
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.bar([str(b.seed) for b in result.beds], [b.bulk_density for b in result.beds], color="tab:brown")
    ax.axhline(cmu_k10.BULK_DENSITY, color="k", ls="--", label="CMU sand, measured")
    ax.set_xlabel("seed")
    ax.set_ylabel("bulk density [kg/m³]")
    ax.set_ylim(0.8 * cmu_k10.BULK_DENSITY, 1.1 * max(cmu_k10.BULK_DENSITY, mean))
    ax.legend()
    return figures, _write(folder, "poured", table, figures, fig)


def write_repose(result: ReposeResult, folder: Path) -> tuple[dict, dict[str, Path]]:
    rows = [pd.DataFrame({"seed": r.seed, "position_m": r.position, "height_m": r.height, "fitted": r.fitted})
            for r in result.runs]
    mean, sd = result.angle
    figures = {"method": "draw-down (ledge), periodic across the width", "angle_deg": mean, "angle_sd_deg": sd,
               "angles_deg": [r.angle for r in result.runs], "at_rest": [r.at_rest for r in result.runs],
               "measured_angle_deg": cmu_k10.ANGLE_OF_REPOSE, "difference_deg": mean - cmu_k10.ANGLE_OF_REPOSE}
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 3.5))
    for r in result.runs:
        line = ax.plot(r.position, r.height, label=f"seed {r.seed}: {r.angle:.1f}°")[0]
        ax.plot(r.position[r.fitted], r.height[r.fitted], "o", ms=3, color=line.get_color())
    ax.set_xlabel("run-out position [m]")
    ax.set_ylabel("surface height [m]")
    ax.set_title(f"angle of repose {mean:.1f} ± {sd:.1f}° (CMU sand {cmu_k10.ANGLE_OF_REPOSE:g}°)")
    ax.set_aspect("equal")
    ax.legend(fontsize=8)
    return figures, _write(folder, "repose", pd.concat(rows), figures, fig)


def write_shear(result: ShearResult, folder: Path) -> tuple[dict, dict[str, Path]]:
    rows = [pd.DataFrame({"normal_stress_Pa": r.normal_stress, "displacement_m": r.displacement,
                          "shear_stress_Pa": r.shear_stress, "measured_normal_Pa": r.measured_normal,
                          "cap_rise_m": r.cap_rise}) for r in result.runs]
    envelope = {key: {"friction_angle_deg": mc.friction_angle, "friction_angle_se_deg": mc.friction_angle_se,
                      "cohesion_Pa": mc.cohesion, "cohesion_se_Pa": mc.cohesion_se}
                for key, mc in (("peak", result.peak), ("residual", result.residual))}
    figures = {**envelope, "particles": result.particles, "bulk_density_kg_m3": result.bulk_density,
               "shear_speed_m_s": result.speed,
               "runs": [{"imposed_normal_Pa": r.normal_stress, "measured_normal_Pa": r.mean_normal,
                         "shear_plane_normal_Pa": r.plane_normal, "peak_Pa": r.peak,
                         "peak_displacement_m": r.peak_displacement, "peak_reached": r.peak_reached,
                         "residual_Pa": r.residual, "wall_seconds": r.wall_seconds} for r in result.runs]}
    plt = pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.8))
    for r in result.runs:
        a.plot(1e3 * r.displacement, 1e-3 * r.shear_stress, label=f"σ = {1e-3 * r.normal_stress:g} kPa")
    a.set_xlabel("shear displacement [mm]")
    a.set_ylabel("shear stress [kPa]")
    a.legend()
    sig = np.array([r.plane_normal for r in result.runs])
    grid = np.linspace(0, sig.max() * 1.1, 20)
    for key, mc, marker in (("peak", result.peak, "o"), ("residual", result.residual, "s")):
        values = [r.peak if key == "peak" else r.residual for r in result.runs]
        b.plot(1e-3 * sig, 1e-3 * np.asarray(values), marker, label=f"{key}: φ = {mc.friction_angle:.1f} ± "
               f"{mc.friction_angle_se:.1f}°, c = {1e-3 * mc.cohesion:.2f} ± {1e-3 * mc.cohesion_se:.2f} kPa")
        b.plot(1e-3 * grid, 1e-3 * (mc.cohesion + grid * math.tan(math.radians(mc.friction_angle))), "--", lw=0.8)
    b.set_xlabel("normal stress on the shear plane [kPa]")
    b.set_ylabel("shear stress [kPa]")
    b.legend(fontsize=8)
    return figures, _write(folder, "shear", pd.concat(rows), figures, fig)


def _fit_dict(fit: PowerFit) -> dict:
    return {"k_kPa_m^n": 1e-3 * fit.k, "k_se_kPa_m^n": 1e-3 * fit.k_se, "n": fit.n, "n_se": fit.n_se,
            "rms_kPa": 1e-3 * fit.rms, "points": fit.points}


def bekker_table(simulated: list[LoadCurve], measured: list[LoadCurve]) -> dict:
    """Bekker's fit computed the same way for both sides: per curve k and n (free), the common n (median of the
    measured fits), k at that n per curve, and k_c, k_phi from the plate sizes (radius b = D/2)."""
    out: dict = {}
    fits = {id(c): fit_power_law(c.sinkage, c.pressure, label=c.label) for c in simulated + measured}
    n_common = common_exponent([fits[id(c)] for c in measured]) if measured else \
        common_exponent([fits[id(c)] for c in simulated])
    out["common_n"] = n_common
    for side, curves in (("simulated", simulated), ("measured", measured)):
        per = []
        for c in curves:
            k_at, k_at_se = fit_k_at_n(c.sinkage, c.pressure, n_common, label=c.label)
            per.append({"label": c.label, "diameter_m": c.size, **_fit_dict(fits[id(c)]),
                        "k_at_common_n_kPa_m^n": 1e-3 * k_at, "k_at_common_n_se_kPa_m^n": 1e-3 * k_at_se})
        out[side] = {"curves": per}
        sizes = {c.size for c in curves}
        if len(sizes) >= 2:
            split = split_k([0.5 * c.size for c in curves], [1e3 * p["k_at_common_n_kPa_m^n"] for p in per], n_common)
            out[side]["k_c_kPa_m^(n-1)"] = 1e-3 * split.k_c
            out[side]["k_c_se"] = 1e-3 * split.k_c_se
            out[side]["k_phi_kPa_m^n"] = 1e-3 * split.k_phi
            out[side]["k_phi_se"] = 1e-3 * split.k_phi_se
    return out


def pressure_errors(simulated: list[LoadCurve], measured: list[LoadCurve], sinkages) -> list[dict]:
    """Per plate size and sinkage: the simulated pressure (mean over replicas), the measured mean and standard
    deviation over trials, and the relative error [Pa]."""
    rows = []
    z = np.asarray(sinkages, float)
    for size in sorted({c.size for c in simulated}):
        sim = [c for c in simulated if c.size == size]
        mea = [c for c in measured if c.size == size]
        s_mean, s_sd, _ = mean_curve(sim, z)
        m_mean, m_sd, m_n = mean_curve(mea, z) if mea else (np.full(z.shape, np.nan),) * 2 + (np.zeros(z.shape),)
        area = sim[0].area
        for k, zk in enumerate(z):
            rows.append({"diameter_m": size, "sinkage_m": zk, "simulated_Pa": s_mean[k] / area,
                         "simulated_sd_Pa": s_sd[k] / area, "measured_Pa": m_mean[k] / area,
                         "measured_sd_Pa": m_sd[k] / area, "measured_trials": int(m_n[k]),
                         "relative_error": s_mean[k] / m_mean[k] - 1.0 if m_n[k] else float("nan")})
    return rows


def write_penetration(results: list[PenetrationResult], measured: list[LoadCurve], folder: Path, name: str,
                      *, friction_angle: float | None = None, cohesion: float = 0.0) -> tuple[dict, dict[str, Path]]:
    """Plate or wheel curves, simulated and measured, in one figure; the Bekker table (plates) and the pressure
    errors; with the lab's friction angle [deg], the bearing capacity of each plate beside its deepest pressure."""
    simulated = [r.curve for r in results]
    table = pd.concat([pd.DataFrame({"source": "DEM", "label": c.label, "size_m": c.size, "sinkage_m": c.sinkage,
                                     "force_N": c.force}) for c in simulated]
                      + [pd.DataFrame({"source": "measured", "label": c.label, "size_m": c.size,
                                       "sinkage_m": c.sinkage, "force_N": c.force}) for c in measured])
    figures: dict = {"runs": [{"label": r.curve.label, "particles": r.particles, "bulk_density_kg_m3": r.bulk_density,
                               "packing_fraction": r.packing_fraction, "inertial_number": r.inertial_number,
                               "wall_seconds": r.wall_seconds, "steps": r.steps, "time_step_s": r.time_step,
                               "bed_seconds": r.bed_seconds} for r in results]}
    if name == "plate":
        figures["bekker"] = bekker_table([c for c in simulated if c.sinkage.max() > 0],
                                         [c for c in measured if c.size in {s.size for s in simulated}])
        figures["pressure"] = pressure_errors(simulated, measured, [0.005, 0.01, 0.015, 0.02, 0.025])
        if friction_angle is not None:
            figures["bearing"] = [_bearing(r, friction_angle, cohesion) for r in results]
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    colours = {}
    for c in measured:
        key = (c.size, c.wheel)
        colour = colours.setdefault(key, f"C{len(colours)}")
        ax.plot(1e3 * c.sinkage, c.force, color=colour, lw=0.7, alpha=0.5)
    for c in simulated:
        key = (c.size, c.wheel)
        colour = colours.setdefault(key, f"C{len(colours)}")
        ax.plot(1e3 * c.sinkage, c.force, color=colour, lw=2.0, label=c.label)
    ax.plot([], [], color="grey", lw=0.7, label="measured (CMU), one line a trial")
    ax.set_xlabel("sinkage [mm]")
    ax.set_ylabel("force [N]")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=8)
    return figures, _write(folder, name, table, figures, fig)


def _bearing(result: PenetrationResult, friction_angle: float, cohesion: float) -> dict:
    c = result.curve
    depth = float(c.sinkage.max())
    unit_weight = result.bulk_density * result.gravity
    cap = circular_footing(c.size, depth, friction_angle, cohesion, unit_weight)
    deepest = float(np.mean(c.force[-5:])) / c.area
    return {"label": c.label, "depth_m": depth, "pressure_at_depth_Pa": deepest, "meyerhof_Pa": cap.meyerhof,
            "terzaghi_Pa": cap.terzaghi, "ratio_to_meyerhof": deepest / cap.meyerhof,
            "ratio_to_terzaghi": deepest / cap.terzaghi}


def headline(test: str, figures: dict) -> str:
    """One line of a test's main figures for the terminal."""
    if test == "poured":
        return (f"bulk density {figures['bulk_density_kg_m3']:.0f} ± {figures['bulk_density_sd_kg_m3']:.0f} kg/m³ "
                f"(CMU sand {figures['measured_bulk_density_kg_m3']:.0f}, {100 * figures['relative_error']:+.1f} %), "
                f"packing fraction {figures['packing_fraction']:.3f}")
    if test == "repose":
        return (f"angle of repose {figures['angle_deg']:.1f} ± {figures['angle_sd_deg']:.1f} deg over "
                f"{len(figures['angles_deg'])} packings (CMU sand {figures['measured_angle_deg']:g} deg)")
    if test == "shear":
        pk, rs = figures["peak"], figures["residual"]
        return (f"peak friction angle {pk['friction_angle_deg']:.1f} ± {pk['friction_angle_se_deg']:.1f} deg, cohesion "
                f"{1e-3 * pk['cohesion_Pa']:.2f} ± {1e-3 * pk['cohesion_se_Pa']:.2f} kPa; residual "
                f"{rs['friction_angle_deg']:.1f} ± {rs['friction_angle_se_deg']:.1f} deg")
    if test == "plate":
        parts = []
        for row in figures["pressure"]:
            if abs(row["sinkage_m"] - 0.01) < 1e-9:
                measured = (f"measured {1e-3 * row['measured_Pa']:.1f} ± {1e-3 * row['measured_sd_Pa']:.1f}"
                            if row["measured_trials"] else "no measured curve")
                parts.append(f"{1e3 * row['diameter_m']:g} mm plate at 10 mm: {1e-3 * row['simulated_Pa']:.1f} kPa "
                             f"({measured})")
        return "; ".join(parts)
    runs = figures["runs"]
    return f"{len(runs)} wheel pressing run(s); curves in the CSV and PNG"
