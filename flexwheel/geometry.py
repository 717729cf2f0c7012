"""Parametric flexible metal wheel: geometry, presets and the structured shell/beam mesh.

The wheel (axle along y, wheel plane x-z, centre at the origin) is made of
* a cylindrical **tread** shell (outer radius ``radius``, mid-surface at radius - thickness/2);
* optional **grousers**: radial plates across the full width on the tread's outside;
* **spokes**: bowed flexures from the hub radius to the tread, in one or more rows across the width
  (each row spans a band of the width and has its own angular offset, so the ExoMars-like layout of
  three loops per side plus three inner loops rotated by 60 deg is a preset); modelled as shells or
  as beams;
* optional **side walls** (``side_walls``): a flat annular disc on each side, from the tread's edge down to the
  hub radius, of the tread's thickness, closing the wheel as a disc wheel is closed (an open wheel driven deep fills
  with soil through its sides, and at a steering angle the soil streams through it);
* a rigid **hub**: the spokes' inner nodes are tied to it (see :class:`~.structure.Structure`).

The contact surface is the tread, the grousers and the side walls. Element size is the resolution parameter; the angular
and width grids are refined until every grouser, spoke and row boundary falls on a grid line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.parameters import cmu_k10, exomars, seed004
from wheelsoil.ranges import Range, check_ranges, non_negative, positive

from .beam_section import rectangular_section
from .material import SEED004_WHEEL, Material
from .mesh import StructureMesh
from .shapes import grid_triangles

PARTS = ["tread", "grouser", "spoke", "side"]
#: The parts the soil touches (indices into :data:`PARTS`): tread, grousers and side walls, not the spokes.
CONTACT_PARTS = (0, 1, 3)


@dataclass(frozen=True)
class SpokeRow:
    """A row of spokes: the band [y_min, y_max] of the width (fractions of the width, -0.5..0.5) and
    the angle [deg] of its first spoke; the row's spokes are spread evenly around the wheel."""

    y_min: float = -0.5
    y_max: float = 0.5
    angle: float = 0.0


