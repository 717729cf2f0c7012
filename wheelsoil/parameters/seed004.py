"""Seed 004: DEM--FEM simulation of the steering performance of the flexible metal wheel of a staffed lunar rover
(``../shared/seeds/004_*.txt``), Table 1 (lunar soil simulant, after Zhu et al. 2023), Table 2 (wheel--soil
system) and sec. 2.3 (the test conditions).

What the paper does not give is marked "ours" (the wheel's tread, spoke and grouser sizes: it shows no drawing).
"""

from wheelsoil.gravity import EARTH_GRAVITY, MOON_GRAVITY
from wheelsoil.material import Material, PairProperties

CITATION = ("seed 004: DEM-FEM simulation of steering performance of flexible metal wheel for staffed lunar "
            "rover, Tables 1-2, sec. 2.3")

# ---- Table 1: lunar soil simulant
#: Particle density 3200 kg/m^3, Young's modulus 50 MPa, Poisson's ratio 0.3.
SOIL = Material("lunar soil simulant", youngs_modulus=50e6, poisson_ratio=0.3, density=3200.0)
#: Soil--soil: restitution 0.5, static friction 0.42, rolling friction 0.11.
SOIL_SOIL = PairProperties(restitution=0.5, static_friction=0.42, rolling_friction=0.11)
#: Soil--steel (the wheel and the bin): restitution 0.5, static friction 0.39, rolling friction 0.15.
SOIL_STEEL = PairProperties(restitution=0.5, static_friction=0.39, rolling_friction=0.15)

#: The bin's walls: structural steel (ours: the paper gives only the soil--steel pair).
BIN_WALLS = Material("steel", youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)

# ---- Table 2: the wheel--soil system
#: FEM elements: E = 800 MPa, nu = 0.288, rho = 7850 kg/m^3.
WHEEL_MATERIAL = Material("seed-004 wheel material", youngs_modulus=800e6, poisson_ratio=0.288, density=7850.0)
WHEEL_RADIUS = 0.6  # m
WHEEL_WIDTH = 0.5  # m
#: Soil bin 3.5 m long, 1.0 m wide, 0.4 m high (sec. 2.3's text says 2.0 m wide; Table 2's 1.0 m is used).
BIN_LENGTH, BIN_WIDTH, BIN_DEPTH = 3.5, 1.0, 0.4
#: Particle diameters 16--24 mm (388,026 particles in the bin).
PARTICLE_DIAMETER_MIN, PARTICLE_DIAMETER_MAX = 0.016, 0.024
PARTICLES = 388_026
#: Paper-size mesh: 29,644 FEM elements (ours: element_size 0.018 m gives about 26,000-30,000).
FEM_ELEMENTS = 29_644

# ---- sec. 2.3: the test conditions
#: Vertical loads [N]: 3000 N at Earth gravity, 500 N at the Moon's (and 3750 N in Table 2).
LOAD_EARTH, LOAD_MOON = 3000.0, 500.0
GRAVITY_EARTH, GRAVITY_MOON = EARTH_GRAVITY, MOON_GRAVITY
#: Wheel speed r omega = 0.6 m/s, so omega = 1 rad/s for r = 0.6 m.
TRAVEL_SPEED = 0.6  # m/s
ANGULAR_VELOCITY = TRAVEL_SPEED / WHEEL_RADIUS  # rad/s
#: Slip ratios 10--60 % and steering angles 5--20 deg of the paper's figures.
SLIPS = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6)
STEERING_ANGLES = (5.0, 10.0, 15.0, 20.0)

#: The lunar-rover wheel (r = 0.6 m, b = 0.5 m, Table 2 material). Tread, spoke and grouser sizes are ours (two
#: side rows of 12 bowed spokes, 24 chevron grousers); element_size 0.018 m gives a mesh of the paper's size.
#: Keyword arguments of ``wheelsoil.flexwheel.geometry.WheelGeometry`` (spoke rows as (y_min, y_max, angle)).
LUNAR_ROVER_WHEEL = dict(
    name="lunar-rover",
    radius=WHEEL_RADIUS,
    width=WHEEL_WIDTH,
    tread_thickness=0.005,
    hub_radius=0.15,
    spokes_per_row=12,
    spoke_thickness=0.010,
    spoke_rows=((-0.5, -0.3, 0.0), (0.3, 0.5, 0.0)),
    spoke_bow=0.1,
    grouser_count=24,
    grouser_height=0.02,
    grouser_thickness=0.004,
    grouser_angle=7.5,
    material=WHEEL_MATERIAL,
    element_size=0.018,
    hub_mass=20.0,
    nominal_load=LOAD_EARTH,
)
