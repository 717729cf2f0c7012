"""The CMU 3D-terramechanics rig's wheel: the K10-mini wheel of the measured single-wheel dataset
(``../shared/data/measured/cmu_3d_terramechanics``; robomechanics/3d-terramechanics parameter files, Pavlov, CMU,
MIT licence; see the dataset's README).
"""

CITATION = "CMU 3D-terramechanics single-wheel trials (Pavlov), K10-mini wheel"

#: Wheel radius and width [m].
RADIUS, WIDTH = 0.058, 0.05
#: Grouser height [m] of the two wheels tested: with grousers and smooth.
GROUSER_HEIGHT = {"grouser": 0.005, "smooth": 0.0}

#: Grousers of the grousered wheel. The lab's files give their height (5 mm) and the area ratio of the grouser tips
#: to the rim, 0.1 (``set_rover_params.m``: ``mu = .1``), but neither their number nor thickness. Ours: 16 grousers
#: of 2.5 mm, whose tips cover 16 x 2.5 mm / (2 pi x 63 mm) = 0.101 of the outer circumference, the lab's ratio.
GROUSER_COUNT, GROUSER_THICKNESS = 16, 0.0025
#: Rim (tread) thickness [m] of the rigid model wheel (ours: the tread of a rigid wheel only fixes where its
#: contact surface lies; the outer radius stays RADIUS).
TREAD_THICKNESS = 0.002

#: The two K10-mini wheels as keyword arguments of ``wheelsoil.flexwheel.geometry.WheelGeometry`` (ours: the spokes
#: and hub only shape the mesh inside the rim, since the CMU wheels are run rigid; element size 6 mm).
K10_MINI_WHEEL = dict(
    radius=RADIUS, width=WIDTH, tread_thickness=TREAD_THICKNESS, hub_radius=0.02, spokes_per_row=6,
    spoke_thickness=0.003, spoke_rows=((-0.5, 0.5, 0.0),), spoke_bow=0.0, element_size=0.006,
)
K10_MINI_WHEELS = {
    "smooth": dict(K10_MINI_WHEEL, name="cmu-k10-smooth"),
    "grouser": dict(K10_MINI_WHEEL, name="cmu-k10-grouser", grouser_count=GROUSER_COUNT,
                    grouser_height=GROUSER_HEIGHT["grouser"], grouser_thickness=GROUSER_THICKNESS),
}

# ---- the sand (data README, from the lab's set_soil_params.m)
#: Bulk density [kg/m^3] and angle of repose [deg] of the dry sand of every CMU test.
BULK_DENSITY, ANGLE_OF_REPOSE = 1330.0, 29.0
