"""The state of a soil coupled to a structure through a :class:`~.contact.WheelContact`, to continue a run from: the
scene's, the structure's and the contact's, as plain arrays and scalars. The testbed's checkpoints
(:meth:`~.testbed.Testbed.state`) and the soil lab's pressing tests (``wheelsoil.soillab.penetration``) take and restore
it the same way here."""

from __future__ import annotations


def take_coupled_state(scene, structure, contact) -> dict:
    """``{"scene", "structure", "contact"}`` states. Taking it puts the soil in a canonical form (its arrays back on the
    host, the neighbour lists rebuilt at the next step) and makes the contact rebuild its candidates, as a restored
    run must: so a run continued from it steps exactly as the run that took it."""
    state = {"scene": scene.state(), "structure": structure.state(), "contact": contact.state()}
    contact.invalidate()
    return state


def restore_coupled_state(state: dict, scene, structure, contact, *, same_spheres: bool = True) -> None:
    """Continue from :func:`take_coupled_state`'s ``state`` with the same soil, structure and contact settings
    (``same_spheres``: the scene holds the spheres it held when the state was taken; false for a moving patch)."""
    scene.restore_state(state["scene"], same_spheres=same_spheres)
    structure.restore_state(state["structure"])
    contact.restore_state(scene, state["contact"])
