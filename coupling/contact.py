"""The DE--FE contact interface: Hertz--Mindlin contact between spheres and the wheel's surface facets.

:class:`WheelContact` is a :class:`wheelsoil.granular.Interaction`: added to a
:class:`~wheelsoil.granular.Scene`, it advances the wheel structure over each DEM step in the
structure's own stable sub-steps, then adds the wheel's contact forces to the spheres and hands the
reactions to the FE nodes for the next step. That is the coupled stepper (seed 004 sec. 2.3, Fig. 3:
the FE side advances over a DEM step with the loads of the last exchange, the DEM side evaluates the
contacts against the wheel at its new position).

Contact model, per physical contact between sphere *i* (centre p, radius r) and a facet of
half thickness h (the contact surface lies h either side of the facet's mid-surface):

* closest point c of the mid-surface triangle to p and its Voronoi region -- face, edge or vertex
  (:mod:`.closest_point`);
* normal n from the sphere towards the wheel: the facet normal for a face contact, (c - p)/|c - p|
  for an edge or vertex; overlap delta = r + h - |p - c|; a face contact keeps the side of the shell
  it began on (recorded in its history), so a sphere pressed hard never passes through the thin shell;
* where facets share an edge or vertex, a contact is counted once: face contacts always count, an
  edge contact only if no facet containing that edge has a face contact and no other facet already
  gave it, a vertex contact only if no face or edge contact involves that vertex (the rule of
  Kremmer & Favier 2001 and of LIGGGHTS' mesh walls);
* force: the Hertz--Mindlin law of :func:`wheelsoil.granular.contact.hertz_mindlin` (seed 004
  eqs. 3--13) with a flat partner (R* = r); the effective mass of eq. 13 pairs the sphere with the
  wheel's apparent mass at the contact point, 1/m_c = sum_k b_k^2 / m_k over the facet's nodes (b_k the
  barycentric weights, m_k the lumped masses; nodes tied to the hub, and a rigid wheel, count as
  immovable); the sphere's own inertia enters the rolling-torque limiter;
  E*, G* of the soil and the wheel material (eqs. 10, 12) and the soil--steel restitution and
  friction of Table 1; the partner's velocity and spin at c are the barycentric interpolation of the
  facet's nodes;
* tangential history per physical contact (up to ``HISTORY_SLOTS`` per sphere), matched from step to
  step by its normal;
* transfer: the facet's nodes receive -F with the barycentric weights of c, plus the moment
  M = -M_roll - (p + r n - c) x F as nodal forces that sum to zero (f_k = lam x s_k with s_k the corner
  positions about the facet centroid and sum_k s_k x (lam x s_k) = M), so force *and* angular momentum
  balance exactly between particles and wheel (action = reaction to round-off). No nodal moments
  are applied: a shell node's small rotary inertia would make them stiff;
* the wheel advances over a DEM step with the forces of the last evaluation, each node's force
  linearised with the contacts' lumped normal stiffness, f - k (x - x_a), about x_a, the node's position carried
  ahead at its velocity to the mean of the sub-steps' positions (:func:`.kernels.node_load`): holding the force
  constant instead lets light nodes (a coarse grouser's tip) that several loaded spheres press on run unstable at
  the DEM step, and linearising about the evaluated position itself gives a node moving into the soil more than f
  on average, so the wheel did not carry the force the soil reported (issue 35);
* candidates: the spheres within reach of each facet plus a margin for the spheres' motion (:data:`SPHERE_SKINS` of
  the scene's skin) and the wheel's (``wheel_skin``), built only in a step in which the scene rebuilt its neighbour
  lists: when they need rebuilding for any other reason (the wheel has moved ``wheel_skin``, a restore, new spheres),
  they are rebuilt at once and the scene is asked to rebuild at the next step
  (:meth:`~wheelsoil.granular.Scene.request_neighbor_rebuild`), where they follow. So a sphere has moved from where
  the candidates saw it no more than since the scene's last rebuild, and each build bounds that motion sphere by
  sphere: its allowance becomes at most its gap to every facet it does not list less the wheel's own skin
  (:func:`.candidate_kernels.count_candidates`, :meth:`~wheelsoil.granular.Scene.limit_allowances`). Near the wheel
  that is the candidates' margin for the spheres' motion (``sphere_skins``); a grain thrown clear of the wheel keeps
  the larger allowance its own clearance gives it, up to :data:`CLEARANCE_CELLS` cells more.
"""

