"""The virtual soil laboratory on wheelsoil's DEM: the tests a soil lab runs on a sand, run on the particles, so
that a particle set can be calibrated to a measured soil before a wheel ever touches it.

Public API::

    PlateSpec, WheelPressSpec, ShearSpec, ReposeSpec      what each test does (plain, checked specs)
    poured_bed_test                                       bulk density and packing fraction of the poured bed
    repose_test                                           angle of repose (draw-down), over packings
    shear_test, mohr_coulomb                              direct shear box: peak and residual phi and c
    plate_test, wheel_press_test                          force against sinkage of a plate or a CMU wheel
    LoadCurve, load_plate_curves, load_wheel_curves       measured and simulated force-sinkage curves
    fit_power_law, fit_k_at_n, split_k                    Bekker's p = k z^n, k = k_c / b + k_phi
    circular_footing                                      Meyerhof's and Terzaghi's ultimate bearing pressure
"""

from wheelsoil.bearing import BearingCapacity, circular_footing
from .bekker import BekkerSplit, PowerFit, common_exponent, fit_k_at_n, fit_power_law, split_k
from .measured import LoadCurve, load_plate_curves, load_wheel_curves, mean_curve, plate_area
from .penetration import PenetrationResult, cmu_wheel, plate_test, wheel_press_test
from .poured import PouredBed, PouredBedResult, poured_bed_test
from .repose import ReposeResult, ReposeRun, repose_test
from .shear import MohrCoulomb, ShearResult, ShearRun, mohr_coulomb, shear_test
from . import specs
from .specs import PlateSpec, ReposeSpec, ShearSpec, WheelPressSpec

__all__ = [
    "BearingCapacity", "BekkerSplit", "LoadCurve", "PenetrationResult", "PlateSpec", "PowerFit", "ReposeSpec",
    "ShearSpec", "WheelPressSpec", "circular_footing", "cmu_wheel", "common_exponent", "fit_k_at_n",
    "fit_power_law", "load_plate_curves", "load_wheel_curves", "mean_curve", "plate_area", "plate_test",
    "split_k", "wheel_press_test", "PouredBed", "PouredBedResult", "poured_bed_test", "ReposeResult", "ReposeRun",
    "repose_test", "MohrCoulomb", "ShearResult", "ShearRun", "mohr_coulomb", "shear_test", "specs",
]
