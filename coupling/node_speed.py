"""The wheel's nodes against the contact's time step: a node that moves too far in one DEM step stops the run.

The sphere--wheel contacts are evaluated once a DEM step (:mod:`.contact`), so a node that moves a good part of its
facets' size in one step has contacts the evaluation cannot follow. Such a node is a blow-up of the coupling, not
physics: on 2026-12-07 a grouser tip rattling at the DEM step moved 67 mm in one step, buried a grain 11.7 mm deep
in its facet and threw it out at 20 m/s (docs/gravity-terms/README.md). The spheres have the same kind of limit,
a fifth of the smallest radius a step (:data:`wheelsoil.granular.health.SPEED_LIMIT_RADII_PER_STEP`).
"""

from __future__ import annotations

import numpy as np

from wheelsoil.errors import SimulationUnstableError

#: A wheel node moving more than this fraction of the shortest contact facet edge in one DEM step is a blow-up. The
#: grouser tip above moved 67 mm in a step against the 4.5 mm this allows on its mesh; a rolling wheel's nodes move
#: about 0.1 mm.
NODE_MOVE_PER_STEP = 0.2


def shortest_edge(triangles: np.ndarray, nodes: np.ndarray) -> float:
    """The shortest edge [m] of the facets ``triangles`` (S, 3) over the node positions ``nodes`` (N, 3)."""
    return float(min(np.linalg.norm(nodes[triangles[:, a]] - nodes[triangles[:, b]], axis=1).min()
                     for a, b in ((0, 1), (1, 2), (2, 0))))


def require_node_speed(speed: float, edge: float, dt: float, substeps: int, t: float) -> None:
    """Raise :class:`SimulationUnstableError` when the wheel's fastest node, at ``speed`` [m/s] at time ``t`` [s],
    moves more than :data:`NODE_MOVE_PER_STEP` ``edge`` [m] per DEM step ``dt`` [s]; ``substeps``: the wheel's
    sub-steps in that step (for the message)."""
    limit = NODE_MOVE_PER_STEP * edge / dt
    if speed > limit:
        raise SimulationUnstableError(
            f"the wheel went unstable at t = {t:.6g} s: a node moves at {speed:.3g} m/s, "
            f"{speed * dt * 1e3:.3g} mm in a DEM step of {dt:.3g} s, more than {NODE_MOVE_PER_STEP:g} of the "
            f"shortest contact facet edge ({edge * 1e3:.3g} mm; {limit:.3g} m/s). The contacts are evaluated once "
            f"a DEM step ({substeps} wheel sub-steps each), so they cannot follow it: shorten the DEM step "
            "(soil.time_step) or soften the wheel")
