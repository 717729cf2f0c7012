"""Verification of the corotational shell/beam FEM against closed-form and published answers.

Every reference is analytical (Euler-Bernoulli beam, elastica, thin ring) and every tolerance is
stated next to its assertion.
"""

import numpy as np
import pytest
from scipy.integrate import solve_bvp, trapezoid
from scipy.spatial.transform import Rotation

from wheelsoil.flexwheel.beam_section import rectangular_section
from wheelsoil.flexwheel.linear import assemble_stiffness
from wheelsoil.material import Material
from wheelsoil.flexwheel.mesh import StructureMesh
from wheelsoil.flexwheel.shapes import beam_ring, cylinder_band, strip
from wheelsoil.flexwheel.statics import relax
from wheelsoil.flexwheel.stability import critical_frequency
from wheelsoil.flexwheel.structure import Structure

# Sze, Liu & Lo (2004), Finite Elem. Anal. Des. 40, 1551: cantilever strip, E = 1.2e6, nu = 0, t = 0.1
SZE = Material("Sze et al. strip", youngs_modulus=1.2e6, poisson_ratio=0.0, density=1.0)
B, T = 1.0, 0.1
EI = 1.2e6 * B * T**3 / 12


def clamped_strip(length, n_length, n_width=1):
    nodes, tri = strip(length, B, n_length, n_width)
    mesh = StructureMesh(nodes, tri, T, SZE)
    clamp = np.flatnonzero(nodes[:, 0] < 1e-9)
    tip = np.flatnonzero(nodes[:, 0] > length - 1e-9)
    return mesh, clamp, tip


def tip_weights(tip):
    w = np.ones(len(tip))
    w[[0, -1]] = 0.5  # consistent lumping of an edge load
    return w / w.sum()


def elastica_tip(load_parameter):
    """Tip (u, w)/L of the inextensible cantilever under a fixed vertical tip load, PL^2/EI given.

    EI theta'' = -P cos(theta), theta(0) = 0, theta'(L) = 0 (Euler's elastica), solved to 1e-10.
    """
    s = np.linspace(0.0, 1.0, 401)

    def rhs(_, y):
        return np.vstack([y[1], -load_parameter * np.cos(y[0])])

    sol = solve_bvp(rhs, lambda a, b: np.array([a[0], b[1]]), s, np.zeros((2, s.size)), tol=1e-10)
    theta = sol.sol(s)[0]
    return trapezoid(np.cos(theta), s) - 1.0, trapezoid(np.sin(theta), s)


def test_small_tip_load_matches_euler_bernoulli_for_shell_and_beam():
    # shell strip: delta = P L^3 / (3 EI); the DKT strip is within 0.1 %
    mesh, clamp, tip = clamped_strip(10.0, 16)
    s = Structure(mesh, hub_nodes=clamp)
    p = 1e-3
    f = np.zeros((mesh.n_nodes, 3))
    f[tip, 2] = p * tip_weights(tip)
    s.set_external(f)
    assert relax(s, tolerance=1e-6).converged
    exact = p * 10.0**3 / (3 * EI)
    assert s.positions()[tip, 2].mean() == pytest.approx(exact, rel=1e-3)
    # beam: Euler-Bernoulli elements are exact at the nodes; 1e-4 is the relaxation tolerance
    x = np.linspace(0, 10.0, 9)
    beams = np.c_[np.arange(8), np.arange(1, 9)]
    bmesh = StructureMesh(np.c_[x, 0 * x, 0 * x], None, 1.0, SZE, beams=beams,
                          beam_section=np.array(rectangular_section(B, T)), beam_orientation=[0, 1, 0])
    s = Structure(bmesh, hub_nodes=[0])
    f = np.zeros((9, 3))
    f[-1, 2] = p
    s.set_external(f)
    assert relax(s, tolerance=1e-7).converged
    assert s.positions()[-1, 2] == pytest.approx(exact, rel=1e-4)


@pytest.mark.parametrize("load_parameter", [1.0, 4.0])
def test_sze_cantilever_under_end_shear_matches_the_elastica(load_parameter):
    """Sze, Liu & Lo (2004) problem 1 (L = 10, b = 1, t = 0.1, E = 1.2e6, nu = 0, P_max = 4, so
    PL^2/EI = P); their S4R reference solution is the elastica of this strip. 16 x 1 facets reach the
    elastica's tip displacements within 0.3 % of L."""
    length = 10.0
    mesh, clamp, tip = clamped_strip(length, 16)
    s = Structure(mesh, hub_nodes=clamp)
    f = np.zeros((mesh.n_nodes, 3))
    f[tip, 2] = load_parameter * EI / length**2 * tip_weights(tip)
    s.set_external(f)
    result = relax(s, tolerance=1e-6, max_steps=400_000)
    assert result.converged, result
    u_ref, w_ref = elastica_tip(load_parameter)
    tip_pos = s.positions()[tip].mean(axis=0)
    assert (tip_pos[0] - length) / length == pytest.approx(u_ref, abs=3e-3)
    assert tip_pos[2] / length == pytest.approx(w_ref, abs=3e-3)


