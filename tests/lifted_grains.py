"""A grain sent up out of the bed, as a wheel throws one: for tests of the neighbour lists' clearance and widened
search (tests/test_displacement_allowance.py, tests/test_periodic_lists.py)."""

from wheelsoil.granular import Scene


def lift(s: Scene, index, positions, speed: float) -> None:
    """Put spheres ``index`` at ``positions`` [m], rising at ``speed`` [m/s] with no wall contact remembered, and step
    once (the restored state rebuilds the lists)."""
    state = s.state()
    state["x"][index] = positions
    state["v"][index] = (0.0, 0.0, speed)
    state["hist_xi_wall"][index] = state["hist_roll_wall"][index] = 0.0
    s.restore_state(state)
    s.step(1)
