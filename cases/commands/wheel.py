"""``wheelsoil wheel``: a preset wheel meshed and load-tested (radial and torsional stiffness); the tests and their
files are :mod:`wheelsoil.flexwheel.load_test_report`'s, this module reads the options, shows progress and prints."""

from __future__ import annotations

import json
import math
from pathlib import Path

from . import common


def add_parser(sub) -> None:
    """The ``wheel`` command on ``sub``."""
    p = sub.add_parser("wheel", help="mesh a preset wheel and load-test it against a flat plate",
                       description="Mesh a preset wheel (lunar-rover: seed 004; exomars: seeds 000/001; the CMU rig's "
                                   "cmu-k10-smooth and cmu-k10-grouser), write the "
                                   "mesh as VTU, and measure its radial stiffness: point-load stiffness at angles "
                                   "over one spoke pitch, and the load-deflection curve against a rigid flat plate "
                                   "over the spoke and midway between spokes; and its torsional stiffness (the hub's "
                                   "torque against its twist ahead of the tread, tread clamped and tread loaded, linear "
                                   "and corotational in both directions: how far the wheel winds up under a driving "
                                   "torque). Writes mesh.vtu, load_test.csv, load_test.png, torsion_test.csv, "
                                   "torsion_test.png and summary.json to --out.")
    p.add_argument("preset", help="wheel preset: lunar-rover, exomars, cmu-k10-smooth or cmu-k10-grouser")
    p.add_argument("--element-size", type=float, default=None, help="target element edge [m] (default: the preset's)")
    p.add_argument("--out", type=Path, default=None, help="output folder (default wheelsoil-output/wheel-<preset>)")
    p.add_argument("--points", type=int, default=6, help="load steps of the plate curve (default 6)")
    p.add_argument("--max-load-factor", type=float, default=1.5,
                   help="largest plate load as a multiple of the preset's nominal load (default 1.5)")
    p.add_argument("--torsion", choices=("corotational", "linear", "none"), default="corotational",
                   help="torsion load test: linear only, or also the corotational curves (default; minutes on a fine mesh)")
    p.add_argument("--max-twist", type=float, default=10.0,
                   help="largest twist of the corotational torsion curves [deg] (default 10)")
    p.set_defaults(func=cmd)


def _bar_progress(bar):
    """A ``progress(phase, done, total)`` that keeps one bar task per phase."""
    tasks = {}

    def update(phase, done, total):
        if phase not in tasks:
            tasks[phase] = bar.add_task(phase, total=total)
        bar.update(tasks[phase], completed=done)
    return update


def cmd(args) -> int:
    import numpy as np

    from wheelsoil.flexwheel import load_test_report as lt
    from wheelsoil.flexwheel.geometry import build_wheel_mesh, preset
    from wheelsoil.provenance import atomic_output, provenance

    console = common.console()
    geometry = preset(args.preset)
    if args.element_size is not None:
        geometry = geometry.with_element_size(args.element_size)
    lt.check_options(args.points, args.max_load_factor, None if args.torsion == "none" else args.max_twist)
    out = args.out or Path("wheelsoil-output") / f"wheel-{geometry.name}"
    mesh, hub = build_wheel_mesh(geometry)
    mesh.write(out / "mesh.vtu")
    console.print(f"[bold]{geometry.name}[/]: {mesh.n_nodes} nodes, {len(mesh.triangles)} facets, {len(mesh.beams)} beams, "
                  f"{len(hub)} hub nodes, structure mass {mesh.total_mass:.3g} kg -> {out / 'mesh.vtu'}")
    with common.progress(console) as bar:
        radial = lt.radial_load_test(geometry, args.points, args.max_load_factor, progress=_bar_progress(bar))
    lt.write_load_csv(radial, out / "load_test.csv")
    summary = {
        "preset": geometry.name,
        "element_size_m": geometry.element_size,
        "nodes": mesh.n_nodes,
        "facets": int(len(mesh.triangles)),
        "beams": int(len(mesh.beams)),
        "structure_mass_kg": mesh.total_mass,
        "spoke_pitch_deg": geometry.spoke_pitch,
        "point_load_stiffness_N_per_m": {f"{a:g}": k for a, k in zip(radial.angles, radial.point_stiffness)},
        "point_load_stiffness_mean_N_per_m": float(np.mean(radial.point_stiffness)),
        "nominal_load_N": geometry.nominal_load,
        "plate_secant_stiffness_at_nominal_N_per_m": radial.nominal_stiffness,
        "provenance": provenance(),
    }
    if args.torsion != "none":
        with common.progress(console) as bar:
            torsion = lt.torsion_load_test(geometry, mesh, args.max_twist, args.torsion == "corotational",
                                           progress=_bar_progress(bar))
        lt.write_torsion_csv(torsion, out / "torsion_test.csv")
        lt.plot_torsion(torsion.curves, out / "torsion_test.png", geometry.name)
        summary["torsion"] = torsion.summary()
        linear = torsion.linear
        console.print(f"torsional stiffness (linear): {linear['tread'].stiffness / 1e3:.2f} kN m/rad with the tread "
                      f"clamped, {linear['free'].stiffness / 1e3:.2f} kN m/rad with the torque on the tread; torsion "
                      f"mode of the tread (hub held) {torsion.frequency:.2f} Hz")
        for c in torsion.curves[2:]:
            k = c.secant_stiffness()
            console.print(f"  corotational, {'tread clamped' if c.hold == 'tread' else 'torque on the tread'}: "
                          + ", ".join(f"{math.degrees(t):+.1f} deg: {q / 1e3:.2f}" for t, q in zip(c.twist, k))
                          + " kN m/rad")
    with atomic_output(out / "summary.json") as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    lt.plot_load_curves(radial.curves, geometry, out / "load_test.png")
    console.print(f"point-load radial stiffness over one spoke pitch ({geometry.spoke_pitch:g} deg): "
                  + ", ".join(f"{a:g} deg: {k / 1e3:.2f} kN/m" for a, k in zip(radial.angles, radial.point_stiffness))
                  + f"; mean {np.mean(radial.point_stiffness) / 1e3:.2f} kN/m")
    for key, k in radial.nominal_stiffness.items():
        console.print(f"plate secant stiffness at the nominal {geometry.nominal_load:g} N, wheel at {key} deg: "
                      f"{k / 1e3:.2f} kN/m")
    torsion_files = f", {out / 'torsion_test.csv'}, {out / 'torsion_test.png'}" if args.torsion != "none" else ""
    console.print(f"wrote {out / 'load_test.csv'}, {out / 'load_test.png'}{torsion_files}, {out / 'summary.json'}")
    return common.EXIT_OK
