"""wheelsoil's smoke steering run: seed 004's wheel, soil, contact and rig (:mod:`.seed004`) in a small, coarse
set-up that runs to a steady state in minutes on two cores (the README's main job, preset ``smoke-1g-steer``).

Every default of the case schema, of the solver's specs (``BedSpec``, ``TestbedSpec``) and of the command line
comes from here. What differs from seed 004 is ours and says why: a 2.0 x 0.9 x 0.2 m periodic bin (a moving
soil patch) of 25--37.5 mm particles (about 12,000 instead of 388,026) and a 0.05 m wheel mesh (3,456 elements
instead of about 30,000); the README states the known error of that scale (the convergence study).
"""

from . import seed004

# ---- [soil]: the bin and its particles
SOIL = dict(
    length=2.0,           # m, along the travel
    width=0.9,            # m
    depth=0.2,            # m, levelled bed
    diameter_min=0.025,   # m (seed 004: 16 mm)
    diameter_max=0.0375,  # m (seed 004: 24 mm)
    periodic=True,        # moving soil patch: the bin need not grow with the drive
    max_settle_time=10.0,  # s, give up preparing the bed after this much settling
)
SOIL_MATERIAL = seed004.SOIL
SOIL_SOIL = seed004.SOIL_SOIL
#: A name of ``wheelsoil.gravity.GRAVITY_PRESETS`` (Earth; the Moon cases say "moon").
GRAVITY = "earth"
#: Random seed of the bed's radii and packing.
SEED = 0

# ---- [wheel]
WHEEL_PRESET = "lunar-rover"
WHEEL = dict(
    element_size=0.05,  # m (the preset's own: 0.018 m)
    damping=10.0,       # 1/s, mass-proportional structural damping relative to the hub
    rigid=False,
)

# ---- [contact]: soil--wheel (seed 004's soil--steel)
CONTACT = seed004.SOIL_STEEL

# ---- [test]: what the rig does
TEST = dict(
    slip=0.3,
    slip_angle=10.0,       # deg
    load=seed004.LOAD_EARTH,
    angular_velocity=seed004.ANGULAR_VELOCITY,
    lowering_speed=0.3,    # m/s
    settle_time=0.1,       # s
    spin_up_time=0.05,     # s
    drive_time=4.0,        # s, the longest drive (the run stops once steady)
    stop_when_steady=True,
    windup="controller",
    windup_gain=4.0,
    windup_filter=0.04,    # s
    max_wind_up=0.6,       # rad
)

# ---- [output]: sampling and the steady-state verdict
OUTPUT = dict(
    sample_interval=0.005,   # s
    average_time=1.0,        # s
    steady_tolerance=0.1,
    slip_tolerance=0.03,
    steady_checks=2,
    steady_drift_confidence=0.0,  # standard errors of a drift added before it is held to the tolerance
    frame_interval=0.05,     # s
    checkpoint_interval=0.25,  # s
    render=True,
)
