"""Static radial load tests of a wheel: point-load stiffness and load-deflection against a flat plate.

Both use the assembled small-strain stiffness of :mod:`.linear` with the hub clamped:

* :func:`point_load_stiffness` -- a radial force on the lowest line of surface nodes (the definition
  behind the 13.2 kN/m quoted for the ExoMars wheel in seed 001), at any angular position of the
  wheel, so the periodic stiffness of a spoked wheel shows (seed 000);
* :func:`plate_load_curve` -- a rigid, frictionless flat plate pushed up against the wheel by given
  deflections; the contact set is found by the active-set method (a node is in contact when it would
  otherwise penetrate the plate, and leaves when its reaction would pull on the plate). The contact
  patch grows with the load, so the curve stiffens.

Geometric nonlinearity is neglected (deflections of a few per cent of the radius); the corotational
solver with dynamic relaxation gives the same force at a 5 mm plate deflection of the ExoMars-like
wheel within the penalty and convergence tolerances (see the closing note of issue 3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from wheelsoil.errors import WheelsoilInputError

from .geometry import WheelGeometry, build_wheel_mesh
from .linear import assemble_stiffness
from .mesh import StructureMesh


def _rotated(mesh: StructureMesh, angle_deg: float) -> StructureMesh:
    """The mesh turned by ``angle_deg`` about the axle (y), so another part of it faces down."""
    a = np.radians(angle_deg)
    rot = np.array([[np.cos(a), 0.0, np.sin(a)], [0.0, 1.0, 0.0], [-np.sin(a), 0.0, np.cos(a)]])
    ori = mesh.beam_orientation @ rot.T if len(mesh.beams) else None
    return StructureMesh(mesh.nodes @ rot.T, mesh.triangles, mesh.thickness, mesh.material, beams=mesh.beams,
                         beam_section=mesh.beam_section if len(mesh.beams) else None, beam_orientation=ori,
                         part=mesh.part, part_names=mesh.part_names, surface=mesh.surface,
                         drilling_penalty=mesh.drilling_penalty)


class _ClampedSystem:
    def __init__(self, mesh: StructureMesh, hub_nodes: np.ndarray):
        self.mesh = mesh
        self.k = assemble_stiffness(mesh).tocsr()
        fixed = np.zeros(6 * mesh.n_nodes, bool)
        fixed[(6 * hub_nodes[:, None] + np.arange(6)).ravel()] = True
        self.free = np.flatnonzero(~fixed)

    def solve(self, prescribed: dict[int, float], forces: np.ndarray | None = None) -> np.ndarray:
        """Displacements with the given dofs prescribed (others free unless clamped)."""
        n = 6 * self.mesh.n_nodes
        u = np.zeros(n)
        pres = np.array(sorted(prescribed), dtype=np.int64)
        if pres.size:
            u[pres] = [prescribed[i] for i in pres]
        unknown = np.setdiff1d(self.free, pres)
        rhs = (np.zeros(n) if forces is None else forces.reshape(-1))[unknown] - self.k[unknown][:, pres] @ u[pres]
        u[unknown] = spla.spsolve(self.k[unknown][:, unknown].tocsc(), rhs)
        return u


@dataclass
class LoadCurve:
    """Plate deflection [m], plate force [N] and number of nodes in contact, per load step."""

    deflection: np.ndarray
    force: np.ndarray
    contact_nodes: np.ndarray
    angle: float

    def secant_stiffness(self) -> np.ndarray:
        """F / delta at each point [N/m]."""
        return self.force / self.deflection

    def stiffness_at(self, load: float) -> float:
        """Secant stiffness [N/m] at a given load [N], interpolated along the curve."""
        if not (self.force[0] <= load <= self.force[-1]):
            raise WheelsoilInputError(
                f"load {load} N is outside the tested range {self.force[0]:.4g}..{self.force[-1]:.4g} N"
            )
        return float(load / np.interp(load, self.force, self.deflection))


def _down_surface(mesh: StructureMesh) -> tuple[np.ndarray, np.ndarray]:
    nodes = np.unique(mesh.triangles[mesh.surface])
    return nodes, mesh.nodes[nodes, 2]


def point_load_stiffness(geometry: WheelGeometry, angle: float = 0.0, load: float = 100.0) -> float:
    """Radial stiffness [N/m] for a point load on the lowest surface line with the wheel turned by ``angle``."""
    mesh, hub = build_wheel_mesh(geometry)
    mesh = _rotated(mesh, angle)
    nodes, z = _down_surface(mesh)
    bottom = nodes[z < z.min() + 1e-9 * geometry.radius]
    forces = np.zeros((mesh.n_nodes, 6))
    forces[bottom, 2] = load / len(bottom)
    u = _ClampedSystem(mesh, hub).solve({}, forces).reshape(-1, 6)
    return float(load / u[bottom, 2].mean())


def plate_load_curve(geometry: WheelGeometry, deflections, angle: float = 0.0, progress=None) -> LoadCurve:
    """Force-deflection of a rigid flat plate pushed up against the clamped-hub wheel.

    ``deflections`` [m] are the plate's travel after first touch (increasing, > 0).
    """
    deflections = np.asarray(deflections, float)
    if deflections.ndim != 1 or deflections.size == 0 or not np.all(deflections > 0) or np.any(np.diff(deflections) <= 0):
        raise WheelsoilInputError(f"deflections must be increasing and > 0 m, got {deflections.tolist()}")
    if deflections[-1] > 0.25 * geometry.radius:
        raise WheelsoilInputError(
            f"deflection {deflections[-1]} m exceeds a quarter of the radius ({0.25 * geometry.radius:.4g} m); "
            "the small-deflection load test does not apply"
        )
    mesh, hub = build_wheel_mesh(geometry)
    mesh = _rotated(mesh, angle)
    system = _ClampedSystem(mesh, hub)
    nodes, z = _down_surface(mesh)
    gap = z - z.min()
    forces, counts = [], []
    active = set(nodes[gap < 1e-12].tolist())
    for k, delta in enumerate(deflections):
        for _ in range(100):
            prescribed = {6 * n + 2: delta - gap[np.searchsorted(nodes, n)] for n in active}
            u = system.solve(prescribed).reshape(-1, 6)
            reaction = (system.k @ u.reshape(-1)).reshape(-1, 6)[:, 2]
            pulling = [n for n in active if reaction[n] < 0.0]
            penetrating = [n for n, g in zip(nodes, gap) if n not in active and u[n, 2] < delta - g - 1e-12 * geometry.radius]
            if not pulling and not penetrating:
                break
            active -= set(pulling)
            active |= set(penetrating)
        else:
            raise WheelsoilInputError(f"the contact set did not settle at deflection {delta} m")
        forces.append(float(sum(reaction[n] for n in active)))
        counts.append(len(active))
        if progress is not None:
            progress(k + 1, len(deflections))
    return LoadCurve(deflections, np.asarray(forces), np.asarray(counts), float(angle))
