"""Static torsion load test of a wheel: the torque the hub needs against the twist of the hub relative to the tread.

A driven flexible wheel winds up: the hub turns ahead of the tread until the spokes carry the driving torque.
How far is set by the wheel's torsional stiffness k_t = T / twist, which this test measures the way a
lab would on a torsion rig (twist in the drive sense, i.e. the hub ahead of the tread about the axle +y):

* ``hold="tread"`` -- the tread is clamped (every tread node held in position and rotation, as by a rigid
  ring) and the hub is turned rigidly by the twist; the torque is the hub's reaction;
* ``hold="free"`` -- the hub is clamped and the tread carries a uniform tangential traction with the torque
  -T (as the soil loads it); the twist is the tread's best-fit rigid rotation about the axle, negated.

``method="linear"``: one sparse solve with the small-strain stiffness (:func:`.linear.assemble_stiffness`);
symmetric in the twist's sign by construction. ``method="corotational"``: the geometrically nonlinear
corotational elements the dynamics use, at every requested twist, in both directions, by Newton's method
(:func:`.statics.solve_static`): bowed spokes make a real wheel's curve lopsided.

Closed form (:func:`spoked_wheel_torsion_stiffness`), for N straight spokes of length L = R - a, bending
rigidity EI in the wheel's plane, clamped at the hub (radius a) and at the rim (radius R): the hub end of
each spoke moves by a theta tangentially and turns by theta; with the clamped-clamped beam's end stiffness
(Przemieniecki, *Theory of Matrix Structural Analysis*, sec. 5.6: F = 12 EI v / L^3 + 6 EI phi / L^2,
M = 6 EI v / L^2 + 4 EI phi / L) the torque is T = a F + M, so

    k_t = N (4 EI / L) (1 + 3 a / L + 3 a^2 / L^2).

``tests/test_flexwheel_torsion.py`` holds the wheel against it (beam spokes exact; shell spokes with nu = 0
converging with the mesh) and checks the linear and corotational tests agree at small twist.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse.linalg as spla

from wheelsoil.errors import SimulationUnstableError, WheelsoilInputError
from wheelsoil.rigid_motion import rotation_about

from .geometry import WheelGeometry, build_wheel_mesh
from .linear import assemble_stiffness
from .mesh import StructureMesh

#: The axle of a wheel mesh (``build_wheel_mesh``: axle along y, wheel plane x-z, centre at the origin).
AXLE = np.array([0.0, 1.0, 0.0])
#: Largest twist increment [deg] of the corotational test's continuation (as torque: that twist at k_t).
MAX_INCREMENT_DEG = 2.0


def spoked_wheel_torsion_stiffness(spokes: int, bending_rigidity: float, hub_radius: float, rim_radius: float) -> float:
    """k_t [N m/rad] of ``spokes`` straight spokes clamped at the hub (radius a) and the rim (radius R), each of
    bending rigidity EI [N m^2] in the wheel's plane: N (4 EI / L) (1 + 3 a/L + 3 a^2/L^2), L = R - a."""
    if not (spokes >= 1 and bending_rigidity > 0 and 0 <= hub_radius < rim_radius):
        raise WheelsoilInputError(f"spokes = {spokes}, EI = {bending_rigidity} N m^2, a = {hub_radius} m, R = {rim_radius} m "
                                  "must satisfy spokes >= 1, EI > 0, 0 <= a < R")
    length = rim_radius - hub_radius
    q = hub_radius / length
    return spokes * 4.0 * bending_rigidity / length * (1.0 + 3.0 * q + 3.0 * q * q)


