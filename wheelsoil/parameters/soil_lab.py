"""The virtual soil lab's defaults (``wheelsoil soil-lab``, :mod:`wheelsoil.soillab`): the particles it starts a
calibration from, and its boxes, speeds and stresses, sized for the CMU sand's tests
(``../shared/data/measured/cmu_3d_terramechanics``; :mod:`.cmu_k10`).

What is ours and why:

* particles of 6.4--9.6 mm (mean 8 mm): the coarsest that put six across the 60 mm plate
  (``soillab.specs.MIN_PARTICLES_ACROSS``) -- sand grains are 0.1--1 mm, so the DEM's grains are a scaled-up sand
  whose scale error the convergence study states;
* particle density 2340 kg/m^3: the lab's poured bed of these particles packs to 0.569 (three seeds at 2300 kg/m^3
  gave 1309 +- 3 kg/m^3, ``wheelsoil soil-lab poured --density 2300``), so 0.569 x 2340 = 1330 kg/m^3, the sand's
  bulk density (quartz grains are 2650 kg/m^3 and pack looser than spheres; what loads the soil under a plate is
  the bulk unit weight);
* Young's modulus 50 MPa, Poisson's ratio 0.3, restitution 0.5: seed 004's soil (Table 1); at the lab's largest
  stress (about 45 kPa under the 100 mm plate) the mean Hertz overlap stays below 5 % of a radius;
* sliding friction 0.5, rolling friction 0.1: the starting point of the calibration, not a calibrated value;
* the plate box 0.3 x 0.3 m (three diameters of the 100 mm plate), 0.12 m deep; pressing at 30 mm/s (inertial
  number about 1e-3 at the 100 mm plate's 10 mm sinkage, quasi-static);
* direct shear box 0.12 m square, 0.06 m high (15 and 7.5 particles of 8 mm), normal stresses 5, 10, 20 kPa (the
  range under the CMU wheel: 20 N over a 50 x 30 mm patch is 13 kPa);
* draw-down box 0.16 m long, 0.08 m high, 0.06 m wide (periodic across), run-out floor 0.2 m.
"""

from wheelsoil.material import Material, PairProperties

from . import seed004

CITATION = "wheelsoil's virtual soil lab defaults (ours, sized for the CMU sand's plate and wheel tests)"

#: The particles a calibration starts from.
PARTICLE_MATERIAL = Material("soil-lab start", youngs_modulus=50e6, poisson_ratio=0.3, density=2340.0)
PARTICLE_PAIR = PairProperties(restitution=0.5, static_friction=0.5, rolling_friction=0.1)
#: The lab's walls, plates and boxes: steel against soil, seed 004's pair.
TOOL_MATERIAL = seed004.BIN_WALLS
TOOL_PAIR = seed004.SOIL_STEEL
DIAMETER_MIN, DIAMETER_MAX = 0.0064, 0.0096

#: The plate-sinkage box and the pressing protocol.
PLATE_BOX = dict(length=0.3, width=0.3, depth=0.12)
PLATE_DIAMETERS = (0.06, 0.1)
PRESS = dict(speed=0.03, max_sinkage=0.03, sample_interval=0.0005)
#: The wheel-sinkage box (the K10-mini wheel: r = 0.058 m, b = 0.05 m, 0.126 m across its grousers; the walls one
#: diameter away along the travel and one width across it).
WHEEL_BOX = dict(length=0.4, width=0.2, depth=0.12)
#: Direct shear box and normal stresses [Pa].
SHEAR = dict(side=0.12, height=0.06, normal_stresses=(5e3, 10e3, 20e3), speed=0.02, max_displacement=0.015,
             sample_interval=0.0003, consolidation_time=0.15)
#: Draw-down (ledge) box of the angle of repose.
REPOSE = dict(length=0.16, width=0.06, height=0.08, run_out=0.2, max_time=3.0, seeds=(0, 1, 2))
#: Seeds of the poured beds.
POURED_SEEDS = (0, 1, 2)
