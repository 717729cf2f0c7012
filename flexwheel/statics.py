"""Static equilibrium by dynamic relaxation: the explicit solver run with kinetic damping.

Kinetic damping (Cundall 1976; Barnes 1999, Int. J. Space Struct. 14, 89-104): the structure moves
undamped under its loads; whenever the kinetic energy passes a maximum, every velocity is set to
zero. The energy removed at each peak drains the motion and the structure settles at a (stable)
equilibrium. Masses do not change the static answer, so the explicit integrator, its lumped masses
and its stable step are used as they are. Convergence is declared when the out-of-balance force and
moment are small relative to the loads (or to the elastic forces when the loading is a prescribed
displacement).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wheelsoil.errors import SimulationUnstableError

from .structure import Structure


@dataclass
class RelaxationResult:
    """How a relaxation ended: ``converged``, steps taken, final relative residual force and moment."""

    converged: bool
    steps: int
    residual_force: float
    residual_moment: float


def residuals(structure: Structure) -> tuple[float, float]:
    """Relative out-of-balance force and moment of the free nodes at the last step.

    The scales are the larger of the external loads and the element corner forces (each element's
    share, which do not cancel at equilibrium); the moment scale also includes force times the mean
    element size, so that structures loaded by forces alone are judged consistently.
    """
    f_tot, m_tot = structure.nodal_forces()
    free = np.ones(structure.mesh.n_nodes, bool)
    free[structure.hub_nodes] = False
    f_ext = structure.arrays.f_ext.to_numpy() + structure.mass[:, None] * structure.gravity
    m_ext = structure.arrays.m_ext.to_numpy()
    slot_f, slot_m = structure.element_corner_forces()
    size = structure.mesh.characteristic_length()
    scale_f = max(np.linalg.norm(f_ext[free]), 0.5 * np.linalg.norm(slot_f), 1e-300)
    scale_m = max(np.linalg.norm(m_ext[free]), 0.5 * np.linalg.norm(slot_m), scale_f * size)
    return float(np.linalg.norm(f_tot[free]) / scale_f), float(np.linalg.norm(m_tot[free]) / scale_m)


#: Relaxation runs at this fraction of the critical step: kinetic-damping restarts can feed energy
#: into modes close to the stability limit (the leapfrog's conserved energy differs from the kinetic
#: plus potential energy there by 1 / (1 - (omega dt / 2)^2)); well below the critical step they cannot
#: build up (measured: 0.5 still let a bent shell strip blow up after 25,000 steps; 0.3 did not).
RELAXATION_STEP_FRACTION = 0.3


def relax(
    structure: Structure,
    *,
    tolerance: float = 1e-6,
    max_steps: int = 200_000,
    check_every: int = 500,
    moment_tolerance: float | None = None,
) -> RelaxationResult:
    """Drive ``structure`` to static equilibrium under its current loads and hub position.

    The hub must be held (prescribed, zero velocity) or absent. Kinetic damping acts every step; the
    residual is checked every ``check_every`` steps. Returns a :class:`RelaxationResult`; raises
    :class:`SimulationUnstableError` if the state blows up.
    """
    moment_tolerance = tolerance if moment_tolerance is None else moment_tolerance
    zero = np.zeros((structure.mesh.n_nodes, 3))
    structure.set_state(velocities=zero, angular_velocities=zero)
    structure.arrays.peak.from_numpy(np.zeros(2))
    steps = 0
    rf = rm = np.inf
    dt = RELAXATION_STEP_FRACTION * structure.critical_time_step
    while steps < max_steps:
        structure.step(check_every, dt, kinetic_damping=True)
        steps += check_every
        if not np.isfinite(structure.kinetic_energy()):
            raise SimulationUnstableError(f"dynamic relaxation diverged after {steps} steps")
        rf, rm = residuals(structure)
        if rf < tolerance and rm < moment_tolerance:
            return RelaxationResult(True, steps, rf, rm)
    return RelaxationResult(False, steps, rf, rm)


# ---------------------------------------------------------------------------------------------
# Newton's method on the corotational internal forces


@dataclass
class StaticSolution:
    """How a Newton solve ended: ``converged``, iterations, and the final relative out-of-balance."""

    converged: bool
    iterations: int
    residual: float


def rotation_matrices(theta: np.ndarray) -> np.ndarray:
    """exp(spin(theta)) for each row of ``theta`` (n, 3): Rodrigues' formula, (n, 3, 3)."""
    theta = np.asarray(theta, float).reshape(-1, 3)
    g = np.linalg.norm(theta, axis=1)
    small = g < 1e-8
    gs = np.where(small, 1.0, g)
    a = np.where(small, 1.0 - g**2 / 6.0, np.sin(gs) / gs)
    b = np.where(small, 0.5 - g**2 / 24.0, (1.0 - np.cos(gs)) / gs**2)
    k = np.zeros((len(theta), 3, 3))
    k[:, 0, 1], k[:, 0, 2], k[:, 1, 2] = -theta[:, 2], theta[:, 1], -theta[:, 0]
    k[:, 1, 0], k[:, 2, 0], k[:, 2, 1] = theta[:, 2], -theta[:, 1], theta[:, 0]
    return np.eye(3) + a[:, None, None] * k + b[:, None, None] * (k @ k)