def _axle_rotation_matrix(angle: float) -> np.ndarray:
    """Rotation by ``angle`` [rad] about +y."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


@dataclass
class TorsionCurve:
    """Twist [rad] (hub ahead of the tread about the axle, the drive sense), torque [N m] on the hub, and
    for the corotational method the Newton iterations it took to reach each point from the undeformed wheel."""

    twist: np.ndarray
    torque: np.ndarray
    method: str
    hold: str
    iterations: np.ndarray = field(default_factory=lambda: np.zeros(0, int))

    def secant_stiffness(self) -> np.ndarray:
        """T / twist at each point [N m/rad]."""
        return self.torque / self.twist

    @property
    def stiffness(self) -> float:
        """The stiffness of the smallest twist tested [N m/rad] (the linear k_t for ``method="linear"``)."""
        k = int(np.argmin(np.abs(self.twist)))
        return float(self.torque[k] / self.twist[k])


def tread_nodes(mesh: StructureMesh) -> np.ndarray:
    """Nodes of the tread shell (part ``tread``)."""
    part = mesh.part[: len(mesh.triangles)]
    return np.unique(mesh.triangles[part == mesh.part_names.index("tread")])


def _tread_traction(mesh: StructureMesh, torque: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodal loads (N, 6) of a uniform tangential traction on the tread with moment ``torque`` about +y, and the
    tread nodes' area weights."""
    part = mesh.part[: len(mesh.triangles)]
    tri = mesh.triangles[part == mesh.part_names.index("tread")]
    area = 0.5 * np.linalg.norm(np.cross(mesh.nodes[tri[:, 1]] - mesh.nodes[tri[:, 0]],
                                         mesh.nodes[tri[:, 2]] - mesh.nodes[tri[:, 0]]), axis=1)
    weight = np.zeros(mesh.n_nodes)
    for a in range(3):
        np.add.at(weight, tri[:, a], area / 3.0)
    x = mesh.nodes
    tangent = np.cross(AXLE, x)  # about +y: y x r
    arm2 = x[:, 0] ** 2 + x[:, 2] ** 2
    scale = torque / float(np.sum(weight * arm2))
    loads = np.zeros((mesh.n_nodes, 6))
    loads[:, :3] = (scale * weight)[:, None] * tangent
    return loads, weight


def torsion_test(geometry: WheelGeometry, twists=None, *, method: str = "linear", hold: str = "tread",
                 torques=None, progress=None) -> TorsionCurve:
    """The torsion load test (see the module docstring).

    ``twists`` [rad] (``hold="tread"``) or ``torques`` [N m] (``hold="free"``): the points of the curve, of
    either sign (default: +-0.5 deg and +-5 deg, or the torques that give about those twists). ``progress(k,
    n)`` is called after each point.
    """
    if method not in ("linear", "corotational"):
        raise WheelsoilInputError(f"torsion test method = {method!r}; choose 'linear' or 'corotational'")
    if hold not in ("tread", "free"):
        raise WheelsoilInputError(f"torsion test hold = {hold!r}; choose 'tread' (tread clamped, hub turned) or "
                                  "'free' (hub clamped, torque on the tread)")
    mesh, hub = build_wheel_mesh(geometry)
    tread = tread_nodes(mesh)
    if hold == "tread":
        points = np.radians([-5.0, -0.5, 0.5, 5.0]) if twists is None else np.asarray(twists, float)
        name = "twists"
    else:
        if torques is None:
            k_lin = _linear_free(mesh, hub, tread, 1.0)[1]
            points = k_lin * np.radians([-5.0, -0.5, 0.5, 5.0])
        else:
            points = np.asarray(torques, float)
        name = "torques"
    if points.ndim != 1 or points.size == 0 or not np.all(np.isfinite(points)) or np.any(points == 0.0):
        raise WheelsoilInputError(f"torsion test {name} must be a non-empty list of finite, non-zero numbers, got "
                                  f"{np.asarray(points).tolist()}")
    if hold == "tread" and np.abs(points).max() > math.radians(45.0):
        raise WheelsoilInputError(f"torsion test twists up to {math.degrees(np.abs(points).max()):.0f} deg: allowed "
                                  "|twist| <= 45 deg")
    twist, torque, iters = [], [], []
    if method == "linear":
        if hold == "tread":
            k_t = _linear_tread(mesh, hub, tread)
            twist, torque = points, k_t * points
        else:
            for t in points:
                phi, _ = _linear_free(mesh, hub, tread, t)
                twist.append(phi)
                torque.append(t)
        iters = np.zeros(len(points), int)
        if progress is not None:
            progress(len(points), len(points))
    else:
        twist, torque, iters = _corotational(mesh, hub, tread, points, hold, name, progress)
    order = np.argsort(twist)
    return TorsionCurve(np.asarray(twist, float)[order], np.asarray(torque, float)[order], method, hold,
                        np.asarray(iters, int)[order])


