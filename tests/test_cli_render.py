"""The command line (bed preparation, render, input errors of the testbed run) and the offscreen render."""

import numpy as np
import pytest

from wheelsoil.cases.cli import EXIT_INPUT, EXIT_OK, main
from wheelsoil.cases.render import render_particles


def test_render_is_non_blank_and_sized(tmp_path):
    import matplotlib.image as mpimg

    rng = np.random.default_rng(0)
    x = rng.uniform(0, 0.1, (200, 3))
    path = render_particles(x, np.full(200, 0.005), tmp_path / "p.png", size=(320, 240),
                            box=((0, 0, 0), (0.1, 0.1, 0.1)))
    img = mpimg.imread(path)
    assert img.shape[:2] == (240, 320)
    rgb = img[..., :3]
    # white background plus coloured particles: many distinct colours, a substantial non-white area
    non_white = np.any(rgb < 0.95, axis=2).mean()
    assert 0.02 < non_white < 0.9
    assert len(np.unique((rgb * 255).astype(int).reshape(-1, 3), axis=0)) > 50


def test_cli_prepare_bed_and_render(tmp_path, monkeypatch):
    monkeypatch.setenv("WHEELSOIL_CACHE", str(tmp_path / "cache"))
    bed = tmp_path / "out" / "bed.h5"
    rc = main(["prepare-bed", "--length", "0.16", "--width", "0.1", "--depth", "0.06", "--dmin", "0.016", "--dmax", "0.024",
               "--walled", "--out", str(bed)])
    assert rc == EXIT_OK
    assert bed.stat().st_size > 0
    assert main(["render", str(bed), "--size", "320", "240"]) == EXIT_OK
    assert bed.with_suffix(".png").stat().st_size > 0


def test_cli_run_rejects_bad_testbed_input(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "--slip", "1.5", "--out", str(out)]) == EXIT_INPUT
    assert "test.slip = 1.5: Input should be less than 1 (allowed slip >= -1 and < 1)" in capsys.readouterr().err
    assert main(["testbed", "no-such-case", "--out", str(out)]) == EXIT_INPUT
    assert "no-such-case: no case file or preset of that name; presets: cmu-grouser, cmu-smooth, mini-1g-steer" in capsys.readouterr().err
    assert main(["run", "smoke-moon-steer", "--load", "0", "--out", str(out)]) == EXIT_INPUT
    assert not out.exists()


def test_cli_bad_input_exit_code(tmp_path, capsys):
    rc = main(["prepare-bed", "--length", "-2", "--out", str(tmp_path / "b.h5")])
    assert rc == EXIT_INPUT
    assert "bed length = -2.0" in capsys.readouterr().err
    assert not (tmp_path / "b.h5").exists()
    with pytest.raises(SystemExit) as exc:
        main(["prepare-bed", "--gravity", "jupiter"])
    assert exc.value.code == 2
    assert main(["render", str(tmp_path / "missing.h5")]) == EXIT_INPUT


def test_case_check_refuses_a_bed_past_the_machine_memory(capsys):
    assert main(["case", "check", "smoke-1g-steer", "--set", "soil.diameter_min=0.001",
                 "--set", "soil.diameter_max=0.0015"]) == EXIT_INPUT
    err = capsys.readouterr().err
    assert "soil.diameter_min" in err and "GiB" in err and "Traceback" not in err