@dataclass(frozen=True)
class WheelGeometry:
    """Every dimension of a wheel [m, deg]; see the module docstring for the parts."""

    radius: float
    width: float
    tread_thickness: float
    hub_radius: float
    spokes_per_row: int
    spoke_thickness: float
    spoke_rows: tuple[SpokeRow, ...] = (SpokeRow(),)
    spoke_bow: float = 0.15
    spoke_model: str = "shell"
    grouser_count: int = 0
    grouser_height: float = 0.0
    grouser_thickness: float = 0.0
    grouser_angle: float = 0.0
    material: Material = field(default_factory=lambda: SEED004_WHEEL)
    element_size: float = 0.02
    hub_mass: float = 0.0
    nominal_load: float = 0.0
    side_walls: bool = False
    name: str = "wheel"

    RANGES: ClassVar[dict[str, Range]] = {
        "radius": positive(), "width": positive(), "tread_thickness": positive(), "hub_radius": positive(),
        "spokes_per_row": Range(lo=1, integer=True), "spoke_thickness": positive(), "spoke_bow": Range(0.0, 0.5),
        "grouser_count": Range(lo=0, integer=True), "grouser_height": non_negative(),
        "grouser_thickness": non_negative(), "grouser_angle": Range(-89.0, 89.0), "element_size": positive(),
        "hub_mass": non_negative(), "nominal_load": non_negative(),
    }
    UNITS: ClassVar[dict[str, str]] = {
        "radius": "m", "width": "m", "tread_thickness": "m", "hub_radius": "m", "spoke_thickness": "m",
        "grouser_height": "m", "grouser_thickness": "m", "grouser_angle": "deg", "element_size": "m",
        "hub_mass": "kg", "nominal_load": "N",
    }

    def __post_init__(self) -> None:
        check_ranges(self, self.RANGES, f"wheel {self.name!r}:", self.UNITS)
        if self.hub_radius >= self.radius - self.tread_thickness:
            raise WheelsoilInputError(
                f"wheel {self.name!r}: hub_radius={self.hub_radius!r} m must be smaller than the tread's inner "
                f"radius {self.radius - self.tread_thickness:.4g} m"
            )
        if self.tread_thickness >= 0.25 * self.radius:
            raise WheelsoilInputError(
                f"wheel {self.name!r}: tread_thickness={self.tread_thickness!r} m is not thin (must be < radius/4)"
            )
        if self.spoke_model not in ("shell", "beam"):
            raise WheelsoilInputError(f"wheel {self.name!r}: spoke_model={self.spoke_model!r}; choose 'shell' or 'beam'")
        if not self.spoke_rows:
            raise WheelsoilInputError(f"wheel {self.name!r}: spoke_rows is empty; the tread must be held by spokes")
        for k, row in enumerate(self.spoke_rows):
            if not (-0.5 <= row.y_min < row.y_max <= 0.5):
                raise WheelsoilInputError(
                    f"wheel {self.name!r}: spoke_rows[{k}] spans y in [{row.y_min}, {row.y_max}] (fractions of the "
                    "width); need -0.5 <= y_min < y_max <= 0.5"
                )
        if self.grouser_count:
            for key in ("grouser_height", "grouser_thickness"):
                positive().check(f"wheel {self.name!r}: with grouser_count = {self.grouser_count},", key,
                                 getattr(self, key), "m")
        if self.element_size > 0.25 * self.width:
            raise WheelsoilInputError(
                f"wheel {self.name!r}: element_size={self.element_size!r} m is too coarse for width {self.width} m "
                f"(must be <= {0.25 * self.width:.4g} m)"
            )

    @property
    def spoke_pitch(self) -> float:
        """Angle [deg] after which the spoke layout repeats (60 deg for six virtual spokes): the smallest
        rotation 360/d (d dividing the number of distinct spoke angles) that maps the spoke angles onto
        themselves -- two rows of 12 staggered by 15 deg repeat every 15 deg, by 10 deg every 30 deg."""
        angles = sorted({round((row.angle + 360.0 * k / self.spokes_per_row) % 360.0, 9)
                         for row in self.spoke_rows for k in range(self.spokes_per_row)})
        n = len(angles)
        present = np.array(angles)
        for d in sorted((d for d in range(1, n + 1) if n % d == 0), reverse=True):
            shifted = (present + 360.0 / d) % 360.0
            gap = np.abs(shifted[:, None] - present[None, :])
            if np.all(np.min(np.minimum(gap, 360.0 - gap), axis=1) < 1e-6):
                return 360.0 / d
        return 360.0

    def with_element_size(self, size: float) -> "WheelGeometry":
        return replace(self, element_size=float(size))

    @property
    def tread_mid_radius(self) -> float:
        return self.radius - 0.5 * self.tread_thickness


#: Peak resident memory per wheel element while a wheel is meshed, assembled and stepped [bytes]: an upper
#: bound, about 2.3 x the 27.8 KiB per element measured for the 25,920-element seed-004 wheel (822 MiB less the
#: 119 MiB interpreter, 2026-11-24; benchmarks/README.md, testbed throughput).
BYTES_PER_ELEMENT = 65536


def estimated_elements(g: WheelGeometry) -> int:
    """Elements (triangles and beams) :func:`build_wheel_mesh` makes, from the grid counts alone (without the
    round-up that puts nodes at every spoke and grouser angle: 10-50 % low on the presets); O(1) in the count."""
    h = g.element_size
    n_around = math.ceil(2 * math.pi * g.tread_mid_radius / h)
    n_width = max(2, math.ceil(g.width / h))
    n = 2 * n_around * n_width
    if g.grouser_count:
        n += g.grouser_count * 2 * max(1, math.ceil(g.grouser_height / h)) * n_width
    n_s = max(2, math.ceil((g.tread_mid_radius - g.hub_radius) * (1 + 2 * g.spoke_bow) / h))
    for row in g.spoke_rows:
        cols = max(1, round((row.y_max - row.y_min) * n_width))
        n += g.spokes_per_row * (2 * n_s * cols if g.spoke_model == "shell" else n_s * (cols + 1))
    if g.side_walls:
        n += 2 * 2 * n_around * _side_rings(g)
    return int(n)


