"""The wheel's load-test report (``wheelsoil wheel``): radial stiffness against a point load and a flat plate, and
torsional stiffness, measured on a preset wheel's mesh with :mod:`.loadtest` and :mod:`.torsion`, written as CSV,
PNG and a summary dictionary. The command (``wheelsoil.cases.commands.wheel``) only reads its options, shows
progress and prints; what is measured, and how, lives here beside the wheel.

``progress(phase, done, total)``, where a function takes it, is called as each phase advances (phases: "point-load
stiffness", "plate curve at <angle> deg", "torsion, tread clamped", "torsion, torque on the tread").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.plotting import pyplot
from wheelsoil.provenance import atomic_output

from .loadtest import plate_load_curve, point_load_stiffness
from .torsion import torsion_test


@dataclass
class RadialLoadTest:
    """Point-load stiffness [N/m] at ``angles`` [deg] over one spoke pitch, the plate curves over the spoke and midway
    between spokes, and the plate's secant stiffness [N/m] at the nominal load by the wheel's angle [deg]."""

    angles: np.ndarray
    point_stiffness: list
    curves: list
    nominal_stiffness: dict = field(default_factory=dict)


@dataclass
class TorsionLoadTest:
    """Torsion curves (linear with the tread clamped and with the torque on the tread, then the corotational ones),
    the tread's inertia about the axle [kg m^2] and the torsion mode of the tread on its spokes, hub held [Hz]."""

    linear: dict
    curves: list
    inertia: float
    frequency: float

    def summary(self) -> dict:
        out = {"linear_tread_clamped_N_m_per_rad": self.linear["tread"].stiffness,
               "linear_torque_on_tread_N_m_per_rad": self.linear["free"].stiffness,
               "tread_inertia_kg_m2": self.inertia, "torsion_mode_hub_held_Hz": self.frequency}
        for c in self.curves[2:]:
            out[f"corotational_{c.hold}"] = {"twist_deg": np.degrees(c.twist).tolist(), "torque_N_m": c.torque.tolist()}
        return out


def _check_plate(points: int, max_load_factor: float) -> None:
    if points < 2:
        raise WheelsoilInputError(f"--points={points} must be >= 2")
    if not max_load_factor > 0:
        raise WheelsoilInputError(f"--max-load-factor={max_load_factor} must be > 0")


def _check_twist(max_twist_deg: float) -> None:
    if not 0 < max_twist_deg <= 45:
        raise WheelsoilInputError(f"--max-twist={max_twist_deg} deg must lie in (0, 45]")


def check_options(points: int, max_load_factor: float, max_twist_deg: float | None) -> None:
    """The load tests' settings, checked before any of them runs (``max_twist_deg`` None: no torsion test)."""
    _check_plate(points, max_load_factor)
    if max_twist_deg is not None:
        _check_twist(max_twist_deg)


def radial_load_test(geometry, points: int, max_load_factor: float, progress=None) -> RadialLoadTest:
    """Point-load stiffness at five angles over one spoke pitch, then ``points`` plate deflections up to
    ``max_load_factor`` times the nominal load at the softest angle's rate (at most a fifth of the radius), over the
    spoke and midway between spokes."""
    _check_plate(points, max_load_factor)
    report = progress or (lambda phase, done, total: None)
    pitch = geometry.spoke_pitch
    angles = np.linspace(0.0, pitch, 5)
    point = []
    for k, a in enumerate(angles):
        point.append(point_load_stiffness(geometry, a))
        report("point-load stiffness", k + 1, len(angles))
    top = min(max_load_factor * max(geometry.nominal_load, 1.0) / min(point), 0.2 * geometry.radius)
    deflections = np.linspace(top / points, top, points)
    curves = []
    for a in (0.0, pitch / 2):
        phase = f"plate curve at {a:g} deg"
        curves.append(plate_load_curve(geometry, deflections, a,
                                       progress=lambda k, n, phase=phase: report(phase, k, n)))
    nominal = {f"{c.angle:g}": c.stiffness_at(geometry.nominal_load) for c in curves
               if geometry.nominal_load and c.force[0] <= geometry.nominal_load <= c.force[-1]}
    return RadialLoadTest(angles, point, curves, nominal)


