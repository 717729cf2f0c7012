"""What one sample of a testbed run records: the forces, sinkages, slips and the hub's pose (the series' columns,
:data:`~.run_summary.SERIES_UNITS`)."""

from __future__ import annotations

import math

from .kinematics import longitudinal_slip, slip_angle_deg


def sample_row(bench, phase: str, interval: float) -> dict:
    """One sample of the series (:data:`~.run_summary.SERIES_UNITS`'s columns) at the end of a sampling interval of
    ``interval`` [s] in the protocol's ``phase``: the contact resultant averaged over the interval in the wheel's
    frame (drawbar pull along the heading, lateral force along the axle, vertical force; the torque about the axle),
    the hub's and the tread's sinkage, the slips and slip angles the hub and the tread see (:mod:`.kinematics`), the
    tread's wind-up and spin, the load, the hub's pose and the travel along the bin. It advances the tread's angle
    and the wind-up controller's filtered spin in ``bench``'s protocol state. ``bench``: the running
    :class:`~.testbed.Testbed`."""
    s, loop = bench.spec, bench.protocol_state
    force, moment, _ = bench.contact.mean_resultant(reset=True)
    hub = bench.structure.hub_position
    vel = bench.structure.hub_velocity
    spin = float(bench.structure.hub_angular_velocity @ bench.axle)
    nodes = bench.structure.positions()
    tread = bench.tracker.state(nodes[bench.tread_nodes], bench.structure.hub_rotation)
    tread_angle = loop.hub_angle - tread.wind_up
    previous = tread_angle if loop.tread_angle is None else loop.tread_angle
    loop.tread_angle = tread_angle
    tread_omega = (tread_angle - previous) / interval
    loop.omega_filtered += (tread_omega - loop.omega_filtered) * min(1.0, interval / s.windup_filter)
    vx = float(vel @ bench.heading)
    vx_tread = float(vel @ tread.heading)
    if bench.spec.slip_speed == "travel":  # the whole horizontal travel speed, the same for hub and tread
        vx = vx_tread = float(math.hypot(vel[0], vel[1]))
    r = bench.wheel.radius
    return {
        "t": bench.scene.time,
        "drawbar_pull": force @ bench.heading,
        "lateral_force": force @ bench.axle,
        "vertical_force": force[2],
        "torque": -(moment @ bench.axle),
        "sinkage": bench.bed.surface_height + r - hub[2],
        "tread_sinkage": bench.bed.surface_height - float(nodes[bench.tread_nodes, 2].min()),
        "slip": longitudinal_slip(vx, spin, r),
        "slip_angle": slip_angle_deg(vel, bench.heading, bench.axle),
        "tread_slip": longitudinal_slip(vx_tread, tread_omega, r),
        "tread_slip_angle": slip_angle_deg(vel, tread.heading, tread.axle),
        "wind_up": tread.wind_up,
        "tread_omega": tread_omega,
        "slip_speed": vx_tread,
        "load": s.load if phase != "lower" else 0.0,
        "omega": spin,
        "travel": hub[0] + loop.shift - bench.start_x,
        "hub_x": hub[0], "hub_y": hub[1], "hub_z": hub[2],
        "contacts": bench.contact.contact_count,
    }