def _side_rings(g: WheelGeometry) -> int:
    """Rings of a side wall's mesh from the tread's mid-surface radius to the hub radius (at least two)."""
    return max(2, math.ceil((g.tread_mid_radius - g.hub_radius) / g.element_size))


def check_mesh_memory(g: WheelGeometry, available: int, share: float = 0.5) -> int:
    """Refuse, before meshing, a wheel whose estimated elements need more than ``share`` of ``available``
    bytes (:data:`BYTES_PER_ELEMENT` each); returns the estimate [bytes]."""
    n = estimated_elements(g)
    need = n * BYTES_PER_ELEMENT
    if available > 0 and need > share * available:
        raise WheelsoilInputError(
            f"wheel {g.name!r}: wheel.element_size = {g.element_size:g} m makes about {n:,} elements, about "
            f"{need / 2**30:.3g} GiB, more than {share:.0%} of the {available / 2**30:.3g} GiB this machine has: "
            f"use a coarser element_size (the preset's own is a good start)"
        )
    return need


def _grid_count(fractions: list[float], start: int, period: float = 1.0) -> int:
    """Smallest n >= start for which every fraction (of ``period``) is a multiple of period / n."""
    for n in range(max(start, 1), 100_000):
        if all(abs(f * n / period - round(f * n / period)) < 1e-6 for f in fractions):
            return n
    raise WheelsoilInputError(f"no grid of up to 100000 divisions puts nodes at {fractions}")


def wheel_mass(geometry: WheelGeometry) -> float:
    """The wheel's whole mass [kg]: its mesh's lumped mass plus the hub's own (what the testbed's rig carries)."""
    return build_wheel_mesh(geometry)[0].total_mass + geometry.hub_mass


