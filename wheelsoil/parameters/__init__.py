"""Named parameter sets, one module each, citable: where every default of wheelsoil comes from.

* :mod:`.seed004` -- seed 004 (DEM--FEM steering of the flexible metal wheel of a staffed lunar rover), Tables
  1--2 and sec. 2.3: the lunar soil simulant, its soil--soil and soil--steel pairs, the wheel material, the
  full-scale bin and particles, the rig's loads, speed, slips and steering angles, and the lunar-rover wheel.
* :mod:`.exomars` -- the ExoMars-like flexible wheel of seeds 000/001 and its spring steel.
* :mod:`.cmu_k10` -- the CMU 3D-terramechanics rig's K10-mini wheel (the measured dataset's wheel).
* :mod:`.cmu_sand` -- the CMU sand as DEM particles, calibrated by the virtual soil lab against the sand's bulk
  density, angle of repose and plate curves (docs/soillab).
* :mod:`.soil_lab` -- the virtual soil lab's defaults: the particles a calibration starts from, its boxes and
  protocols.
* :mod:`.smoke` -- wheelsoil's own smoke steering run (seed 004's wheel, soil and rig in a small, coarse
  bin): the defaults of the case schema (:mod:`wheelsoil.cases.schema`), the solver's specs (``BedSpec``,
  ``TestbedSpec``) and the command line, so that the three layers cannot disagree.

The modules hold plain values and :class:`~wheelsoil.material.Material` / :class:`~wheelsoil.material.PairProperties`
objects, nothing that needs the solver: every layer imports them, they import nothing above
:mod:`wheelsoil.material`. Their allowed ranges live with the specs that use them (:mod:`wheelsoil.ranges`).
"""

from . import cmu_k10, cmu_sand, exomars, seed004, smoke, soil_lab

__all__ = ["cmu_k10", "cmu_sand", "exomars", "seed004", "smoke", "soil_lab"]
