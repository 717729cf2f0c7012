"""The protocol of a body outside a scene that exchanges contact forces with its spheres (a wheel, a plate)."""

from __future__ import annotations


class Interaction:
    """A body outside the scene that exchanges contact forces with the spheres (protocol).

    The scene calls, in every step,

    * ``after_drift(scene, dt)`` once the spheres have drifted to t + dt (a body advances itself
      to t + dt here), then
    * ``add_forces(scene, dt) -> int``: it adds its contact forces and torques at t + dt to
      ``scene.device_state().external_force/external_torque`` and returns its number of contacts.
      The one-launch step that follows adds them to the sphere--sphere and sphere--wall forces
      (:mod:`.fused_step`).

    A body that keeps candidate lists of spheres near it, built with a margin for the spheres' motion, bounds how far
    a sphere may move between two of the scene's neighbour rebuilds (otherwise a sphere clear of its neighbours may
    move up to half its clearance), in one of two ways: sphere by sphere, by calling
    ``scene.limit_allowances(gap, less)`` with each sphere's gap to what it did not list each time it builds its
    lists (:meth:`~.scene.Scene.limit_allowances`; the wheel contact does), or for all alike, by defining
    ``displacement_cap(scene) -> float``: the margin [m] (:meth:`~.scene.Scene.displacement_cap`). It builds its
    lists in a step in which the scene rebuilt (``scene.neighbor_rebuilds`` changed), or else calls
    ``scene.request_neighbor_rebuild()`` so that the next step does.

    An optional ``renumber(scene, old_of_new)`` hears that sphere k is now the former sphere ``old_of_new[k]``
    (-1: a new one) after spheres were added or removed.

    ``contact_moduli`` lists the effective Young's moduli [Pa] of its contacts with the spheres so
    that the scene's stable time step accounts for them.
    """

    contact_moduli: tuple[float, ...] = ()

    def after_drift(self, scene, dt: float) -> None:  # pragma: no cover - protocol
        """Advance the body to t + dt [s] (``scene``: the :class:`~.scene.Scene`, already drifted)."""

    def add_forces(self, scene, dt: float) -> int:  # pragma: no cover - protocol
        """Add the contact forces and torques at t + dt to the scene's external arrays; the number of contacts."""
        return 0


class SkinCap(Interaction):
    """No body, no force: caps every sphere's displacement allowance at ``skins`` of the scene's skin, for comparing
    rebuild rules in one run (the trajectory is the same under any; ``scene.interactions.append(SkinCap(2.0))``)."""

    def __init__(self, skins: float) -> None:
        self.skins = float(skins)

    def after_drift(self, scene, dt: float) -> None:
        pass

    def add_forces(self, scene, dt: float) -> int:
        return 0

    def displacement_cap(self, scene) -> float:
        """``skins`` of the scene's skin [m]."""
        return self.skins * scene.skin


class HalfSkinRule(SkinCap):
    """Every sphere's displacement allowance capped at half the skin: the plain Verlet test (a rebuild once any sphere
    has moved half the skin) that the neighbour lists used before each sphere had its own allowance
    (:func:`.neighbors.displacement_allowance`)."""

    def __init__(self) -> None:
        super().__init__(0.5)
