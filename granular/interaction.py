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