def build_wheel_mesh(geometry: WheelGeometry) -> tuple[StructureMesh, np.ndarray]:
    """Mesh the wheel. Returns the mesh and the indices of the hub nodes (spokes' inner ends)."""
    g = geometry
    h = g.element_size
    r_mid = g.tread_mid_radius
    # ---- angular grid: tread nodes at every grouser and spoke angle
    turns = []
    for row in g.spoke_rows:
        turns += [((row.angle / 360.0) + k / g.spokes_per_row) % 1.0 for k in range(g.spokes_per_row)]
    turns += [((g.grouser_angle / 360.0) + k / g.grouser_count) % 1.0 for k in range(g.grouser_count)]
    n_around = _grid_count(turns, math.ceil(2 * math.pi * r_mid / h))
    # ---- width grid: nodes at every row boundary
    bounds = [row.y_min + 0.5 for row in g.spoke_rows] + [row.y_max + 0.5 for row in g.spoke_rows]
    n_width = _grid_count(bounds, max(2, math.ceil(g.width / h)))
    nw1 = n_width + 1
    phi = 2 * math.pi * np.arange(n_around) / n_around
    y = np.linspace(-g.width / 2, g.width / 2, nw1)
    pp, yy = np.meshgrid(phi, y, indexing="ij")
    nodes = [np.c_[r_mid * np.cos(pp.ravel()), yy.ravel(), r_mid * np.sin(pp.ravel())]]
    n_nodes = n_around * nw1
    tri = [grid_triangles(n_around, n_width, periodic_u=True)[:, ::-1]]  # outward normals
    thick = [np.full(len(tri[0]), g.tread_thickness)]
    part = [np.zeros(len(tri[0]), np.int64)]

    def tread_node(i, j):
        return (i % n_around) * nw1 + j

    # ---- grousers: radial plates outside the tread
    for k in range(g.grouser_count):
        i = int(round(((g.grouser_angle / 360.0 + k / g.grouser_count) % 1.0) * n_around)) % n_around
        new, local = _grouser(g, phi[i], y, [tread_node(i, j) for j in range(nw1)], n_nodes)
        nodes.append(new)
        n_nodes += len(new)
        tri.append(local)
        thick.append(np.full(len(local), g.grouser_thickness))
        part.append(np.ones(len(local), np.int64))
    # ---- spokes
    hub_nodes = []
    beams, beam_sec = [], []
    span = r_mid - g.hub_radius
    n_s = max(2, math.ceil(span * (1 + 2 * g.spoke_bow) / h))
    u = np.linspace(0.0, 1.0, n_s + 1)
    for row in g.spoke_rows:
        j0 = int(round((row.y_min + 0.5) * n_width))
        j1 = int(round((row.y_max + 0.5) * n_width))
        cols = np.arange(j0, j1 + 1)
        for k in range(g.spokes_per_row):
            i = int(round(((row.angle / 360.0 + k / g.spokes_per_row) % 1.0) * n_around)) % n_around
            c, s = math.cos(phi[i]), math.sin(phi[i])
            radial = np.array([c, s])
            tangent = np.array([-s, c])
            path = (g.hub_radius + u[:, None] * span) * radial + (g.spoke_bow * span * np.sin(np.pi * u))[:, None] * tangent
            inner = path[:-1]  # the last point is the tread node
            new = np.zeros((len(inner), len(cols), 3))
            new[..., 0] = inner[:, None, 0]
            new[..., 2] = inner[:, None, 1]
            new[..., 1] = y[cols][None, :]
            ids = np.vstack([n_nodes + np.arange(new.shape[0] * new.shape[1]).reshape(new.shape[:2]),
                             [[tread_node(i, j) for j in cols]]])
            nodes.append(new.reshape(-1, 3))
            n_nodes += new.shape[0] * new.shape[1]
            hub_nodes.extend(ids[0].tolist())
            if g.spoke_model == "shell":
                local = grid_triangles(n_s, len(cols) - 1)
                tri.append(ids.ravel()[local])
                thick.append(np.full(len(local), g.spoke_thickness))
                part.append(np.full(len(local), 2, np.int64))
            else:
                strip_width = (row.y_max - row.y_min) * g.width / len(cols)
                for jc in range(len(cols)):
                    for a in range(n_s):
                        beams.append((ids[a, jc], ids[a + 1, jc]))
                        beam_sec.append(rectangular_section(strip_width, g.spoke_thickness))
    if g.side_walls:
        for j in (0, n_width):
            new, local, inner = _side_wall(g, phi, y[j], [tread_node(i, j) for i in range(n_around)], n_nodes)
            nodes.append(new)
            n_nodes += len(new)
            hub_nodes.extend(inner)
            tri.append(local)
            thick.append(np.full(len(local), g.tread_thickness))
            part.append(np.full(len(local), PARTS.index("side"), np.int64))
    triangles = np.vstack(tri)
    n_tri = len(triangles)
    surface = np.flatnonzero(np.isin(np.concatenate(part), CONTACT_PARTS))
    beam_arr = np.asarray(beams, np.int64).reshape(-1, 2)
    mesh = StructureMesh(
        nodes=np.vstack(nodes),
        triangles=triangles,
        thickness=np.concatenate(thick),
        material=g.material,
        beams=beam_arr,
        beam_section=np.asarray(beam_sec).reshape(-1, 4) if beams else None,
        beam_orientation=[0.0, 1.0, 0.0] if beams else None,
        part=np.concatenate(part + [np.full(len(beam_arr), 2, np.int64)]),
        part_names=list(PARTS),
        surface=surface,
    )
    assert n_tri == len(mesh.triangles)
    return mesh, np.unique(np.asarray(hub_nodes, np.int64))


