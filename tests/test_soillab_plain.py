"""The virtual soil lab's plain parts: Bekker fits (against exact data and the CMU data README's published fits),
bearing capacity (against Meyerhof's and Terzaghi's tables), the measured-data reader and the specs' refusals."""

import math
import os

import numpy as np
import pytest

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.soillab import (PlateSpec, ReposeSpec, ShearSpec, WheelPressSpec, circular_footing, fit_k_at_n,
                               fit_power_law, load_plate_curves, load_wheel_curves, mean_curve, split_k)
from wheelsoil.soillab.shapes import disc, square_ring
from wheelsoil.soillab.specs import (MAX_OVERLAP_FRACTION, check_plate_fits, check_resolution, inertial_number,
                                     max_normal_stress, mean_and_spread)


# ---------------------------------------------------------------------- Bekker
@pytest.mark.parametrize("k,n", [(8e6, 1.44), (2e5, 0.6), (5e7, 1.9)])
def test_power_law_recovers_exact_parameters(k, n):
    z = np.linspace(1e-3, 0.03, 40)
    fit = fit_power_law(z, k * z**n)
    assert fit.k == pytest.approx(k, rel=1e-6)
    assert fit.n == pytest.approx(n, rel=1e-7)
    assert fit.rms < 1e-6 * k * 0.03**n


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_power_law_standard_errors_cover_the_truth(seed):
    """With noise the fitted k and n lie within four of their standard errors of the truth."""
    rng = np.random.default_rng(seed)
    z = np.linspace(1e-3, 0.03, 200)
    p = 8e6 * z**1.44 * (1 + 0.05 * rng.standard_normal(z.size))
    fit = fit_power_law(z, p)
    assert abs(fit.n - 1.44) < 4 * fit.n_se
    assert abs(fit.k - 8e6) < 4 * fit.k_se


def test_k_at_given_n_is_the_least_squares_closed_form():
    z = np.linspace(1e-3, 0.02, 30)
    p = 3e6 * z**1.2
    k, se = fit_k_at_n(z, p, 1.2)
    assert k == pytest.approx(3e6, rel=1e-12)
    assert se < 1e-6 * k


def test_split_recovers_kc_and_kphi():
    """k = k_c / b + k_phi: two plate radii give both exactly; four points give standard errors."""
    k_c, k_phi = 2.0e5, 6.0e6
    b = np.array([0.03, 0.05])
    s = split_k(b, k_c / b + k_phi, 1.4)
    assert s.k_c == pytest.approx(k_c, rel=1e-10) and s.k_phi == pytest.approx(k_phi, rel=1e-10)
    b4 = np.array([0.03, 0.03, 0.05, 0.05])
    s4 = split_k(b4, k_c / b4 + k_phi + np.array([1e4, -1e4, 1e4, -1e4]), 1.4)
    assert s4.k_c == pytest.approx(k_c, rel=1e-9) and s4.k_c_se > 0 and s4.k_phi_se > 0
    with pytest.raises(WheelsoilInputError, match="two sizes"):
        split_k([0.03, 0.03], [1.0, 2.0], 1.4)


def test_power_law_needs_three_points():
    with pytest.raises(WheelsoilInputError, match="at least 3"):
        fit_power_law([0.0, 1e-3, 2e-3], [0.0, 1.0, 2.0])


# ---------------------------------------------------------------------- bearing capacity
def test_meyerhof_factors_match_his_table():
    """Meyerhof (1963) at phi = 30 deg: N_q = 18.40, N_c = 30.14, N_gamma = 15.67; at 20 deg: 6.40, 14.83, 2.87."""
    for phi, (n_q, n_c, n_g) in ((30.0, (18.40, 30.14, 15.67)), (20.0, (6.40, 14.83, 2.87))):
        cap = circular_footing(0.1, 0.0, phi, 0.0, 1.3e4)
        assert (cap.n_q, cap.n_c, cap.n_gamma) == pytest.approx((n_q, n_c, n_g), abs=0.01)


