"""Wheel meets soil: the DE--FE contact interface, the coupled stepper and the single-wheel testbed.

* :mod:`.closest_point` -- point--triangle closest point with face, edge and vertex regions;
* :mod:`.surface` -- the wheel's contact surface (triangles, shared edges, node adjacency);
* :mod:`.contact` -- Hertz--Mindlin particle--triangle contact (:class:`WheelContact`), forces to the
  FE nodes by barycentric weights;
* :mod:`.testbed` -- the rig: slip, steering angle, vertical load, protocol, measured quantities and
  checkpoints (:meth:`Testbed.state`, :meth:`Testbed.restore_state`).

The cases (seed 004 at full scale, the smoke and mini cases) are TOML files in ``cases/presets``.
"""
