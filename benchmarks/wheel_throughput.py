"""Wheel FEM speed: element updates per second and the cost of one DEM-step interval.

Meshes the seed-004 lunar-rover preset at its default resolution (about the paper's 29,644 elements)
and a coarse copy, times steady stepping in the serial (one launch per batch of steps) and parallel
(one launch per phase) forms, and reports the wheel's stable time step next to the soil's (seed-004
particles of 16-24 mm, seed-004 Table 1 soil, steel wall pairs), i.e. how many wheel sub-steps one
DEM step costs, and what that interval takes on this machine.

Also the compile time of the smoke wheel's stepping kernel (two sub-steps a launch, as a coupled smoke run
takes them) in a fresh process with an empty Taichi kernel cache, then with the cache it filled.

With ``--cmu-rigid``: only the CMU twin's rigid grousered wheel (the ``cmu-grouser`` preset, its hub free and
spinning under random nodal loads), one step at the twin's DEM step in the serial and the parallel form, in
alternating rounds (a shared machine's speed drifts between rounds); the two forms' states are compared bit for bit.

Run:  python -m wheelsoil.benchmarks.wheel_throughput [--out benchmarks/results/wheel.json]
      python -m wheelsoil.benchmarks.wheel_throughput --compile-only
      python -m wheelsoil.benchmarks.wheel_throughput --cmu-rigid [--out benchmarks/results/wheel-cmu-rigid.json]
"""

import argparse
import json
import math
import time
from pathlib import Path

from wheelsoil import runtime
from wheelsoil.benchmarks.common import cache_times, machine, peak_rss_mib, versions


def _time_steps(structure, n_steps: int, repeats: int = 3) -> float:
    structure.step(10)  # compile and warm up
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        structure.step(n_steps)
        best = min(best, (time.perf_counter() - t0) / n_steps)
    return best


_COMPILE_CODE = """
import time
t0 = time.perf_counter()
from wheelsoil import runtime
runtime.init({arch!r})
from wheelsoil.cases.build import wheel_geometry
from wheelsoil.cases.schema import load_case
from wheelsoil.flexwheel.geometry import build_wheel_mesh
from wheelsoil.flexwheel.structure import Structure
mesh, hub = build_wheel_mesh(wheel_geometry(load_case("smoke-1g-steer")))
wheel = Structure(mesh, hub_nodes=hub, serial=False)
t1 = time.perf_counter()
wheel.step(2)
t2 = time.perf_counter()
wheel.step(2)
print(t1 - t0, t2 - t1, time.perf_counter() - t2)
"""


def compile_time_cold_wheel(arch=None) -> dict:
    """Seconds to set up the smoke wheel, to its first two sub-steps (the stepping kernel's compile) and to the
    next two, in a fresh process with an empty Taichi kernel cache (``cold_cache``) and then with the cache it
    filled (``warm_cache``)."""
    return cache_times(_COMPILE_CODE.format(arch=arch), ("setup_s", "first_two_substeps_s", "next_two_substeps_s"))