def solve_static(
    structure: Structure,
    fixed_nodes,
    loads: np.ndarray | None = None,
    *,
    tolerance: float = 1e-6,
    max_iterations: int = 40,
    axis=None,
) -> StaticSolution:
    """Static equilibrium of the corotational structure by a Newton--Krylov method, from its current state.

    ``fixed_nodes`` keep their current positions and rotations (the caller prescribes them with
    :meth:`Structure.set_state`); every other node is free. ``loads``: dead nodal loads (N, 6) [N, N m].
    The residual is the corotational internal force of the Taichi kernels plus the loads, on the free dofs.
    Each Newton step solves J d = r by GMRES (Saad & Schultz 1986) with the Jacobian applied exactly, as the
    directional derivative of the internal forces (a forward difference), preconditioned by the small-strain
    stiffness of :func:`.linear.assemble_stiffness` re-assembled in the elements' current frames and
    factorised (Knoll & Keyes 2004, J. Comput. Phys. 193, 357: Jacobian-free Newton--Krylov). The
    preconditioner alone (a modified Newton) converges slowly where soft modes -- thin spokes twisting --
    meet stress-dependent stiffness it lacks; the Krylov step supplies it. A rotation increment d theta
    updates a node as R <- exp(d theta) R (the spatial spin the element moments are conjugate to); a step that
    would multiply the residual tenfold is halved (backtracking). Converged when the residual is below ``tolerance`` times
    the larger of the loads and the fixed nodes' reactions (round-off in the element forces floors it near
    1e-7 at the smallest loads).

    ``axis``: a unit vector through the origin about which the free part may turn nearly rigidly (a wheel's
    tread about its axle). A linearised rotation u = phi x X stretches what it turns by phi^2 / 2, which on a
    stiff ring is a spurious force far above a soft load; so each free node's turn about ``axis`` (its
    tangential displacement over its distance from the axis) is applied as a finite rotation, and only the
    rest of its step linearly: what stretches then is the turn's gradient, not the turn.
    """
    mesh = structure.mesh
    n = mesh.n_nodes
    fixed = np.zeros(n, bool)
    fixed[np.asarray(fixed_nodes, np.int64)] = True
    free_dofs = (6 * np.flatnonzero(~fixed)[:, None] + np.arange(6)).ravel()
    ext = np.zeros((n, 6)) if loads is None else np.asarray(loads, float).reshape(n, 6)
    axis = None if axis is None else np.asarray(axis, float) / np.linalg.norm(axis)

    def forces(x, rot):
        structure.set_state(positions=x, rotations=rot)
        f, m = structure.internal_forces()
        return np.c_[f, m] + ext

    def moved(x, rot, d):
        return _increment(x, rot, d.reshape(n, 6), np.flatnonzero(~fixed), axis)

    x = structure.positions()
    rot = structure.rotations()
    total = forces(x, rot)
    residual = np.inf
    length = float(np.ptp(mesh.nodes, axis=0).max())
    for it in range(max_iterations + 1):
        r = total.reshape(-1)[free_dofs]
        scale = max(np.linalg.norm(ext), np.linalg.norm(total[fixed]), 1e-300)
        residual = float(np.linalg.norm(r) / scale)
        if residual < tolerance:
            structure.set_state(positions=x, rotations=rot)
            return StaticSolution(True, it, residual)
        if it == max_iterations:
            break
        step = _newton_krylov_step(mesh, x, rot, total, free_dofs, forces, moved, length)
        x, rot, total = _backtrack(x, rot, step, r, free_dofs, n, forces, moved)
    structure.set_state(positions=x, rotations=rot)
    return StaticSolution(False, max_iterations, residual)