def test_cantilever_rolled_up_by_an_end_moment_forms_a_circle():
    """M = 2 pi EI / L bends the strip into a full circle: tip back at the clamp, every node on the
    circle of radius EI/M. Checked at half the moment (a semicircle) and the full moment, to 0.5 % of L."""
    length = 12.0
    mesh, clamp, tip = clamped_strip(length, 16)
    s = Structure(mesh, hub_nodes=clamp)
    moment = np.zeros((mesh.n_nodes, 3))
    for fraction in (0.25, 0.5, 0.75, 1.0):
        m = fraction * 2 * np.pi * EI / length
        moment[tip, 1] = -m * tip_weights(tip)
        s.set_external(None, moment)
        assert relax(s, tolerance=2e-5, max_steps=400_000).converged
        kappa = m / EI
        x = s.positions()
        s_arc = mesh.nodes[:, 0]
        exact = np.c_[np.sin(kappa * s_arc) / kappa, (1 - np.cos(kappa * s_arc)) / kappa]
        if fraction in (0.5, 1.0):
            err = np.abs(x[:, [0, 2]] - exact).max()
            assert err < 5e-3 * length, (fraction, err)


@pytest.mark.parametrize("model", ["beam", "shell"])
def test_pinched_ring_converges_to_the_thin_ring_answer(model):
    """Thin ring pinched by two opposite loads P: the loaded diameter shortens by
    (pi/4 - 2/pi) P R^3 / (E I) (Timoshenko, Strength of Materials I, sec. 83). The error must fall
    with refinement and be below 1 % on the finest mesh."""
    radius, p = 1.0, 1e-3
    exact = (np.pi / 4 - 2 / np.pi) * p * radius**3 / EI
    errors = []
    for n in (16, 32, 64):
        if model == "beam":
            nodes, beams = beam_ring(radius, n)
            mesh = StructureMesh(nodes, None, 1.0, SZE, beams=beams, beam_section=np.array(rectangular_section(B, T)),
                                 beam_orientation=[0, 1, 0])
        else:
            nodes, tri = cylinder_band(radius, B, n, 1)
            mesh = StructureMesh(nodes, tri, T, SZE)
        top = np.flatnonzero(np.abs(nodes[:, 2] - radius) < 1e-9)
        bottom = np.flatnonzero(np.abs(nodes[:, 2] + radius) < 1e-9)
        s = Structure(mesh)
        f = np.zeros((mesh.n_nodes, 3))
        f[top, 2] = -p / len(top)
        f[bottom, 2] = p / len(bottom)
        s.set_external(f)
        assert relax(s, tolerance=1e-6, max_steps=400_000).converged
        x = s.positions()
        shortening = 2 * radius - (x[top, 2].mean() - x[bottom, 2].mean())
        errors.append(abs(shortening / exact - 1))
    assert errors[0] > errors[1] > errors[2], errors
    assert errors[2] < 0.01, errors


def _bent_strip_state():
    mesh, clamp, tip = clamped_strip(10.0, 8)
    s = Structure(mesh)
    rng = np.random.default_rng(3)
    x = mesh.nodes + 0.05 * rng.standard_normal(mesh.nodes.shape)
    rot = Rotation.from_rotvec(0.1 * rng.standard_normal((mesh.n_nodes, 3))).as_matrix()
    return s, x, rot


def test_rigid_rotation_produces_no_internal_force_and_rotates_the_deformed_forces():
    """Objectivity: rotating the undeformed mesh rigidly gives zero internal force (to round-off); a
    rigid rotation Q of a deformed state gives forces Q f and the same strain energy."""
    s, x, rot = _bent_strip_state()
    q = Rotation.from_rotvec([0.7, -1.9, 2.4]).as_matrix()  # a rotation of 3.1 rad
    shift = np.array([3.0, -2.0, 5.0])
    s.set_state(positions=s.mesh.nodes @ q.T + shift, rotations=np.broadcast_to(q, (s.mesh.n_nodes, 3, 3)))
    f0, m0 = s.internal_forces()
    s.set_state(positions=x, rotations=rot)
    f1, m1 = s.internal_forces()
    e1 = s.strain_energy()
    scale = np.abs(f1).max()
    assert np.abs(f0).max() < 1e-9 * scale and np.abs(m0).max() < 1e-9 * np.abs(m1).max()
    s.set_state(positions=x @ q.T + shift, rotations=np.einsum("ij,njk->nik", q, rot))
    f2, m2 = s.internal_forces()
    assert np.allclose(f2, f1 @ q.T, atol=1e-9 * scale)
    assert np.allclose(m2, m1 @ q.T, atol=1e-9 * np.abs(m1).max())
    assert s.strain_energy() == pytest.approx(e1, rel=1e-10)
    # element forces are self-equilibrated in the current configuration (momentum conservation)
    assert np.abs(f1.sum(axis=0)).max() < 1e-10 * scale
    moment = np.cross(x, f1).sum(axis=0) + m1.sum(axis=0)
    assert np.abs(moment).max() < 1e-9 * scale * 10.0


