"""Passive earth pressure beside the rim's stress integrals (vectorised NumPy): the soil bulldozed ahead of a sunken
wheel and the grousers' thrust (the forms :func:`.terramechanics.contact_forces` adds to its integrals, each scaled by
its :class:`~.terramechanics.SoilParameters` factor). ``soil`` and ``wheel`` are
:class:`~.terramechanics.SoilParameters` and :class:`~.terramechanics.RigidWheel`, as in :mod:`.side_forces`."""

import numpy as np

from .side_forces import bearing_capacity_factors, soil_state


def bulldozing_force(soil, wheel, sinkage, gravity, cohesion=None, density=None) -> np.ndarray:
    """Bulldozing resistance of the soil pushed ahead of a wheel sunk by z [N] (magnitude, against travel).

    Bekker's passive-pressure form as Wong (Theory of Ground Vehicles, ch. 2) and Ishigami et al. (2008)
    give it, after Hegedus (1960; seed 002 ref. 7, named in seed 003 sec. 3.3.4)::

        R_b = b (0.67 c z K_pc + 0.5 gamma z^2 K_pgamma)
        K_pc = (N_c - tan phi) cos^2 phi,    K_pgamma = (2 N_gamma / tan phi + 1) cos^2 phi

    with the modified Terzaghi factors of seed 003 eq. 18 (:func:`bearing_capacity_factors`) and gamma =
    rho g. ``cohesion`` and ``density`` override the soil's (e.g. gravity-scaled or compacted) per condition.
    """
    z = np.asarray(sinkage, float)
    phi = np.radians(soil.friction_angle)
    n_gamma, n_c, _ = bearing_capacity_factors(soil.friction_angle)
    k_pc = (n_c - np.tan(phi)) * np.cos(phi) ** 2
    k_pgamma = (2.0 * n_gamma / np.tan(phi) + 1.0) * np.cos(phi) ** 2
    rho, c = soil_state(soil, density, cohesion)
    gamma = rho * np.asarray(gravity, float)
    return wheel.width * (0.67 * c * z * k_pc + 0.5 * gamma * z * z * k_pgamma)


def grouser_forces(soil, wheel, theta_f, theta_r, gravity, density=None, cohesion=None):
    """Grouser forces (seed 003 eq. 20, surcharge q = 0): passive earth pressure on each grouser in the soil.

    A grouser at angle theta carries F_g = b (rho g h^2 N_phi / 2 + 2 c h sqrt(N_phi)) normal to its radial
    face, i.e. tangential to the wheel: forward thrust F_g cos theta and lift F_g sin theta, acting about
    h / 3 inside the tip (seed 003: at about 2/3 of the grouser height), so the motor supplies
    F_g (r + h / 3). Averaged over one grouser pitch, count / (2 pi) grousers per radian of contact arc.
    ``density`` and ``cohesion`` override the soil's per condition. Returns (F_x, F_z, T) [N, N, N m].
    """
    h, b, r = wheel.grouser_height, wheel.width, wheel.radius
    rho, c = soil_state(soil, density, cohesion)
    n_phi = np.tan(np.pi / 4 + np.radians(soil.friction_angle) / 2) ** 2
    per_grouser = b * (0.5 * rho * np.asarray(gravity, float) * h * h * n_phi + 2.0 * c * h * np.sqrt(n_phi))
    per_radian = per_grouser * wheel.grouser_count / (2.0 * np.pi)
    fx = per_radian * (np.sin(theta_f) - np.sin(theta_r))  # int cos(theta) d theta over the contact
    fz = per_radian * (np.cos(theta_r) - np.cos(theta_f))  # int sin(theta) d theta
    torque = per_radian * (theta_f - theta_r) * (r + h / 3.0)
    return fx, fz, torque