def cmu_rigid_forms(steps: int, rounds: int) -> dict:
    """The CMU rigid wheel's step [s] in the serial and parallel forms, alternating rounds (module docstring)."""
    import numpy as np

    from wheelsoil.cases.build import wheel_geometry
    from wheelsoil.cases.schema import load_case
    from wheelsoil.flexwheel.geometry import build_wheel_mesh
    from wheelsoil.flexwheel.structure import Structure

    case = load_case("cmu-grouser")
    geometry = wheel_geometry(case)
    dt = 2e-5  # the twin's DEM step (its runs' logs)
    mesh, hub = build_wheel_mesh(geometry)
    rng = np.random.default_rng(0)
    forces, moments = rng.normal(size=(mesh.n_nodes, 3)), 1e-3 * rng.normal(size=(mesh.n_nodes, 3))

    def wheel(serial: bool):
        w = Structure(mesh, hub_nodes=hub, hub_center=np.zeros(3), hub_mass=geometry.hub_mass, rigid=True,
                      damping=case.wheel.damping, serial=serial)
        w.set_external(forces, moments)
        w.drive_hub(free_translation=(True, True, True), free_rotation=(True, True, True),
                    angular_velocity=(0.0, case.test.angular_velocity, 0.0))
        w.advance(dt)  # compile and warm up
        return w

    times: dict = {"serial": [], "parallel": []}
    final = {}
    for _ in range(rounds):
        for form in times:
            w = wheel(form == "serial")
            t0 = time.perf_counter()
            for _ in range(steps):
                w.advance(dt, check=False)
            w.check_health()  # ends on a host read: every launch has finished
            times[form].append((time.perf_counter() - t0) / steps)
            final[form] = w.positions()
    same = bool(np.array_equal(final["serial"], final["parallel"]))
    out = {"nodes": mesh.n_nodes, "elements": mesh.n_elements, "steps": steps, "rounds": rounds, "dt_s": dt,
           "seconds_per_step": times, "same_state": same,
           "parallel_over_serial_best": min(times["parallel"]) / min(times["serial"]),
           "parallel_over_serial_rounds": [p / q for p, q in zip(times["parallel"], times["serial"])]}
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("benchmarks/results/wheel.json"))
    parser.add_argument("--steps", type=int, default=200, help="steps per timing (default 200)")
    parser.add_argument("--arch", default=None, help="Taichi backend (default cpu)")
    parser.add_argument("--compile-only", action="store_true",
                        help="only the smoke wheel's stepping-kernel compile time, cold and warm cache")
    parser.add_argument("--cmu-rigid", action="store_true",
                        help="only the CMU twin's rigid wheel, serial against parallel form, alternating rounds")
    parser.add_argument("--rounds", type=int, default=5, help="alternating rounds of --cmu-rigid (default 5)")
    args = parser.parse_args(argv)
    if args.cmu_rigid:
        runtime.init(args.arch)
        res = {"machine": machine(), "versions": versions(), **cmu_rigid_forms(max(args.steps, 1000), args.rounds)}
        best = {k: 1e3 * min(v) for k, v in res["seconds_per_step"].items()}
        print(f"CMU rigid wheel, {res['nodes']} nodes: serial {best['serial']:.3f} ms/step, parallel "
              f"{best['parallel']:.3f} ms/step (best of {args.rounds}); parallel/serial best "
              f"{res['parallel_over_serial_best']:.2f}, per round "
              f"{', '.join(f'{r:.2f}' for r in res['parallel_over_serial_rounds'])}; same state: {res['same_state']}")
        out = args.out if args.out != Path("benchmarks/results/wheel.json") else Path("benchmarks/results/wheel-cmu-rigid.json")
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(res, indent=2))
        return 0
    if args.compile_only:
        compile_times = compile_time_cold_wheel(args.arch)
        print("smoke wheel, first two sub-steps:", json.dumps(compile_times))
        return 0
    runtime.init(args.arch)

    from wheelsoil.flexwheel.geometry import LUNAR_ROVER, build_wheel_mesh
    from wheelsoil.flexwheel.structure import Structure
    from wheelsoil.granular.materials import LUNAR_SOIL_SIMULANT, STEEL, effective_modulus
    from wheelsoil.granular.timestep import estimate_time_step

    soil_dt = estimate_time_step(
        0.008, LUNAR_SOIL_SIMULANT, wall_moduli=(effective_modulus(LUNAR_SOIL_SIMULANT, STEEL),), impact_speed=1.0
    ).stable
    results = {"machine": machine(), "versions": versions(), "soil_time_step_s": soil_dt, "cases": []}
    for label, size in (("seed-004 size", LUNAR_ROVER.element_size), ("coarse", 0.05)):
        t0 = time.perf_counter()
        mesh, hub = build_wheel_mesh(LUNAR_ROVER.with_element_size(size))
        t_mesh = time.perf_counter() - t0
        for serial in (True, False):
            t0 = time.perf_counter()
            wheel = Structure(mesh, hub_nodes=hub, serial=serial)
            t_setup = time.perf_counter() - t0
            per_step = _time_steps(wheel, args.steps)
            substeps = math.ceil(soil_dt / wheel.stable_time_step)
            case = {
                "mesh": label,
                "elements": mesh.n_elements,
                "nodes": mesh.n_nodes,
                "form": "serial" if serial else "parallel",
                "mesh_seconds": t_mesh,
                "setup_seconds": t_setup,
                "wheel_stable_time_step_s": wheel.stable_time_step,
                "seconds_per_step": per_step,
                "element_updates_per_second": mesh.n_elements / per_step,
                "substeps_per_dem_step": substeps,
                "seconds_per_dem_step_interval": substeps * per_step,
            }
            results["cases"].append(case)
            print(f"{label:14s} {case['form']:8s} {mesh.n_elements:6d} elements: {1e3 * per_step:7.3f} ms/step, "
                  f"{case['element_updates_per_second'] / 1e6:6.2f} M element updates/s, wheel dt "
                  f"{wheel.stable_time_step:.3e} s vs soil dt {soil_dt:.3e} s -> {substeps} sub-steps, "
                  f"{1e3 * case['seconds_per_dem_step_interval']:.2f} ms per DEM step")
    results["peak_rss_mib"] = peak_rss_mib()
    results["compile"] = compile_time_cold_wheel(args.arch)
    print("smoke wheel, first two sub-steps:", json.dumps(results["compile"]))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=2))
    print(f"peak RSS {results['peak_rss_mib']:.0f} MiB; wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