def test_internal_forces_are_the_gradient_of_the_strain_energy_and_match_the_assembled_stiffness():
    """The corotational forces are -dU/dx (checked by central differences at a deformed state), and
    their tangent at the reference state is the assembled linear stiffness of linear.py."""
    s, x, rot = _bent_strip_state()
    s.set_state(positions=x, rotations=rot)
    f, _ = s.internal_forces()
    eps = 1e-6
    for node, k in ((3, 2), (7, 0), (12, 1)):
        xp, xm = x.copy(), x.copy()
        xp[node, k] += eps
        xm[node, k] -= eps
        s.set_state(positions=xp)
        up = s.strain_energy()
        s.set_state(positions=xm)
        um = s.strain_energy()
        assert -(up - um) / (2 * eps) == pytest.approx(f[node, k], rel=1e-5, abs=1e-9 * np.abs(f).max())
    # tangent at the reference vs the assembled stiffness
    mesh = s.mesh
    k_lin = assemble_stiffness(mesh).toarray()
    s.set_state(positions=mesh.nodes, rotations=np.broadcast_to(np.eye(3), (mesh.n_nodes, 3, 3)))
    n = mesh.n_nodes
    for node, k in ((5, 2), (9, 0), (4, 4)):  # dof index within the node's 6
        cols = []
        for sign in (1, -1):
            if k < 3:
                xp = mesh.nodes.copy()
                xp[node, k] += sign * eps
                s.set_state(positions=xp)
            else:
                r = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
                r[node] = Rotation.from_rotvec(sign * eps * np.eye(3)[k - 3]).as_matrix()
                s.set_state(positions=mesh.nodes, rotations=r)
            ff, mm = s.internal_forces()
            cols.append(np.c_[ff, mm].reshape(-1))
            s.set_state(positions=mesh.nodes, rotations=np.broadcast_to(np.eye(3), (n, 3, 3)))
        tangent = -(cols[0] - cols[1]) / (2 * eps)
        assert np.allclose(tangent, k_lin[:, 6 * node + k], atol=1e-6 * np.abs(k_lin).max())


def test_packed_stiffness_blocks_multiply_like_the_full_ones():
    """The element loop reads each facet's stiffness packed (symmetric membrane block: upper triangle; bending
    block: only what multiplies the in-plane rotations). Its products equal the full 9x9 products of
    shell_setup for every facet of a bent strip, and a block that is not symmetric is refused."""
    import taichi as ti

    from wheelsoil.flexwheel.shell import _bending_times, _membrane_times, pack_stiffness, shell_setup
    from wheelsoil.taichi_types import nd_f64_2d, to_ndarray, vec9

    s, _, _ = _bent_strip_state()
    mesh = s.mesh
    _, _, km, kb = shell_setup(mesh.nodes, mesh.triangles, mesh.thickness, mesh.material, mesh.drilling_penalty)
    km_p, kb_p = pack_stiffness(km, kb)
    rng = np.random.default_rng(0)
    dm = rng.normal(size=(len(km), 9))
    db = rng.normal(size=(len(kb), 9))
    db[:, [0, 3, 6]] = 0.0  # a flat facet's nodes have no normal deformational translation

    @ti.kernel
    def products(km: nd_f64_2d, kb: nd_f64_2d, dm: nd_f64_2d, db: nd_f64_2d, fm: nd_f64_2d, fb: nd_f64_2d):
        for e in range(km.shape[0]):
            a = vec9(0.0)
            b = vec9(0.0)
            for i in ti.static(range(9)):
                a[i] = dm[e, i]
                b[i] = db[e, i]
            fa = _membrane_times(km, e, a)
            fbe = _bending_times(kb, e, b)
            for i in ti.static(range(9)):
                fm[e, i] = fa[i]
                fb[e, i] = fbe[i]

    fm, fb = to_ndarray(ti.f64, np.zeros_like(dm)), to_ndarray(ti.f64, np.zeros_like(db))
    products(to_ndarray(ti.f64, km_p), to_ndarray(ti.f64, kb_p), to_ndarray(ti.f64, dm), to_ndarray(ti.f64, db),
             fm, fb)
    scale_m, scale_b = np.abs(km).max(), np.abs(kb).max()
    assert np.allclose(fm.to_numpy(), np.einsum("eij,ej->ei", km, dm), rtol=0, atol=1e-12 * scale_m)
    assert np.allclose(fb.to_numpy(), np.einsum("eij,ej->ei", kb, db), rtol=0, atol=1e-12 * scale_b)
    lopsided = km.copy()
    lopsided[0, 0, 1] += 1e-3 * scale_m
    with pytest.raises(ValueError, match="membrane stiffness blocks are not symmetric"):
        pack_stiffness(lopsided, kb)


