"""Finite-element mesh of a shell/beam structure: arrays in, checks, lumped mass, meshio export.

A :class:`StructureMesh` is plain NumPy: node coordinates [m], triangles (shell facets) with a
thickness each [m], 2-node beams with a cross-section (A, I_y, I_z, J) and an orientation vector for
the section's local y axis, a part id per element, and the list of facets that form the contact
surface (the tread and grousers of a wheel). Nothing here knows about Taichi.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from wheelsoil.errors import WheelsoilInputError

from .material import Material
from .shell_stiffness import DRILLING_PENALTY


def _as_array(name, value, dtype, shape_tail, allow_empty=True):
    arr = np.asarray(value if value is not None else np.zeros((0,) + shape_tail), dtype=dtype)
    if arr.ndim != 1 + len(shape_tail) or arr.shape[1:] != shape_tail:
        raise WheelsoilInputError(f"{name} must have shape (n, {', '.join(map(str, shape_tail))}), got {arr.shape}")
    if not allow_empty and arr.shape[0] == 0:
        raise WheelsoilInputError(f"{name} is empty")
    if arr.dtype.kind == "f" and not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise WheelsoilInputError(f"{name}[{', '.join(map(str, bad))}] is {arr[tuple(bad)]!r}; all entries must be finite")
    return arr


@dataclass
class StructureMesh:
    """Nodes, shell facets and beams of one structure (SI units).

    Parameters
    ----------
    nodes: (N, 3) coordinates [m].
    triangles: (T, 3) node indices of the shell facets (counter-clockwise seen from the side the
        normal points to).
    thickness: (T,) shell thickness [m] (a scalar is broadcast).
    beams: (B, 2) node indices of the beams.
    beam_section: (B, 4) section (A [m^2], I_y [m^4], I_z [m^4], J [m^4]); a single row is broadcast.
    beam_orientation: (B, 3) a vector that fixes the section's local y axis (made normal to the beam).
    material: the elastic material of the whole structure.
    part: per element (facets first, then beams) an index into ``part_names``.
    surface: indices of the facets that form the outer (contact) surface; default all facets.
    """

    nodes: np.ndarray
    triangles: np.ndarray
    thickness: np.ndarray | float
    material: Material
    beams: np.ndarray | None = None
    beam_section: np.ndarray | None = None
    beam_orientation: np.ndarray | None = None
    part: np.ndarray | None = None
    part_names: list[str] = field(default_factory=lambda: ["structure"])
    surface: np.ndarray | None = None
    drilling_penalty: float = DRILLING_PENALTY

    def __post_init__(self) -> None:
        if not math.isfinite(self.material.youngs_modulus):
            raise WheelsoilInputError(
                f"material {self.material.name!r}: youngs_modulus E = {self.material.youngs_modulus!r} Pa: the wheel's "
                "finite elements need a finite modulus (a rigid wheel is wheel.rigid = true)")
        self.nodes = _as_array("nodes", self.nodes, float, (3,), allow_empty=False)
        n = len(self.nodes)
        self.triangles = _as_array("triangles", self.triangles, np.int64, (3,))
        self.beams = _as_array("beams", self.beams, np.int64, (2,))
        nt, nb = len(self.triangles), len(self.beams)
        if nt + nb == 0:
            raise WheelsoilInputError("the mesh has neither triangles nor beams")
        for name, idx in (("triangles", self.triangles), ("beams", self.beams)):
            if idx.size and (idx.min() < 0 or idx.max() >= n):
                bad = idx[(idx < 0) | (idx >= n)][0]
                raise WheelsoilInputError(f"{name} refer to node {bad}, but node indices run from 0 to {n - 1}")
        self.thickness = np.broadcast_to(np.asarray(self.thickness, float), (nt,)).copy()
        if nt and not (np.all(np.isfinite(self.thickness)) and self.thickness.min() > 0):
            k = int(np.argmin(np.where(np.isfinite(self.thickness), self.thickness, -np.inf)))
            raise WheelsoilInputError(f"thickness[{k}] = {self.thickness[k]!r} m; shell thickness must be > 0")
        if nb:
            sec = np.asarray(self.beam_section if self.beam_section is not None else np.nan, float)
            sec = np.broadcast_to(sec, (nb, 4)).copy() if sec.ndim < 2 or sec.shape[0] == 1 else sec
            self.beam_section = _as_array("beam_section", sec, float, (4,))
            if len(self.beam_section) != nb or self.beam_section.min() <= 0:
                raise WheelsoilInputError(
                    "beam_section must give (A, I_y, I_z, J) > 0 for every beam "
                    f"(got shape {self.beam_section.shape}, minimum {self.beam_section.min():.3g})"
                )
            ori = self.beam_orientation if self.beam_orientation is not None else [0.0, 0.0, 1.0]
            ori = np.asarray(ori, float)
            self.beam_orientation = _as_array("beam_orientation", np.broadcast_to(ori, (nb, 3)).copy(), float, (3,))
        else:
            self.beam_section = np.zeros((0, 4))
            self.beam_orientation = np.zeros((0, 3))
        if self.part is None:
            self.part = np.zeros(nt + nb, dtype=np.int64)
        self.part = np.asarray(self.part, dtype=np.int64)
        if len(self.part) != nt + nb or (self.part.size and self.part.max() >= len(self.part_names)):
            raise WheelsoilInputError("part must hold one index into part_names per element (facets, then beams)")
        self.surface = np.arange(nt) if self.surface is None else np.asarray(self.surface, dtype=np.int64)
        self._check_geometry()

    def _check_geometry(self) -> None:
        if len(self.triangles):
            p = self.nodes[self.triangles]
            cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
            area2 = np.linalg.norm(cross, axis=1)
            edge2 = np.max([np.sum((p[:, i] - p[:, j]) ** 2, axis=1) for i, j in ((0, 1), (1, 2), (2, 0))], axis=0)
            quality = area2 / np.maximum(edge2, 1e-300)  # 2A / l_max^2: sqrt(3)/2 for equilateral
            k = int(np.argmin(quality))
            if quality[k] < 1e-3:
                raise WheelsoilInputError(
                    f"triangle {k} (nodes {self.triangles[k].tolist()}) is degenerate: 2*area/longest_edge^2 = "
                    f"{quality[k]:.2e} (must be >= 1e-3; 0.87 is equilateral)"
                )
        if len(self.beams):
            d = self.nodes[self.beams[:, 1]] - self.nodes[self.beams[:, 0]]
            length = np.linalg.norm(d, axis=1)
            k = int(np.argmin(length))
            scale = np.ptp(self.nodes, axis=0).max()
            if length[k] <= 1e-9 * max(scale, 1e-300):
                raise WheelsoilInputError(f"beam {k} (nodes {self.beams[k].tolist()}) has zero length")
            ori = self.beam_orientation
            sin = np.linalg.norm(np.cross(d / length[:, None], ori), axis=1) / np.maximum(np.linalg.norm(ori, axis=1), 1e-300)
            k = int(np.argmin(sin))
            if sin[k] < 1e-3:
                raise WheelsoilInputError(
                    f"beam_orientation[{k}] = {ori[k].tolist()} is parallel to beam {k}; it must fix the section's y axis"
                )

    # ---------------------------------------------------------------- derived quantities
    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def n_elements(self) -> int:
        return len(self.triangles) + len(self.beams)

    def characteristic_length(self) -> float:
        """Mean element size [m]: sqrt of the mean facet area, or the mean beam length."""
        sizes = []
        if len(self.triangles):
            sizes.append(np.sqrt(self.facet_areas()))
        if len(self.beams):
            sizes.append(self.beam_lengths())
        return float(np.concatenate(sizes).mean())

    def facet_areas(self) -> np.ndarray:
        p = self.nodes[self.triangles]
        return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)

    def beam_lengths(self) -> np.ndarray:
        return np.linalg.norm(self.nodes[self.beams[:, 1]] - self.nodes[self.beams[:, 0]], axis=1)

    def element_masses(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Lumped translational mass [kg] and rotary inertia [kg m^2] per element corner.

        Facets: m = rho t A / 3 per corner; rotary inertia m * max(t^2/12, alpha_d A) -- the physical
        t^2/12 raised where needed so that the drilling and bending rotations never limit the time step
        (rotary inertia scaling, e.g. Hughes, *The Finite Element Method*, sec. 9.4; it changes no
        static answer). Beams: m = rho A L / 2 per end, rotary inertia m * 2 max(I_y, I_z) / A.
        Returns (facet_mass (T,), facet_inertia (T,), beam_mass (B,), beam_inertia (B,)).
        """
        rho = self.material.density
        area = self.facet_areas()
        t = self.thickness
        fm = rho * t * area / 3.0
        fi = fm * np.maximum(t**2 / 12.0, self.drilling_penalty * area)
        bm = rho * self.beam_section[:, 0] * self.beam_lengths() / 2.0
        bi = bm * 2.0 * np.maximum(self.beam_section[:, 1], self.beam_section[:, 2]) / self.beam_section[:, 0]
        return fm, fi, bm, bi

    def lumped_mass(self) -> tuple[np.ndarray, np.ndarray]:
        """Node mass [kg] and isotropic rotary inertia [kg m^2], assembled from ``element_masses``."""
        fm, fi, bm, bi = self.element_masses()
        mass = np.zeros(self.n_nodes)
        inertia = np.zeros(self.n_nodes)
        for a in range(3):
            np.add.at(mass, self.triangles[:, a], fm)
            np.add.at(inertia, self.triangles[:, a], fi)
        for a in range(2):
            np.add.at(mass, self.beams[:, a], bm)
            np.add.at(inertia, self.beams[:, a], bi)
        return mass, inertia

    @property
    def total_mass(self) -> float:
        return float(self.lumped_mass()[0].sum())

    # ---------------------------------------------------------------- export
    def to_meshio(self, point_data: dict | None = None):
        """A ``meshio.Mesh`` with ``triangle`` and ``line`` cells and per-cell part id and thickness."""
        import meshio

        cells, part, thick = [], [], []
        nt = len(self.triangles)
        if nt:
            cells.append(("triangle", self.triangles.astype(np.int64)))
            part.append(self.part[:nt])
            thick.append(self.thickness)
        if len(self.beams):
            cells.append(("line", self.beams.astype(np.int64)))
            part.append(self.part[nt:])
            thick.append(np.sqrt(self.beam_section[:, 0]))
        return meshio.Mesh(
            self.nodes, cells, point_data=point_data or {},
            cell_data={"part": part, "thickness": thick},
        )

    def write(self, path: str | Path, point_data: dict | None = None) -> Path:
        """Write the mesh (and optional nodal fields) with meshio; the format follows the suffix
        (``.vtu`` for ParaView, ``.xdmf``, ...). The file appears complete or not at all."""
        from wheelsoil.provenance import atomic_output

        path = Path(path)
        fmt = _meshio_format(path)
        with atomic_output(path) as tmp:
            mesh = self.to_meshio(point_data)
            if fmt == "xdmf":  # inline XML data: one self-contained file that survives the rename
                import meshio.xdmf

                meshio.xdmf.write(tmp, mesh, data_format="XML")
            else:
                mesh.write(tmp, file_format=fmt)
        return path


def _meshio_format(path: Path) -> str:
    fmt = {".vtu": "vtu", ".xdmf": "xdmf", ".xmf": "xdmf", ".vtk": "vtk", ".msh": "gmsh"}.get(path.suffix.lower())
    if fmt is None:
        raise WheelsoilInputError(f"mesh file {path}: suffix {path.suffix!r} not supported; use .vtu, .xdmf, .vtk or .msh")
    return fmt