def test_surface_footing_on_sand_is_the_self_weight_term():
    """c = 0, D = 0: q_u = 0.5 gamma B N_gamma s_gamma (Meyerhof) and 0.3 gamma B N_gamma (Terzaghi's circle)."""
    cap = circular_footing(0.1, 0.0, 30.0, 0.0, 1.3e4)
    k_p = math.tan(math.radians(60.0)) ** 2
    assert cap.meyerhof == pytest.approx(0.5 * 1.3e4 * 0.1 * cap.n_gamma * (1 + 0.1 * k_p), rel=1e-12)
    from wheelsoil.validation.terramechanics import bearing_capacity_factors

    n_gamma_t, _, _ = bearing_capacity_factors(30.0)  # Terzaghi's factors as seed 003 eq. 18 (Coduto)
    assert cap.terzaghi == pytest.approx(0.3 * 1.3e4 * 0.1 * n_gamma_t, rel=1e-12)


def test_a_long_rectangle_is_meyerhofs_strip_and_a_square_his_circle():
    """Meyerhof's rectangle: as L/B grows the shape factors go to 1, leaving the strip's 0.5 gamma B N_gamma on the
    surface with his tabulated N_gamma (15.67 at 30 deg); at B = L it is his circle of diameter B (the same shape
    factors), in either order of the sides."""
    from wheelsoil.bearing import rectangular_footing

    assert rectangular_footing(1.0, 1e9, 0.0, 30.0, 0.0, 1e4) == pytest.approx(0.5 * 1e4 * 1.0 * 15.67, rel=1e-3)
    for depth in (0.0, 0.03):
        square = rectangular_footing(0.1, 0.1, depth, 35.0, 200.0, 1.3e4)
        assert square == pytest.approx(circular_footing(0.1, depth, 35.0, 200.0, 1.3e4).meyerhof, rel=1e-12)
    assert rectangular_footing(0.05, 0.11, 0.03, 35.0, 0.0, 1e4) == rectangular_footing(0.11, 0.05, 0.03, 35.0, 0.0, 1e4)
    with pytest.raises(WheelsoilInputError, match="footing sizes"):
        rectangular_footing(0.0, 0.1, 0.0, 30.0, 0.0, 1e4)


def test_bearing_capacity_refuses_angles_outside_its_range():
    with pytest.raises(WheelsoilInputError, match="friction_angle = 5"):
        circular_footing(0.1, 0.0, 5.0, 0.0, 1e4)


# ---------------------------------------------------------------------- measured data
def test_cmu_plate_fits_match_the_data_readme(measured_dir):
    """The data README's per-trial Bekker fits (on every windowed sample; refitting the downsampled rows moves n by
    < 0.05 and k by < 20 %): median n and k per box and plate, and p at 10 mm mean +- sd."""
    path = os.path.join(measured_dir, "cmu_3d_terramechanics", "force_displacement", "plate_sinkage.csv")
    curves = load_plate_curves(path)
    assert len(curves) == 12
    readme = {("large", 0.06): (8444e3, 1.546, 7.71e3), ("large", 0.1): (10310e3, 1.436, 13.64e3),
              ("small", 0.06): (5695e3, 1.456, 7.65e3), ("small", 0.1): (8003e3, 1.409, 13.35e3)}
    for (box, d), (k, n, p10) in readme.items():
        group = [c for c in curves if c.box == box and c.size == d]
        assert len(group) == 3
        fits = [fit_power_law(c.sinkage, c.pressure) for c in group]
        assert np.median([f.n for f in fits]) == pytest.approx(n, abs=0.05)
        assert np.median([f.k for f in fits]) == pytest.approx(k, rel=0.2)
        mean, _, count = mean_curve(group, np.array([0.01]))
        assert count[0] == 3
        assert mean[0] / group[0].area == pytest.approx(p10, rel=0.04)


def test_cmu_wheel_curves_load(measured_dir):
    path = os.path.join(measured_dir, "cmu_3d_terramechanics", "force_displacement", "wheel_sinkage.csv")
    curves = load_wheel_curves(path)
    assert {c.wheel for c in curves} == {"smooth", "grouser"}
    assert sum(c.box == "small" for c in curves) == 12 and sum(c.box == "large" for c in curves) == 6
    with pytest.raises(WheelsoilInputError, match="no plate area"):
        _ = curves[0].pressure