def write_load_csv(test: RadialLoadTest, path) -> None:
    rows = ["angle_deg,deflection_m,force_N,contact_nodes"]
    for c in test.curves:
        rows += [f"{c.angle:g},{d:.6g},{f:.6g},{n}" for d, f, n in zip(c.deflection, c.force, c.contact_nodes)]
    with atomic_output(path) as tmp:
        tmp.write_text("\n".join(rows) + "\n")


def torsion_load_test(geometry, mesh, max_twist_deg: float, corotational: bool, progress=None) -> TorsionLoadTest:
    """The linear torsional stiffness with the tread clamped and with the torque on the tread, and (``corotational``)
    the corotational curves at +-1 deg, +-max/2 and +-max of twist."""
    _check_twist(max_twist_deg)
    report = progress or (lambda phase, done, total: None)
    linear = {hold: torsion_test(geometry, method="linear", hold=hold) for hold in ("tread", "free")}
    curves = list(linear.values())
    twists = np.radians([-max_twist_deg, -max_twist_deg / 2, -1.0, 1.0, max_twist_deg / 2, max_twist_deg])
    if corotational:
        curves.append(torsion_test(geometry, twists, method="corotational", hold="tread",
                                   progress=lambda k, n: report("torsion, tread clamped", k, n)))
        curves.append(torsion_test(geometry, method="corotational", hold="free", torques=linear["free"].stiffness * twists,
                                   progress=lambda k, n: report("torsion, torque on the tread", k, n)))
    # the torsion mode of the tread on its spokes, hub held: f = sqrt(k_t / I) / 2 pi, I the tread's and grousers'
    # inertia about the axle (their nodes beyond the spokes' reach)
    mass, _ = mesh.lumped_mass()
    outer = np.flatnonzero(np.hypot(mesh.nodes[:, 0], mesh.nodes[:, 2]) >= geometry.tread_mid_radius - 1e-9)
    inertia = float(np.sum(mass[outer] * (mesh.nodes[outer, 0] ** 2 + mesh.nodes[outer, 2] ** 2)))
    frequency = math.sqrt(linear["free"].stiffness / inertia) / (2 * math.pi)
    return TorsionLoadTest(linear, curves, inertia, frequency)


def write_torsion_csv(test: TorsionLoadTest, path) -> None:
    rows = ["hold,method,twist_deg,torque_N_m,secant_stiffness_N_m_per_rad"]
    for c in test.curves:
        rows += [f"{c.hold},{c.method},{math.degrees(t):.6g},{q:.6g},{q / t:.6g}" for t, q in zip(c.twist, c.torque)]
    with atomic_output(path) as tmp:
        tmp.write_text("\n".join(rows) + "\n")


def plot_torsion(curves, path, name) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.5, 4))
    span = max(abs(float(np.max(np.abs(c.twist)))) for c in curves)
    for c in curves:
        label = f"{'tread clamped' if c.hold == 'tread' else 'torque on the tread'}, {c.method}"
        if c.method == "linear":
            tw = np.linspace(-span, span, 3)
            ax.plot(np.degrees(tw), c.stiffness * tw, "--", lw=1, label=label)
        else:
            ax.plot(np.degrees(c.twist), c.torque, "o-", label=label)
    ax.axhline(0, color="0.7", lw=0.5)
    ax.axvline(0, color="0.7", lw=0.5)
    ax.set_xlabel("twist: hub ahead of the tread [deg] (+: drive)")
    ax.set_ylabel("torque on the hub [N m]")
    ax.set_title(f"{name}: torsion load test")
    ax.legend(fontsize=7)
    fig.tight_layout()
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def plot_load_curves(curves, geometry, path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for c in curves:
        ax.plot(1e3 * np.concatenate([[0], c.deflection]), np.concatenate([[0], c.force]), "o-",
                label=f"wheel turned {c.angle:g} deg")
    if geometry.nominal_load:
        ax.axhline(geometry.nominal_load, color="0.5", ls="--", lw=0.8, label=f"nominal {geometry.nominal_load:g} N")
    ax.set_xlabel("plate deflection [mm]")
    ax.set_ylabel("plate force [N]")
    ax.set_title(f"{geometry.name}: radial load against a flat plate")
    ax.legend()
    fig.tight_layout()
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)
