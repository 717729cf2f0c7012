"""The ExoMars-like flexible wheel of seeds 000 (periodic stiffness of a flexible wheel, r = 142.5 mm, b = 120 mm,
12 grousers of 12.5 mm; three flexible loops on each side plus three inner loops rotated by 60 deg: six virtual
spokes, six stiffness peaks per turn) and 001 (flexible against rigid wheels; radial point-load stiffness of the
ExoMars wheel about 13.2 kN/m).

Sheet thicknesses are ours, chosen so that the radial point-load stiffness comes out near seed 001's 13.2 kN/m.
"""

from wheelsoil.material import Material

CITATION = "seeds 000/001: ExoMars flexible wheel (periodic stiffness; flexible against rigid)"

#: Spring steel of the sheet-metal rim and flexures.
SPRING_STEEL = Material("spring steel", youngs_modulus=200e9, poisson_ratio=0.29, density=7850.0)
#: Radial point-load stiffness of the ExoMars wheel quoted in seed 001 [N/m].
RADIAL_STIFFNESS = 13.2e3
#: Nominal wheel load [N].
NOMINAL_LOAD = 172.0

#: Keyword arguments of ``wheelsoil.flexwheel.geometry.WheelGeometry`` (spoke rows as (y_min, y_max, angle)).
EXOMARS_WHEEL = dict(
    name="exomars",
    radius=0.1425,
    width=0.12,
    tread_thickness=0.0008,
    hub_radius=0.045,
    spokes_per_row=3,
    spoke_thickness=0.0005,
    spoke_rows=((-0.5, -0.25, 0.0), (0.25, 0.5, 0.0), (-0.125, 0.125, 60.0)),
    spoke_bow=0.3,
    grouser_count=12,
    grouser_height=0.0125,
    grouser_thickness=0.0010,
    grouser_angle=15.0,
    material=SPRING_STEEL,
    element_size=0.006,
    hub_mass=1.0,
    nominal_load=NOMINAL_LOAD,
)