def test_measured_file_without_columns_is_refused(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("box,plate_diameter_mm,trial,sinkage_mm\nlarge,60,1,1.0\n")
    with pytest.raises(WheelsoilInputError, match=r"lacks the column\(s\) \['force_N'\]"):
        load_plate_curves(bad)
    with pytest.raises(WheelsoilInputError, match="does not exist"):
        load_plate_curves(tmp_path / "none.csv")


# ---------------------------------------------------------------------- specs and limits
@pytest.mark.parametrize("make,match", [
    (lambda: PlateSpec(diameter=-0.1), "plate diameter = -0.1"),
    (lambda: PlateSpec(speed=2.0), "plate speed = 2.0"),
    (lambda: PlateSpec(sample_interval=0.02), "sample_interval"),
    (lambda: WheelPressSpec(wheel="spiked"), "wheel = 'spiked'"),
    (lambda: ShearSpec(normal_stresses=(1e3, 2e3)), "at least three"),
    (lambda: ShearSpec(normal_stresses=(1e3, 2e3, -1.0)), "normal_stresses"),
    (lambda: ShearSpec(max_displacement=0.05), "quarter of the side"),
    (lambda: ReposeSpec(seeds=(1, 1)), "distinct seeds"),
    (lambda: ReposeSpec(height=0.3), "exceeds its length"),
])
def test_bad_specs_name_key_and_value(make, match):
    with pytest.raises(WheelsoilInputError, match=match):
        make()


def test_fit_and_resolution_limits():
    with pytest.raises(WheelsoilInputError, match="wider than the lab's box"):
        check_plate_fits("plate diameter", 0.4, 0.3, 0.3)
    with pytest.raises(WheelsoilInputError, match="box side >= 0.45"):
        check_plate_fits("plate diameter", 0.15, 0.3, 0.3)
    check_plate_fits("plate diameter", 0.1, 0.3, 0.3)
    with pytest.raises(WheelsoilInputError, match="particles of at most 0.01 m"):
        check_resolution("plate diameter", 0.06, 0.012)


def test_stress_limit_gives_the_stated_overlap():
    """At the limit stress, Rumpf's mean contact force gives a Hertz overlap of exactly MAX_OVERLAP_FRACTION of the
    radius (Johnson eq. 4.22 for two equal spheres)."""
    e, nu, d = 5e7, 0.3, 0.008
    sigma = max_normal_stress(e, nu, d)
    force = sigma * math.pi * d**2 / (0.58 * 6.0)
    e_star = e / (2 * (1 - nu**2))
    delta = (3 * force / (4 * e_star * math.sqrt(d / 4))) ** (2 / 3)
    assert delta == pytest.approx(MAX_OVERLAP_FRACTION * d / 2, rel=1e-12)
    assert inertial_number(1.0, 0.01, 1e4, 2500.0) == pytest.approx(0.01 / 2.0, rel=1e-12)


def test_plate_and_box_meshes():
    """The disc covers the regular polygon's area with every normal down; the ring's walls enclose the box."""
    x, t = disc(0.05, 6)
    cross = np.cross(x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]])
    assert np.all(cross[:, 2] < 0)
    n_outer = 36
    polygon = 0.5 * n_outer * 0.05**2 * math.sin(2 * math.pi / n_outer)
    assert 0.5 * np.abs(cross[:, 2]).sum() == pytest.approx(polygon, rel=1e-12)
    assert len(t) == sum(6 * (2 * k - 1) for k in range(1, 7))
    nodes, tri = square_ring(0.1, 0.0, 0.05, 4, flange=0.02)
    assert nodes[:, 0].min() == pytest.approx(-0.02) and nodes[:, 0].max() == pytest.approx(0.12)
    walls = np.cross(nodes[tri[:, 1]] - nodes[tri[:, 0]], nodes[tri[:, 2]] - nodes[tri[:, 0]])
    centroid = nodes[tri].mean(axis=1)
    vertical = np.abs(walls[:, 2]) < 1e-15
    inward = np.einsum("ij,ij->i", walls[vertical], np.array([0.05, 0.05, 0.0]) - centroid[vertical])
    assert np.all(inward > 0)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_mean_and_spread_over_seeds_is_the_sample_mean_and_deviation(seed):
    values = np.random.default_rng(seed).normal(20.0, 2.0, size=3 + seed)
    mean, spread = mean_and_spread(iter(values))
    assert mean == pytest.approx(values.mean(), rel=1e-12)
    assert spread == pytest.approx(values.std(ddof=1), rel=1e-12)
    one = mean_and_spread([values[0]])
    assert one[0] == values[0] and np.isnan(one[1])