def _increment(x: np.ndarray, rot: np.ndarray, d: np.ndarray, free_nodes: np.ndarray, axis) -> tuple:
    """Positions and rotations after the step ``d`` (n, 6): x + d, R <- exp(d theta) R; with ``axis``, each free
    node's turn about it (its tangential displacement over its distance from the axis) applied as a finite rotation
    and only the rest of its step linearly (:func:`solve_static`)."""
    if axis is None:
        return x + d[:, :3], rotation_matrices(d[:, 3:]) @ rot
    p = x[free_nodes]
    perp = p - np.outer(p @ axis, axis)
    r2 = np.maximum(np.sum(perp * perp, axis=1), 1e-300)
    phi = (np.cross(perp, d[free_nodes, :3]) @ axis) / r2
    turn = rotation_matrices(phi[:, None] * axis[None, :])
    rest = d[free_nodes, :3] - phi[:, None] * np.cross(axis, perp)
    x_new, rot_new = x.copy(), rot.copy()
    x_new[free_nodes] = np.einsum("kij,kj->ki", turn, p) + rest
    rot_new[free_nodes] = turn @ rotation_matrices(d[free_nodes, 3:] - phi[:, None] * axis[None, :]) @ rot[free_nodes]
    return x_new, rot_new


def _newton_krylov_step(mesh, x, rot, total, free_dofs, forces, moved, length: float) -> np.ndarray:
    """One Newton step on the free dofs: J d = r by GMRES, J applied as the forward-difference derivative of the
    internal forces, preconditioned by the small-strain stiffness in the current configuration (:func:`solve_static`)."""
    import scipy.sparse.linalg as spla

    from .linear import assemble_stiffness
    from .mesh import StructureMesh

    n = mesh.n_nodes
    current = StructureMesh(x, mesh.triangles, mesh.thickness, mesh.material, beams=mesh.beams,
                            beam_section=mesh.beam_section if len(mesh.beams) else None,
                            beam_orientation=mesh.beam_orientation if len(mesh.beams) else None,
                            drilling_penalty=mesh.drilling_penalty)
    lu = spla.splu(assemble_stiffness(current).tocsr()[free_dofs][:, free_dofs].tocsc())
    base = total.reshape(-1)[free_dofs]

    def jacobian(v):
        norm = np.linalg.norm(v)
        if norm == 0.0:
            return np.zeros_like(v)
        eps = 1e-7 * length / norm
        d = np.zeros(6 * n)
        d[free_dofs] = eps * v
        return -(forces(*moved(x, rot, d)).reshape(-1)[free_dofs] - base) / eps

    size = len(free_dofs)
    op = spla.LinearOperator((size, size), matvec=jacobian)
    pre = spla.LinearOperator((size, size), matvec=lu.solve)
    step, _ = spla.gmres(op, base, M=pre, x0=lu.solve(base), rtol=1e-4, restart=30, maxiter=3)
    return step


def _backtrack(x, rot, step, r, free_dofs, n: int, forces, moved) -> tuple:
    """The state after ``step``, halved (at most eight times) while it multiplies the residual tenfold: Newton from
    far away can overshoot, and a good step may still raise the force residual for a while (stiff membrane forces
    of second order in a soft mode's displacement), so only a tenfold rise counts. Returns (x, rot, forces)."""
    old = np.linalg.norm(r)
    for _ in range(8):
        d = np.zeros(6 * n)
        d[free_dofs] = step
        x_new, rot_new = moved(x, rot, d)
        trial = forces(x_new, rot_new)
        if np.linalg.norm(trial.reshape(-1)[free_dofs]) < 10.0 * old:
            break
        step = 0.5 * step
    return x_new, rot_new, trial