def test_undamped_free_vibration_conserves_energy_and_momentum():
    """A free strip set spinning and vibrating: total energy constant within 0.5 % over several
    vibration periods (central difference: bounded, O(dt^2) fluctuation); linear momentum exact."""
    nodes, tri = strip(1.0, 0.2, 10, 2)
    mesh = StructureMesh(nodes, tri, 0.01, Material("steel", 2e11, 0.3, 7850.0))
    s = Structure(mesh)
    spin = np.array([0.0, 0.0, 30.0])
    v = np.cross(spin, nodes - nodes.mean(axis=0))
    v[:, 2] += 2.0 * np.sin(np.pi * nodes[:, 0])  # first bending shape
    s.set_state(velocities=v, angular_velocities=np.broadcast_to(spin, (mesh.n_nodes, 3)))
    e0 = s.kinetic_energy() + s.strain_energy()
    p0 = (s.mass[:, None] * s.velocities()).sum(axis=0)
    energies = []
    for _ in range(40):
        s.step(250)
        energies.append(s.kinetic_energy() + s.strain_energy())
    assert s.time > 0.05  # several periods of the first free-free mode (~ 50 Hz)
    assert max(abs(np.array(energies) / e0 - 1)) < 5e-3
    p1 = (s.mass[:, None] * s.velocities()).sum(axis=0)
    assert np.allclose(p1, p0, atol=1e-9 * np.abs(p0).max() + 1e-12)


def test_time_step_convergence_of_a_vibrating_cantilever():
    """A cantilever released from its undeformed shape with a velocity field (no load, so the
    half-step start of the velocities is exact): halving dt cuts the change of the tip position by
    about 4 (central difference is 2nd order); required: at least 3."""
    mesh, clamp, tip = clamped_strip(10.0, 8)
    results = []
    # steps as fractions of the element bound (Irons), well inside the asymptotic range of the integrator
    bound = 2.0 / float(critical_frequency(mesh).max())
    for fraction in (0.8, 0.4, 0.2):
        s = Structure(mesh, hub_nodes=clamp)
        v = np.zeros((mesh.n_nodes, 3))
        v[:, 2] = 0.01 * (mesh.nodes[:, 0] / 10.0) ** 2
        s.set_state(velocities=v)
        n = int(round(2.0 / (fraction * bound)))
        s.step(n, 2.0 / n)
        results.append(s.positions()[tip, 2].mean())
    d1, d2 = abs(results[0] - results[1]), abs(results[1] - results[2])
    assert d2 < d1 / 3, (results, d1, d2)


def test_assembled_critical_step_is_the_stability_limit():
    """The structure's critical step is the assembled system's 2 / omega_max (Lanczos): central differences
    from a state that excites every mode stay bounded at 0.98 of it and blow up at 1.03 of it; the element
    bound (Irons) lies below it."""
    from wheelsoil.flexwheel import stepper
    from wheelsoil.flexwheel.stability import assembled_critical_frequency

    mesh, _, _ = clamped_strip(1.0, 8)
    omega = assembled_critical_frequency(mesh)
    assert omega < float(critical_frequency(mesh).max())
    rng = np.random.default_rng(3)
    v0 = rng.normal(0.0, 1e-3, (mesh.n_nodes, 3))
    w0 = rng.normal(0.0, 1e-3, (mesh.n_nodes, 3))
    growth = {}
    for fraction in (0.98, 1.03):
        s = Structure(mesh)  # no hub: every node free, as the frequency was computed
        assert s.critical_time_step == pytest.approx(2.0 / omega, rel=1e-12)
        s.set_state(velocities=v0, angular_velocities=w0)
        e0 = s.kinetic_energy()
        # the kernels directly: Structure.step refuses a step above the limit
        stepper.steps_serial(4000, fraction * 2.0 / omega, 0.0, 0.0, 0.0, 0.0, 0, mesh.n_nodes, len(mesh.triangles),
                             len(mesh.beams), 0, *s.arrays.kernel_args)
        growth[fraction] = s.kinetic_energy() / e0
    assert growth[0.98] < 10.0
    assert not growth[1.03] < 1e6