def _corotational(mesh: StructureMesh, hub: np.ndarray, tread: np.ndarray, points: np.ndarray, hold: str, name: str,
                  progress) -> tuple[list, list, list]:
    """The corotational curve by continuation: each sign's points in order of size, each reached from the last
    in increments of at most ``MAX_INCREMENT`` of twist (or the torque of it, at the linear stiffness)."""
    from .statics import solve_static
    from .structure import Structure

    step = math.radians(MAX_INCREMENT_DEG)
    if hold == "free":
        step *= abs(_linear_free(mesh, hub, tread, 1.0)[1])
    out, done = {}, 0
    for sign in (-1.0, 1.0):
        targets = sorted(p for p in points if np.sign(p) == sign)
        if sign < 0:
            targets = targets[::-1]
        structure = Structure(mesh, hub_nodes=None)
        level, total_iterations = 0.0, 0
        for target in targets:
            while abs(level) < abs(target):
                level = sign * min(abs(target), abs(level) + step)
                if hold == "tread":
                    rot = _axle_rotation_matrix(level)
                    x = structure.positions()
                    rots = structure.rotations()
                    x[hub] = mesh.nodes[hub] @ rot.T
                    rots[hub] = rot
                    structure.set_state(positions=x, rotations=rots)
                    sol = solve_static(structure, np.concatenate([hub, tread]))
                else:
                    loads, weight = _tread_traction(mesh, -level)
                    sol = solve_static(structure, hub, loads, axis=AXLE)
                total_iterations += sol.iterations
                if not sol.converged:
                    raise SimulationUnstableError(
                        f"the corotational torsion test did not converge at {name[:-1]} {level:.4g} (residual "
                        f"{sol.residual:.2e} after {sol.iterations} iterations): the wheel may buckle at that load")
            if hold == "tread":
                f, m = structure.internal_forces()
                xh = structure.positions()[hub]
                # the hub supplies the opposite of the elements' pull on its nodes
                t = -float(np.sum(np.cross(xh, f[hub]) @ AXLE + m[hub] @ AXLE))
                out[target] = (target, t, total_iterations)
            else:
                _, weight = _tread_traction(mesh, 1.0)
                phi = -rotation_about(structure.positions()[tread], mesh.nodes[tread], AXLE, weight[tread])
                out[target] = (phi, target, total_iterations)
            done += 1
            if progress is not None:
                progress(done, len(points))
    rows = [out[p] for p in points]
    return [r[0] for r in rows], [r[1] for r in rows], [r[2] for r in rows]


def _linear_tread(mesh: StructureMesh, hub: np.ndarray, tread: np.ndarray) -> float:
    """k_t [N m/rad] with the tread clamped and the hub turned rigidly (small-strain stiffness, one solve)."""
    k = assemble_stiffness(mesh).tocsr()
    n = mesh.n_nodes
    u = np.zeros((n, 6))
    u[hub, :3] = np.cross(AXLE, mesh.nodes[hub])  # unit twist: u = y x X, rotation (0, 1, 0)
    u[hub, 3:] = AXLE
    held = np.zeros(n, bool)
    held[hub] = held[tread] = True
    pres = (6 * np.flatnonzero(held)[:, None] + np.arange(6)).ravel()
    free = (6 * np.flatnonzero(~held)[:, None] + np.arange(6)).ravel()
    uu = u.reshape(-1)
    uu[free] = spla.spsolve(k[free][:, free].tocsc(), -(k[free][:, pres] @ uu[pres]))
    reaction = (k @ uu).reshape(n, 6)
    return float(np.sum(np.cross(mesh.nodes[hub], reaction[hub, :3]) @ AXLE + reaction[hub, 3:] @ AXLE))


def _linear_free(mesh: StructureMesh, hub: np.ndarray, tread: np.ndarray, torque: float) -> tuple[float, float]:
    """(twist [rad], k_t [N m/rad]) with the hub clamped and ``torque`` [N m] on the tread as a uniform
    tangential traction against the drive (small-strain stiffness, one solve)."""
    loads, weight = _tread_traction(mesh, -torque)
    k = assemble_stiffness(mesh).tocsr()
    n = mesh.n_nodes
    held = np.zeros(n, bool)
    held[hub] = True
    free = (6 * np.flatnonzero(~held)[:, None] + np.arange(6)).ravel()
    u = np.zeros(6 * n)
    u[free] = spla.spsolve(k[free][:, free].tocsc(), loads.reshape(-1)[free])
    u = u.reshape(n, 6)
    x = mesh.nodes[tread]
    w = weight[tread]
    # small-rotation best fit about the axle: phi = sum w (X x u).y / sum w |X_perp|^2
    phi = float(np.sum(w * (np.cross(x, u[tread, :3]) @ AXLE)) / np.sum(w * (x[:, 0] ** 2 + x[:, 2] ** 2)))
    twist = -phi
    return twist, torque / twist
