"""The torsion load test against the closed form of a spoked wheel (straight spokes clamped at hub and rim),
its mesh convergence with shell spokes, linear against corotational at small twist, both directions, and the
static Newton solver it uses."""

import math
from dataclasses import replace

import numpy as np
import pytest

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.flexwheel.geometry import LUNAR_ROVER, SpokeRow, WheelGeometry
from wheelsoil.material import Material
from wheelsoil.flexwheel.torsion import spoked_wheel_torsion_stiffness, torsion_test

#: nu = 0, so that a plate strip in cylindrical bending has the beam's rigidity E b t^3 / 12 exactly.
STEEL_NU0 = Material("steel, nu = 0", youngs_modulus=200e9, poisson_ratio=0.0, density=7850.0)
#: Six straight (unbowed) spokes across the whole width: the closed form's wheel.
SPOKED = WheelGeometry(name="spoked", radius=0.3, width=0.1, tread_thickness=0.004, hub_radius=0.06,
                       spokes_per_row=6, spoke_thickness=0.003, spoke_rows=(SpokeRow(-0.5, 0.5, 0.0),),
                       spoke_bow=0.0, spoke_model="beam", material=STEEL_NU0, element_size=0.025)


def closed_form(g: WheelGeometry) -> float:
    ei = g.material.youngs_modulus * g.width * g.spoke_thickness**3 / 12.0
    return spoked_wheel_torsion_stiffness(g.spokes_per_row, ei, g.hub_radius, g.tread_mid_radius)


def test_closed_form_limits():
    # a spoke from the axis (a = 0) is a cantilever-guided beam: k = 4 EI / L per spoke
    assert spoked_wheel_torsion_stiffness(1, 2.0, 0.0, 0.5) == pytest.approx(4 * 2.0 / 0.5)
    assert spoked_wheel_torsion_stiffness(3, 2.0, 0.1, 0.5) == pytest.approx(3 * 4 * 2.0 / 0.4 * (1 + 0.75 + 3 / 16))
    with pytest.raises(WheelsoilInputError):
        spoked_wheel_torsion_stiffness(2, 1.0, 0.5, 0.4)


def test_beam_spokes_match_the_closed_form():
    """Hermite beam elements are exact for end loads: agreement to round-off, both directions."""
    curve = torsion_test(SPOKED, np.radians([-2.0, 2.0]), method="linear")
    assert curve.secant_stiffness() == pytest.approx([closed_form(SPOKED)] * 2, rel=1e-10)


def test_shell_spokes_converge_to_the_closed_form():
    """DKT plate strips in cylindrical bending: second-order convergence onto E b t^3 / 12 (nu = 0)."""
    errors = []
    for h in (0.025, 0.0125, 0.00625):
        g = replace(SPOKED, spoke_model="shell", element_size=h)
        errors.append(torsion_test(g, method="linear").stiffness / closed_form(g) - 1.0)
    errors = np.abs(errors)
    rates = np.log2(errors[:-1] / errors[1:])
    assert np.all(rates > 1.8), (errors, rates)
    assert errors[-1] < 5e-4


def test_corotational_equals_linear_at_small_twist_and_stiffens_at_large():
    lin = torsion_test(SPOKED, method="linear").stiffness
    small = torsion_test(SPOKED, np.radians([-1e-3, 1e-3]), method="corotational")
    assert small.secant_stiffness() == pytest.approx([lin, lin], rel=1e-5)
    # straight spokes clamped at both ends stretch as the hub turns: the stiffness rises with the twist,
    # the same in both directions (the wheel is symmetric)
    large = torsion_test(SPOKED, np.radians([-5.0, 5.0]), method="corotational")
    k = large.secant_stiffness()
    assert k[0] == pytest.approx(k[1], rel=1e-6) and k[0] > 1.5 * lin


def test_bowed_spokes_soften_in_their_bow_s_direction():
    """Bowed beam spokes: the corotational curve meets the linear stiffness at small twist and is lopsided at
    large twist (seed 004's wheel in miniature; the same on the preset wheel in the slow test below)."""
    g = replace(SPOKED, spoke_bow=0.15)
    lin = torsion_test(g, method="linear").stiffness
    k = torsion_test(g, np.radians([-5.0, -0.05, 0.05, 5.0]), method="corotational").secant_stiffness()
    assert k[1] == pytest.approx(lin, rel=0.01) and k[2] == pytest.approx(lin, rel=0.01)
    assert abs(k[0] - k[3]) > 0.1 * lin


@pytest.mark.slow
@pytest.mark.parametrize("hold", ["tread", "free"])
def test_bowed_spokes_make_the_wheel_lopsided(hold):
    """The seed-004 wheel (coarse): bowed spokes soften in the drive direction and stiffen against it; the
    corotational curve meets the linear stiffness at small twist."""
    g = LUNAR_ROVER.with_element_size(0.05)
    lin = torsion_test(g, method="linear", hold=hold)
    points = dict(twists=np.radians([-5.0, -0.1, 0.1, 5.0])) if hold == "tread" else \
        dict(torques=lin.stiffness * np.radians([-5.0, -0.1, 0.1, 5.0]))
    curve = torsion_test(g, method="corotational", hold=hold, **points)
    k = curve.secant_stiffness()
    assert k[1] == pytest.approx(lin.stiffness, rel=0.02) and k[2] == pytest.approx(lin.stiffness, rel=0.02)
    assert k[3] < k[2] < k[1] < k[0]  # drive direction (+) softer, the other stiffer
    if hold == "free":  # the tread's own flexibility adds to the spokes'
        assert lin.stiffness < torsion_test(g, method="linear").stiffness


@pytest.mark.slow
def test_preset_wheel_torsion_converges_with_the_mesh():
    """k_t of the seed-004 wheel at element sizes halving from 0.05 m: the changes shrink (Richardson)."""
    ks = [torsion_test(LUNAR_ROVER.with_element_size(h), method="linear").stiffness for h in (0.05, 0.025, 0.0125)]
    d1, d2 = abs(ks[1] - ks[0]), abs(ks[2] - ks[1])
    assert d2 < 0.5 * d1 and d2 < 0.02 * ks[2], ks


def test_bad_torsion_input_is_refused():
    with pytest.raises(WheelsoilInputError, match="method"):
        torsion_test(SPOKED, method="nonlinear")
    with pytest.raises(WheelsoilInputError, match="hold"):
        torsion_test(SPOKED, hold="hub")
    with pytest.raises(WheelsoilInputError, match="non-zero"):
        torsion_test(SPOKED, [0.0, 0.1])
    with pytest.raises(WheelsoilInputError, match="45 deg"):
        torsion_test(SPOKED, [math.radians(60.0)])