def _grouser(g: WheelGeometry, angle: float, y: np.ndarray, root: list[int], first: int):
    """One grouser: a radial plate at ``angle`` [rad] across the width (nodes at ``y`` [m]) from the tread's nodes
    ``root`` at the mid-surface out to the outer radius plus the grouser height. Returns its new nodes (first
    numbered ``first``) and its triangles (node indices)."""
    n_g, nw1 = max(1, math.ceil(g.grouser_height / g.element_size)), len(y)
    heights = np.linspace(0.0, g.grouser_height + 0.5 * g.tread_thickness, n_g + 1)[1:]
    rr, yy = np.meshgrid(g.tread_mid_radius + heights, y, indexing="ij")
    new = np.c_[rr.ravel() * math.cos(angle), yy.ravel(), rr.ravel() * math.sin(angle)]
    ids = np.vstack([root, first + np.arange(n_g * nw1).reshape(n_g, nw1)])
    return new, ids.ravel()[grid_triangles(n_g, nw1 - 1)]


def _side_wall(g: WheelGeometry, phi: np.ndarray, y: float, edge: list[int], first: int):
    """One side wall: an annulus in the plane at ``y`` [m], from the tread's edge nodes ``edge`` (one per angle of
    ``phi`` [rad]) in rings down to the hub radius. Returns its new nodes (first numbered ``first``), its triangles
    (node indices) and its innermost ring's nodes (tied to the hub)."""
    n_r, n_around = _side_rings(g), len(phi)
    r_mid = g.tread_mid_radius
    radii = r_mid - (r_mid - g.hub_radius) * np.arange(1, n_r + 1) / n_r
    rr, pp = np.meshgrid(radii, phi, indexing="ij")
    new = np.c_[rr.ravel() * np.cos(pp.ravel()), np.full(rr.size, y), rr.ravel() * np.sin(pp.ravel())]
    ids = np.vstack([edge, first + np.arange(n_r * n_around).reshape(n_r, n_around)])  # (ring, angle)
    local = grid_triangles(n_around, n_r, periodic_u=True)  # angles (closed around) x rings
    return new, ids.T.ravel()[local], ids[-1].tolist()


def from_parameters(values: dict) -> WheelGeometry:
    """A :class:`WheelGeometry` from a parameter set's keyword dictionary (spoke rows as (y_min, y_max, angle))."""
    values = dict(values)
    values["spoke_rows"] = tuple(SpokeRow(*row) for row in values["spoke_rows"])
    return WheelGeometry(**values)


#: The flexible metal wheel of the staffed lunar rover of seed 004 (:data:`wheelsoil.parameters.seed004.LUNAR_ROVER_WHEEL`:
#: r = 0.6 m, b = 0.5 m, Table 2 material; tread, spoke and grouser sizes ours). ``element_size`` 0.018 m gives a
#: mesh of the paper's size (about 30,000 elements); coarser sizes are for quick runs.
LUNAR_ROVER = from_parameters(seed004.LUNAR_ROVER_WHEEL)

#: ExoMars-like flexible wheel of seeds 000/001 (:data:`wheelsoil.parameters.exomars.EXOMARS_WHEEL`).
EXOMARS = from_parameters(exomars.EXOMARS_WHEEL)

#: The CMU rig's K10-mini wheels, smooth and with 16 grousers of 5 mm (:data:`wheelsoil.parameters.cmu_k10.K10_MINI_WHEELS`:
#: r = 0.058 m, b = 0.05 m; run rigid, as the rig's wheels are).
CMU_K10_SMOOTH, CMU_K10_GROUSER = (from_parameters(cmu_k10.K10_MINI_WHEELS[k]) for k in ("smooth", "grouser"))

PRESETS = {g.name: g for g in (LUNAR_ROVER, EXOMARS, CMU_K10_SMOOTH, CMU_K10_GROUSER)}


def preset(name: str) -> WheelGeometry:
    """A preset wheel by name (``lunar-rover``, ``exomars``, ``cmu-k10-smooth`` or ``cmu-k10-grouser``)."""
    try:
        return PRESETS[name]
    except KeyError:
        raise WheelsoilInputError(f"unknown wheel preset {name!r}; choose one of {sorted(PRESETS)}") from None