from __future__ import annotations

import math

import numpy as np
import taichi as ti

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.flexwheel.structure import Structure
from wheelsoil.granular.materials import (
    SOIL_STEEL,
    Material,
    PairProperties,
    effective_modulus,
    effective_shear_modulus,
)
from wheelsoil.granular.contact import ROLLING_MODELS
from wheelsoil.granular.scene import Interaction, Scene
from wheelsoil.granular.neighbors import exclusive_scan
from wheelsoil.taichi_types import vec3

from . import candidate_kernels as ck
from . import kernels as k
from .node_speed import require_node_speed, shortest_edge
from .surface import ContactSurface
from .surface_arrays import SurfaceArrays

#: Physical contacts per sphere whose tangential history is kept (a sphere touches the wheel at one
#: or two places in practice: a face, or the corner between the tread and a grouser).
HISTORY_SLOTS = 4
#: The per-particle contact history arrays: contact normals, tangential displacements [m], rolling spring torques
#: [N m] (EPSD pairs; zero under CDT) and the number of slots in use.
HISTORY_KEYS = ("hist_n", "hist_xi", "hist_roll", "hist_count")


def anchor_lead(interval: float, substeps: int) -> float:
    """How far ahead [s], at its present velocity, a node's linearised contact force is anchored: Delta t (n - 1) /
    (2 n), the mean time of the n sub-steps' force evaluations over the interval Delta t (each evaluates before it
    moves the node). A node moving steadily then receives exactly the evaluated force on average
    (:func:`.kernels.node_load`)."""
    return interval * (substeps - 1) / (2 * substeps)


def _grown(arrays: dict, name: str, dtype, size: int, shape_tail: tuple = ()):
    """``arrays[name]``, a scratch ndarray of at least ``size`` rows (replaced by one 25 % larger when too small)."""
    arr = arrays.get(name)
    if arr is None or arr.shape[0] < size:
        rows = max(16, int(size * 1.25) + 16)
        if dtype is vec3:
            arr = ti.Vector.ndarray(3, ti.f64, shape=(rows,) + shape_tail)
        else:
            arr = ti.ndarray(dtype, shape=(rows,) + shape_tail)
        arrays[name] = arr
    return arr


#: The candidates' margin for the spheres' motion between two rebuilds, in the scene's skins: the least allowance the
#: wheel leaves a sphere near it (a sphere clear of its neighbours may otherwise move up to half its clearance;
#: :func:`wheelsoil.granular.neighbors.displacement_allowance`). Four skins: a grain thrown up along the wheel's face
#: lists the facets a few millimetres off it, so it is not held to a rebuild every few dozen steps; at the rig's
#: scale 22 rebuilds in 1,200 steps against 43 at two skins, for the same contact cost (benchmarks/README.md).
SPHERE_SKINS = 4.0
#: How far beyond the candidates' reach, in grid cells, a sphere's cell is checked for facets at all
#: (:func:`.candidate_kernels.mark_near_cells`): a sphere in a cell with none within that reach may move that much
#: further before the scene rebuilds, so that the wheel does not hold back a grain it has thrown clear.
CLEARANCE_CELLS = 2


