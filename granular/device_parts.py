"""A scene on the device, part by part, made from its host state (:func:`DeviceParts.upload`) and dropped before a
structural edit: the particle arrays (:mod:`.particles`), the neighbour list with the pairs' contact history on the
shared grid (:mod:`.neighbor_list`, :mod:`.grid`), the walls (:mod:`.walls`), the pair constants
(:class:`.contact.ContactParameters`), the stepper (:mod:`.stepper`) and the health figures' buffer."""

from __future__ import annotations

from dataclasses import dataclass

import taichi as ti

from .contact import ContactParameters
from .contact_history import ContactHistory
from .errors import WheelsoilInputError
from .grid import UniformGrid
from .materials import Material, PairProperties
from .neighbor_list import NeighborList, PairList, row_width
from .particles import ParticleArrays
from .scene_domain import SceneDomain
from .sphere_state import SphereState
from .stepper import Stepper
from .walls import Wall, WallArrays


@dataclass
class DeviceParts:
    """A scene on the device, part by part (made from the host state, dropped before a structural edit)."""

    particles: ParticleArrays
    neighbor_list: NeighborList
    walls: WallArrays
    params: ContactParameters
    stepper: Stepper
    health: ti.Ndarray  # state_health's five figures

    @classmethod
    def upload(cls, spheres: SphereState, history: ContactHistory | None, walls: list[Wall], material: Material,
               pair: PairProperties, domain: SceneDomain, skin: float, cell_size: float | None) -> "DeviceParts":
        """The parts of a scene of ``spheres`` with the contacts' memory ``history`` (None: no contact yet), on a
        grid over ``domain`` of cells ``cell_size`` [m] (default and minimum the reach 2 r_max + ``skin``). The
        neighbour list is not built yet."""
        r_min, r_max = float(spheres.r.min()), float(spheres.r.max())
        reach = 2.0 * r_max + skin
        cell = reach if cell_size is None else float(cell_size)
        if cell < reach * (1 - 1e-12):
            raise WheelsoilInputError(
                f"cell_size = {cell!r} m is smaller than the interaction reach 2 r_max + skin = {reach:.4g} m"
            )
        grid = UniformGrid.covering(domain.lo, domain.hi, cell, period=domain.period)
        n, h, s = len(spheres), history, spheres
        particles = ParticleArrays.upload(s.x, s.v, s.w, s.f, s.t, s.r, s.mobile, material.density)
        # the pair list the first build carries the history from (the host copy, if any)
        pairs = (PairList.from_history(n, h.pair_i, h.pair_j, h.pair_xi, h.pair_roll) if h is not None
                 else PairList.allocate(n, 1))
        neighbor_list = NeighborList(n, grid, skin, row_width(r_min, r_max, skin), pairs, r_max)
        wall_arrays = WallArrays.upload(walls, material, n, *((h.xi_wall, h.roll_wall) if h is not None
                                                              else (None, None)))
        params = ContactParameters.of(material, pair)
        return cls(particles, neighbor_list, wall_arrays, params,
                   Stepper(particles, neighbor_list, wall_arrays, params), ti.ndarray(ti.f64, shape=5))

    def history(self) -> ContactHistory:
        """The contacts' memory as it stands on the device (a host copy)."""
        return ContactHistory(**self.neighbor_list.history(), **self.walls.history())