def test_calibration_objective_on_known_curves():
    """Equal curves and the sand's repose score 0; a DEM twice too soft everywhere scores (ln 2)^2 over the points
    both curves reach; 4 deg of repose error adds (4 / 2)^2; the best candidate is the least objective."""
    from wheelsoil.soillab.objective import SINKAGES, best, score

    z = np.array(SINKAGES)
    measured = 1e6 * z ** 1.4
    measured_short = measured.copy()
    measured_short[-1] = np.nan  # the 100 mm plates end before 25 mm
    plates = lambda f: {"0.06": {"simulated_Pa": list(f * measured), "measured_Pa": list(measured)},  # noqa: E731
                        "0.1": {"simulated_Pa": list(f * measured), "measured_Pa": list(measured_short)}}
    exact = score({"plates": plates(1.0), "repose_deg": 29.0})
    assert exact["objective"] == pytest.approx(0.0, abs=1e-15) and exact["plate_points"] == 9
    soft = score({"plates": plates(0.5), "repose_deg": 25.0})
    assert soft["plate_log_mse"] == pytest.approx(np.log(2.0) ** 2)
    assert soft["objective"] == pytest.approx(np.log(2.0) ** 2 + 4.0)
    chosen = best([{"plates": plates(0.5), "repose_deg": 29.0, "id": 1}, {"plates": plates(0.9), "repose_deg": 28.0,
                                                                            "id": 2}])
    assert chosen["id"] == 2


def test_cmu_sand_is_the_calibrations_choice():
    """wheelsoil.parameters.cmu_sand is what the stored calibration chooses by its rule (docs/soillab_calibration.py):
    the EPSD candidates, grid and verified surface minimum, scored again from their stored measurements
    (soillab.objective.score), the least objective; the density is the one its bed was poured at."""
    import json
    from pathlib import Path

    from wheelsoil.parameters import cmu_sand
    from wheelsoil.soillab.objective import best

    docs = Path(__file__).resolve().parent.parent / "docs" / "soillab"
    rows = [json.loads(p.read_text()) for folder in ("calibration-epsd", "calibration-epsd-surface")
            for p in sorted((docs / folder / "candidates").glob("*.json"))]
    assert len(rows) == 10 and all(r["rolling_model"] == "epsd" for r in rows)
    chosen = best(rows)
    pair, material = cmu_sand.PARTICLE_PAIR, cmu_sand.PARTICLE_MATERIAL
    assert (chosen["friction"], chosen["rolling_friction"], chosen["rolling_model"]) == (
        pair.static_friction, pair.rolling_friction, pair.rolling_model)
    assert chosen["density"] == material.density
    assert chosen["objective"] == pytest.approx(cmu_sand.CALIBRATION["objective"], abs=5e-4)
    assert chosen["repose_deg"] == pytest.approx(cmu_sand.CALIBRATION["repose_deg"], abs=0.05)


def test_cmu_sand_is_the_wide_box_calibrations_choice_too():
    """The calibration run again with every plate in the wide box (design epsd-box: the nine EPSD grid candidates and
    the earlier surface minimum, docs/soillab/calibration-epsd-box), scored again from its stored curves, chooses the
    same particles: cmu_sand's friction, rolling friction, law and density, with the objective its file records."""
    import json
    from pathlib import Path

    from wheelsoil.parameters import cmu_sand
    from wheelsoil.soillab.objective import best

    folder = Path(__file__).resolve().parent.parent / "docs" / "soillab" / "calibration-epsd-box" / "candidates"
    rows = [json.loads(p.read_text()) for p in sorted(folder.glob("*.json"))]
    assert len(rows) == 10 and all(r["plate_box_m"] == [0.6, 0.6, 0.12] for r in rows)
    chosen = best(rows)
    pair, material = cmu_sand.PARTICLE_PAIR, cmu_sand.PARTICLE_MATERIAL
    assert (chosen["friction"], chosen["rolling_friction"], chosen["rolling_model"], chosen["density"]) == (
        pair.static_friction, pair.rolling_friction, pair.rolling_model, material.density)
    assert chosen["objective"] == pytest.approx(cmu_sand.WIDE_BOX_CALIBRATION["objective"], abs=5e-4)