def _check_options(structure, pair, wheel_skin, sphere_skins) -> None:
    """:class:`WheelContact`'s arguments, refused with the offending one named."""
    for key, value in (("wheel_skin", wheel_skin), ("sphere_skins", sphere_skins)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise WheelsoilInputError(f"{key} = {value!r} must be a finite number > 0")
    if not isinstance(structure, Structure):
        raise WheelsoilInputError(f"structure must be a flexwheel Structure, got {type(structure).__name__}")
    if not isinstance(pair, PairProperties):
        raise WheelsoilInputError(f"pair must be a PairProperties, got {type(pair).__name__}")


def _evaluation_arrays(ds, w, a: dict, d: SurfaceArrays, resultant) -> tuple[tuple, tuple, tuple]:
    """The array arguments of :func:`.kernels.wheel_contacts` in its order, in three runs around its two scalars
    (the active count, the culling's facet count): the scene's particle arrays ``ds``, the candidate arrays ``a``
    with the wheel's device arrays ``w`` and the surface's ``d``, and the rest to the ``resultant``."""
    return (
        (ds.x, ds.v, ds.w, ds.radius, ds.mass, ds.inertia, ds.external_force, ds.external_torque),
        (a["active"], a["start"], a["cand"], a["code"], a["keep"], a["bary"], a["normal"], a["overlap"],
         a["f_wheel"], a["m_wheel"], a["xi_new"], a["roll_new"], a["stiffness"], a["hist_n"], a["hist_xi"],
         a["hist_roll"], a["hist_count"],
         w.x, w.v, w.w, d.inverse_mass, d.triangles, d.edges, d.half_thickness),
        (d.facet_plane, d.facet_ball,
         d.nodes, d.corner_start, d.corners, d.facet_start, a["facet_entries"],
         w.f_ext, w.k_ext, w.x_anchor, d.node_reference, w.hub, resultant),
    )


class WheelContact(Interaction):
    """Contact between the spheres of a scene and the surface facets of a wheel structure.

    Parameters
    ----------
    structure: the wheel (flexible or ``rigid=True``), advanced by this interface every DEM step.
    soil: the particles' material (E, nu) for the effective moduli.
    pair: soil--wheel restitution, static and rolling friction (default: seed 004 Table 1 soil--steel).
    advance_structure: advance the structure over each DEM step (``False``: held where it is, e.g. a frozen wheel).
    health_every: steps between the structure's health checks.
    wheel_skin, sphere_skins: how far [m] the wheel's surface may move before the candidate lists are rebuilt (default:
        four times the scene's skin), and the candidates' margin for the spheres' motion, in scene skins (default
        :data:`SPHERE_SKINS`); module docstring, *candidates* (a change takes effect at the scene's next rebuild).
    """

    def __init__(
        self,
        structure: Structure,
        soil: Material,
        pair: PairProperties = SOIL_STEEL,
        *,
        advance_structure: bool = True,
        health_every: int = 200,
        wheel_skin: float | None = None,
        sphere_skins: float = SPHERE_SKINS,
    ) -> None:
        _check_options(structure, pair, wheel_skin, sphere_skins)
        self._wheel_skin_request = wheel_skin
        self.sphere_skins = float(sphere_skins)
        self.structure = structure
        self.surface = ContactSurface.from_mesh(structure.mesh)
        #: the shortest edge of the contact facets [m] (the reference of the nodes' speed limit)
        self.shortest_edge = shortest_edge(self.surface.triangles, structure.mesh.nodes)
        wheel = structure.mesh.material
        self.soil, self.pair = soil, pair
        self.e_eff = effective_modulus(soil, wheel)
        self.g_eff = effective_shear_modulus(soil, wheel)
        self.contact_moduli = (self.e_eff,)
        self.advance_structure = bool(advance_structure)
        #: set aside candidates their facet's bounds prove apart (:func:`.kernels.surely_apart`; the same results)
        self.cull_far_candidates = True
        self.health_every = max(1, int(health_every))
        self.rebuilds = 0
        self.structure_substeps = 0
        self._last_substeps = 1  # sub-steps of the structure's last advance (the next one's, as it stays put)
        self._steps = 0
        self._n_contacts = self._n_candidates = 0
        sf = self.surface
        self._surface_arrays = SurfaceArrays.upload(sf, structure)
        self._resultant = ti.Vector.ndarray(3, ti.f64, shape=5)
        self._resultant.fill(0.0)
        self._stats = ti.ndarray(ti.f64, shape=3)
        self._contact_arrays = None  # the contact kernel's array arguments (gathered after each rebuild)
        self._arrays: dict = {}
        self._scene_key = None
        self._need_rebuild = True
        self._seen_rebuilds = -1

    # ------------------------------------------------------------------ buffers
    def _buffer(self, name: str, dtype, size: int, *, shape_tail: tuple = ()):
        """A scratch ndarray of at least ``size`` rows (:func:`_grown`)."""
        return _grown(self._arrays, name, dtype, size, shape_tail)

    def _attach(self, scene: Scene) -> None:
        """(Re)allocate the per-particle arrays and the facet grid for ``scene``'s particles."""
        n = scene.n_particles
        radii = scene.radii
        self.wheel_skin = self._wheel_skin_request or 4.0 * scene.skin
        self.r_max = float(radii.max())
        a = self._arrays
        a.clear()
        for name, rows in (("count", n), ("start", n + 1), ("active", n), ("hist_count", n)):
            a[name] = ti.ndarray(ti.i32, shape=rows)
        for name in ("hist_n", "hist_xi", "hist_roll"):
            a[name] = ti.Vector.ndarray(3, ti.f64, shape=(n, HISTORY_SLOTS))
        a["hist_count"].fill(0)
        a["wheel_gap"] = ti.ndarray(ti.f64, shape=n)
        self._scene_key = (id(scene), n)
        self._n_active = 0
        self._need_rebuild = True

    def _rebuild(self, scene: Scene) -> None:
        ds = self._scene_state = scene.device_state()
        self._contact_arrays = None
        w = self.structure.device_arrays()
        a, d = self._arrays, self._surface_arrays
        sf = self.surface
        # the soil's own grid (:meth:`Scene.grid`): a facet is binned into every cell its box grown by r_max + skin
        # meets, and a sphere reads only its cell, so any cell edge works
        grid = scene.grid
        self.skin = self.sphere_skins * scene.skin + self.wheel_skin  # candidate margin
        if "cell_count" not in a or a["cell_count"].shape[0] != grid.n_cells:
            a["cell_count"] = ti.ndarray(ti.i32, shape=grid.n_cells)
            a["cell_start"] = ti.ndarray(ti.i32, shape=grid.n_cells + 1)
            a["near"] = ti.ndarray(ti.i32, shape=grid.n_cells)
        origin, inv_cell, dims = grid.kernel_args()
        pad = self.r_max + self.skin
        far_pad = pad + CLEARANCE_CELLS * grid.cell
        ck.mark_near_cells(w.x, d.triangles, d.half_thickness, sf.n_facets, far_pad, origin, inv_cell, dims, a["near"])
        ck.facet_cell_ranges(w.x, d.triangles, d.half_thickness, sf.n_facets, pad, origin, inv_cell, dims,
                            d.facet_lo, d.facet_hi, a["cell_count"])
        total = exclusive_scan(a["cell_count"], a["cell_start"])
        cell_fill = self._buffer("cell_fill", ti.i32, a["cell_count"].shape[0])
        cell_facets = self._buffer("cell_facets", ti.i32, max(total, 1))
        ck.fill_facet_cells(sf.n_facets, dims, d.facet_lo, d.facet_hi, a["cell_start"], cell_fill, cell_facets)
        ck.count_candidates(ds.x, ds.radius, self.skin, pad, far_pad, origin, inv_cell, dims, a["cell_start"],
                           cell_facets, a["near"], w.x, d.triangles, d.half_thickness, a["count"], a["hist_count"],
                           a["wheel_gap"])
        scene.limit_allowances(a["wheel_gap"], self.wheel_skin)
        n_cand = exclusive_scan(a["count"], a["start"])
        self._n_candidates = n_cand
        cand = self._buffer("cand", ti.i32, max(n_cand, 1))
        ck.fill_candidates(ds.x, ds.radius, self.skin, origin, inv_cell, dims, a["cell_start"], cell_facets,
                          w.x, d.triangles, d.half_thickness, a["start"], cand)
        facet_entries = self._buffer("facet_entries", ti.i32, max(n_cand, 1))
        self._n_active = ck.index_active(a["count"], a["start"], a["active"], sf.n_facets, cand, d.facet_start,
                                        d.facet_fill, facet_entries)
        for name, dtype in (("code", ti.i32), ("keep", ti.i32), ("overlap", ti.f64), ("stiffness", ti.f64), ("normal", vec3),
                            ("f_wheel", vec3), ("m_wheel", vec3), ("xi_new", vec3), ("roll_new", vec3)):
            self._buffer(name, dtype, max(n_cand, 1))
        self._buffer("bary", ti.f64, max(n_cand, 1), shape_tail=(3,))
        self._arrays["keep"].fill(0)
        ck.copy_node_positions(w.x, d.nodes, d.node_reference)
        self._seen_rebuilds = scene.neighbor_rebuilds
        self._need_rebuild = False
        self.rebuilds += 1

    # ------------------------------------------------------------------ Interaction protocol
    def after_drift(self, scene: Scene, dt: float) -> None:
        """Advance the wheel over [t, t + dt] with the loads of the last contact evaluation."""
        if self.advance_structure:
            self._steps += 1
            self._last_substeps = self.structure.advance(dt, check=False)
            self.structure_substeps += self._last_substeps
            if self._steps % self.health_every == 0:  # one read of the nodes' speeds serves both checks
                require_node_speed(self.structure.check_health(), self.shortest_edge, dt, self._last_substeps,
                                   self.structure.time)

    def add_forces(self, scene: Scene, dt: float) -> int:
        """Evaluate every sphere--wheel contact at the current positions (see the module docstring)."""
        if self._scene_key != (id(scene), scene.n_particles):
            self._attach(scene)
        scene_rebuilt = scene.neighbor_rebuilds != self._seen_rebuilds
        if self._need_rebuild or scene_rebuilt:
            self._rebuild(scene)
            if not scene_rebuilt:  # built off the scene's Verlet reference: both again at the next step
                scene.request_neighbor_rebuild()
        self._launch_contacts(dt)
        # two scalar reads (~25 us) rather than to_numpy (~100 us: a copy kernel and an array)
        self._n_contacts = int(self._stats[1])
        # rebuild before the wheel's surface has moved its skin (less a margin for one more step)
        if self._stats[0] > (0.8 * self.wheel_skin) ** 2:
            scene.request_neighbor_rebuild()
        return self._n_contacts

    def _launch_contacts(self, dt: float) -> None:
        """One evaluation of every contact (:func:`.kernels.wheel_contacts`, as a compute graph); its array
        arguments are gathered once per candidate rebuild."""
        if self._contact_arrays is None:
            self._contact_arrays = _evaluation_arrays(self._scene_state, self.structure.device_arrays(), self._arrays,
                                                      self._surface_arrays, self._resultant)
        particles, entries, rest = self._contact_arrays
        n_cull = self.surface.n_facets if self.cull_far_candidates else 0
        k.wheel_contacts_graph(
            *particles, self._n_active, *entries, n_cull, *rest,
            self.e_eff, self.g_eff, self.pair.damping_ratio, self.pair.static_friction, self.pair.rolling_friction,
            ROLLING_MODELS[self.pair.rolling_model], dt, anchor_lead(dt, self._last_substeps), self._stats,
        )

    # ------------------------------------------------------------------ measured quantities
    @property
    def candidates_set_aside(self) -> int:
        """Candidates the last evaluation set aside by their facets' bounds (``cull_far_candidates``; a scalar read)."""
        return int(self._stats[2])

    @property
    def candidate_count(self) -> int:
        """Candidate (sphere, facet) pairs held since the last candidate rebuild."""
        return int(self._n_candidates)

    @property
    def contact_count(self) -> int:
        """Physical sphere--wheel contacts at the last evaluation."""
        return int(self._n_contacts)

    def resultant(self) -> tuple[np.ndarray, np.ndarray]:
        """Force [N] of the soil on the wheel and its moment [N m] about the hub centre, last evaluation."""
        r = self._resultant.to_numpy()
        return r[k.RES_FORCE].copy(), r[k.RES_MOMENT].copy()

    def mean_resultant(self, reset: bool = True) -> tuple[np.ndarray, np.ndarray, int]:
        """Force and moment of :meth:`resultant` averaged over every evaluation since the last reset,
        and the number of evaluations."""
        r = self._resultant.to_numpy()
        samples = int(round(r[k.RES_SAMPLES][0]))
        scale = 1.0 / max(samples, 1)
        out = r[k.RES_FORCE_SUM] * scale, r[k.RES_MOMENT_SUM] * scale, samples
        if reset:
            r[k.RES_FORCE_SUM:] = 0.0
            self._resultant.from_numpy(r)
        return out

    # ------------------------------------------------------------------ checkpoints
    _STATE_SCALARS = ("rebuilds", "structure_substeps", "_steps", "_n_contacts", "_last_substeps")

    def state(self) -> dict:
        """Per-particle contact history, the force accumulators and counters (for checkpoints)."""
        out = {key: getattr(self, key) for key in self._STATE_SCALARS}
        out["resultant"] = self._resultant.to_numpy()
        if self._arrays:
            for key in HISTORY_KEYS:
                out[key] = self._arrays[key].to_numpy()
        return out

    def renumber(self, scene: Scene, old_of_new: np.ndarray) -> None:
        """The scene's spheres were renumbered (sphere k is the former ``old_of_new[k]``, -1 for a new one):
        carry each sphere's contact history to its new index (called by the scene)."""
        if not self._arrays or self._scene_key is None:
            return
        old = {key: self._arrays[key].to_numpy() for key in HISTORY_KEYS}
        self._attach(scene)
        keep = old_of_new >= 0
        for key, values in old.items():
            new = np.zeros((len(old_of_new),) + values.shape[1:], values.dtype)
            new[keep] = values[old_of_new[keep]]
            self._arrays[key].from_numpy(np.ascontiguousarray(new))

    def invalidate(self) -> None:
        """Rebuild the candidate lists at the next evaluation (after the scene's arrays were reset)."""
        self._need_rebuild = True

    def restore_state(self, scene: Scene, state: dict) -> None:
        """Continue from a :meth:`state` taken with the same wheel on ``scene``'s particles."""
        # a checkpoint from before the sub-step count was kept: 1, as a fresh contact starts
        for key in self._STATE_SCALARS:
            setattr(self, key, int(state.get(key, 1) if key == "_last_substeps" else state[key]))
        self._resultant.from_numpy(np.asarray(state["resultant"], float))
        if "hist_count" in state:
            self._attach(scene)
            if "hist_roll" not in state:  # a checkpoint from before the rolling history existed
                state = {**state, "hist_roll": np.zeros_like(state["hist_xi"])}
            for key in HISTORY_KEYS:
                if tuple(np.shape(state[key])[:1]) != (scene.n_particles,):
                    raise WheelsoilInputError(f"the saved contact history {key!r} is for another number of particles")
                self._arrays[key].from_numpy(np.ascontiguousarray(state[key]))
        self._need_rebuild = True

    def nodal_forces(self) -> np.ndarray:
        """Contact forces [N] on every structure node at the last evaluation, (N, 3)."""
        return self.structure.device_arrays().f_ext.to_numpy()
