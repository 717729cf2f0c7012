"""The CMU lab's own terramechanics model's parameters for the K10-mini wheels in its sand, as the lab published them
(robomechanics/3d-terramechanics, ``terramechanics/``; Copyright 2022 Catherine Pavlov, Carnegie Mellon University,
MIT licence). Used by :mod:`wheelsoil.validation.cmu_lab_model`, the port of that model, so that wheelsoil's
validation can be held against the authors' hand-built model on the same trials.

SI units here (the lab's files use kN, kPa and kN/m^(n+2)); the conversions are stated beside each value.
"""

CITATION = ("Pavlov, CMU robomechanics/3d-terramechanics (MIT): terramechanics/set_soil_params.m, set_rover_params.m, "
            "trench_off_grouser.mat, trench_off_smooth_new.mat")

#: Wheels (``set_rover_params.m``, 'K10_mini_grouser' / 'K10_mini_smooth'): radius r and width b [m], grouser height
#: h_g [m] (shearing radius r_s = r + h_g), area ratio mu of the grouser tips [-] (the normal stress mixes the rim's
#: and the tips' radius in this ratio; 1 on the smooth wheel, whose r_s is r).
WHEELS = {
    "grouser": {"radius": 0.058, "width": 0.05, "grouser_height": 0.005, "tip_area_ratio": 0.1},
    "smooth": {"radius": 0.058, "width": 0.05, "grouser_height": 0.0, "tip_area_ratio": 1.0},
}

#: The sand (``set_soil_params.m``, hand tuned per wheel): sinkage modulus k [N/m^(n+2)] (8e3 kN/m^(n+2)), specific
#: weight [N/m^3] (1.33e3 kg/m^3 x 9.8 m/s^2), friction angle phi [deg] (the angle of repose, 29 deg), cohesion c [Pa]
#: (1.0 kPa), shear modulus K [m], and the sinkage exponent N = n0 + n1 s when driving, n0 - n2 s' when skidding
#: (s the slip against the rim, s' against the travel speed, both negative when skidding).
SOILS = {
    "grouser": {"sinkage_modulus": 8e6, "specific_weight": 1.33e3 * 9.8, "friction_angle": 29.0, "cohesion": 1000.0,
                "shear_modulus": 0.021, "n0": 1.46, "n1": 0.01, "n2": 0.74},
    "smooth": {"sinkage_modulus": 8e6, "specific_weight": 1.33e3 * 9.8, "friction_angle": 29.0, "cohesion": 1000.0,
               "shear_modulus": 0.021, "n0": 1.46, "n1": 0.01, "n2": 0.55},
}

#: The stress-angle constants tuned per wheel and steering angle [deg] (the ``a0, a1, b0, b1`` of every record of
#: ``trench_off_grouser.mat`` and ``trench_off_smooth_new.mat``, the files ``generate_paper_plots.m`` runs the model
#: on; the same at every rim speed): while driving theta_m = theta_f (a0 + a1 s) and theta_r = theta_f (b0 + b1 s)
#: (``update_thetas.m``). 4 constants per angle, 28 per wheel, tuned on the trials themselves.
TUNED_ANGLES = {
    "grouser": {
        0.0: (0.2733546922889461, 0.6729029231713534, -0.6639642063751685, -0.17657550779985434),
        15.0: (0.2885459576138457, 0.65065392297571, -0.49896082715456214, -0.40765677850635396),
        30.0: (0.4681110470754031, 0.4498508009605678, -0.4371829588705479, -0.5626608810896282),
        45.0: (0.6173351543280646, 0.29847006496607303, -0.5087303757152555, -0.491206343290757),
        60.0: (0.7141290335585561, 0.21145237416772927, -0.5334345519798215, -0.46653984693090567),
        75.0: (0.796233618120201, 0.13122654278221096, -0.5317139971234683, -0.41705617437289755),
        90.0: (0.9370342271044753, 0.04988137405872774, -0.999529222573679, -0.00023990834326617264),
    },
    "smooth": {
        0.0: (0.20238774948104193, 0.7048417369376859, -0.4759941788478192, -0.00029220456910127734),
        15.0: (0.22417343615155166, 0.6968933887079799, -0.4701142884755583, -0.005278911116580837),
        30.0: (0.5697187148905489, 0.199318010610556, -0.5075959215599034, -0.00972587862266101),
        45.0: (0.629888097493009, 0.1668524555618668, -0.46051915096851254, -0.14710348730115586),
        60.0: (0.7246352911103627, 0.1324960837864007, -0.5448399878526606, -0.12699145015226673),
        75.0: (0.8073988758282912, 0.11187381666198301, -0.6296939491244271, -0.15773788821218962),
        90.0: (0.905698612201502, 0.06304499959496848, -0.9996822394789769, -0.0001628238994990213),
    },
}
#: The rim speed [mm/s] of the trials whose mean load fixes the skidding wheel's stress angles at each steering angle
#: (``run_model.m``: ``Fz_data(4, k)``, the fourth rim speed of 0, 3, 5, 8, ...: "the test where s is approx 0").
SKID_REFERENCE_RIM_SPEED = 8.0
#: Number of points of the lab's integration over theta (``forces.m``: ``linspace(theta_r, theta_f, 101)``).
THETA_POINTS = 101
