"""Coupled testbed speed: wall time per simulated second at smoke scale, where each DEM step's time goes,
and a measured extrapolation to seed-004 scale (388,026 particles, the full-resolution wheel).

1. Smoke scale (``smoke-1g-steer``: about 12,000 particles, 3,456 wheel elements): runs the whole testbed
   protocol (lower, settle, drive) and reports wall time per simulated second and peak memory; then keeps
   driving for ``--steps`` DEM steps with timers on the three parts of a coupled step -- the soil (DEM
   neighbour search, contact forces, integration), the wheel (its FE sub-steps over the DEM step) and the
   wheel--soil contact (evaluation, and candidate rebuilds separately); those steps alternate with as many of the
   same bed alone in ``--rounds`` chunks, so that the coupled-over-soil ratio does not take the machine's drift.
2. Seed-004 scale, each part measured in its own process so that its memory is its own:
   * the wheel at the preset's full resolution: mesh, stable step, time per FE sub-step, memory;
   * a bed of 388,026 spheres of 16--24 mm (``dem_throughput.memory_check``): memory while stepping;
   * the bare interpreter with Taichi initialised (subtracted from both, so the sum counts it once).
3. Extrapolation: the soil's cost per particle-step, the contact cost per contact and the rebuild cost per
   particle, all measured in part 1, times the seed-004 counts; the wheel's measured sub-step time times
   the sub-steps per (smaller) seed-004 DEM step; the seed-004 protocol's simulated time (lowering as
   measured at smoke scale, then 0.1 s settle, 0.05 s spin-up, 2.5 s drive).

Run:  python -m wheelsoil.benchmarks.testbed_throughput [--out benchmarks/results/testbed.json] [--arch cuda]
      python -m wheelsoil.benchmarks.testbed_throughput --cmu --out benchmarks/results/testbed-cmu.json
        (only the CMU twin's scale: part 1 on ``cmu-grouser``; ``--set KEY=VALUE ...`` changes the case, e.g. the
        particles' size for the rig at about 100,000 particles; ``--half-skin-too`` also times the half-skin
        neighbour-rebuild rule in the same rounds)
      python -m wheelsoil.benchmarks.testbed_throughput --compare-pinning 3 --drive-time 0.05
        (only the A/B of pinned and unpinned worker threads, :mod:`wheelsoil.threads`, in alternating processes)
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from wheelsoil import runtime
from wheelsoil.benchmarks.common import machine, own_peak_rss_mib, versions
from wheelsoil.benchmarks.coupled_rounds import coupled_against_soil

SEED004_PARTICLES = 388_026
SEED004_DRIVE_TIME = 2.5


#: The coupled parts: name -> the case preset they run.
COUPLED_PARTS = {"smoke": "smoke-1g-steer", "cmu": "cmu-grouser"}


def smoke_part(steps: int, drive_time: float, arch, preset: str = COUPLED_PARTS["smoke"], rounds: int = 6,
               overrides: tuple[str, ...] = (), half_skin_too: bool = False, sphere_skins: tuple = (),
               narrow_too: bool = False) -> dict:
    """The whole protocol of ``preset`` with a short drive, then ``steps`` timed DEM steps of steady driving by part,
    alternating in ``rounds`` chunks with as many steps of the same bed alone (module docstring, part 1; ``preset``
    cmu-grouser: the CMU twin's rigid wheel on its calibrated sand, issue 37 item 2). ``overrides``: the case's
    ``KEY=VALUE`` settings (as ``wheelsoil run --set``), e.g. finer particles for the rig at its own scale;
    ``half_skin_too``, ``sphere_skins``, ``narrow_too``: time the half-skin rebuild rule, other margins for the spheres'
    motion and the allowance before the widened search too,
    in the same rounds (:func:`.coupled_rounds.coupled_against_soil`)."""
    from wheelsoil.cases import build
    from wheelsoil.cases.schema import load_case
    from wheelsoil.coupling.testbed import Testbed
    from wheelsoil.granular import prepare_bed

    case = load_case(preset, [*overrides, f"test.drive_time={drive_time!r}", "test.stop_when_steady=false",
                              f"output.average_time={min(0.1, 0.5 * drive_time)!r}", "output.render=false"])
    bed = prepare_bed(build.bed_spec(case), arch=arch)
    t0 = time.perf_counter()
    bench = Testbed(bed, build.wheel_geometry(case), build.testbed_spec(case), arch=arch)
    setup = time.perf_counter() - t0
    cpu0 = time.process_time()
    result = bench.run()
    protocol_cpu = time.process_time() - cpu0
    info = result.info
    out = {
        "case": case.name,
        "overrides": list(overrides),
        "particles": info["particles"],
        "fe_elements": info["fe_elements"],
        "contact_facets": info["contact_facets"],
        "setup_seconds": setup,
        "protocol_wall_seconds": info["wall_seconds"],
        "protocol_simulated_seconds": info["simulated_seconds"],
        "wall_seconds_per_simulated_second": info["seconds_per_simulated_second"],
        "protocol_cores_busy": protocol_cpu / info["wall_seconds"],  # CPU time of all threads / wall, whole run
        "lowering_and_settling_simulated_seconds": info["t_spin_up"],
        "wind_up_simulated_seconds": info["t_hold"] - info["t_wind_up"] if math.isfinite(info["t_hold"]) else math.nan,
        "dem_time_step_s": info["dem_time_step"],
        "fe_time_step_s": info["fe_time_step"],
        "fe_substeps_per_dem_step": info["fe_substeps"] / info["dem_steps"],
    }
    out.update(coupled_against_soil(bench, bed, case, steps, rounds, arch, half_skin_too, sphere_skins, narrow_too))
    return out


def fe_seed004_part(steps: int, arch) -> dict:
    from wheelsoil.coupling.surface import ContactSurface
    from wheelsoil.flexwheel.geometry import LUNAR_ROVER, build_wheel_mesh
    from wheelsoil.flexwheel.structure import Structure

    runtime.init(arch)
    mesh, hub = build_wheel_mesh(LUNAR_ROVER)
    wheel = Structure(mesh, hub_nodes=hub, hub_center=mesh.nodes[hub].mean(axis=0), hub_mass=LUNAR_ROVER.hub_mass,
                      damping=10.0, gravity=(0.0, 0.0, -9.81))
    surface = ContactSurface.from_mesh(mesh)
    wheel.step(10)
    best = math.inf
    for _ in range(3):
        t0 = time.perf_counter()
        wheel.step(steps)
        best = min(best, (time.perf_counter() - t0) / steps)
    return {"fe_elements": int(mesh.n_elements), "nodes": int(mesh.n_nodes), "contact_facets": int(surface.n_facets),
            "fe_time_step_s": wheel.stable_time_step, "ms_per_substep": 1e3 * best, "peak_rss_mib": own_peak_rss_mib()}


def dem_seed004_part(arch) -> dict:
    from wheelsoil.benchmarks.dem_throughput import memory_check

    runtime.init(arch)
    return memory_check(SEED004_PARTICLES) | {"peak_rss_mib": own_peak_rss_mib()}


def base_part(arch) -> dict:
    import taichi as ti

    runtime.init(arch)

    @ti.kernel
    def touch() -> ti.i32:
        return 1

    touch()
    return {"peak_rss_mib": own_peak_rss_mib()}


def _child(part: str, arch, steps: int, *, drive_time: float | None = None, env: dict | None = None) -> dict:
    cmd = [sys.executable, "-m", "wheelsoil.benchmarks.testbed_throughput", "--part", part, "--steps", str(steps)]
    if arch:
        cmd += ["--arch", arch]
    if drive_time is not None:
        cmd += ["--drive-time", repr(drive_time)]
    done = subprocess.run(cmd, capture_output=True, text=True, check=False,
                          env=None if env is None else {**os.environ, **env})
    if done.returncode != 0:
        raise RuntimeError(f"benchmark part {part!r} failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def extrapolate(smoke: dict, fe: dict, dem: dict, base: dict) -> dict:
    """Seed-004 cost from the measured smoke-scale parts and the measured full-resolution wheel."""
    from wheelsoil.cases import build
    from wheelsoil.cases.schema import load_case

    s_bed, f_bed = build.bed_spec(load_case("smoke-1g-steer")), build.bed_spec(load_case("seed004-1g-steer"))
    # the DEM step scales with the smallest radius (Rayleigh and Hertz estimates are both ~ R)
    dt = smoke["dem_time_step_s"] * f_bed.diameter_min / s_bed.diameter_min
    particles = SEED004_PARTICLES / smoke["particles"]
    # contacts on the same tread area scale with 1 / d^2
    d_s = 0.5 * (s_bed.diameter_min + s_bed.diameter_max)
    d_f = 0.5 * (f_bed.diameter_min + f_bed.diameter_max)
    contacts = (d_s / d_f) ** 2
    substeps = math.ceil(dt / fe["fe_time_step_s"])
    ms = {
        "soil": smoke["ms_per_step_soil"] * particles,
        "wheel": fe["ms_per_substep"] * substeps,
        "contact_evaluation": smoke["ms_per_step_contact_evaluation"] * contacts,
        # candidate rebuilds loop over all particles; they follow the DEM rebuilds (every ~skin / speed)
        "contact_rebuild": smoke["ms_per_step_contact_rebuild"] * particles,
    }
    simulated = smoke["lowering_and_settling_simulated_seconds"] + 0.05 + SEED004_DRIVE_TIME
    per_step = sum(ms.values())
    soil_alone = smoke["ms_per_step_soil_alone"] * particles
    steps = simulated / dt
    return {
        "particles": SEED004_PARTICLES,
        "fe_elements": fe["fe_elements"],
        "contact_facets": fe["contact_facets"],
        "dem_time_step_s": dt,
        "fe_substeps_per_dem_step": substeps,
        "scale_factors": {"particles": particles, "contacts": contacts},
        "ms_per_step": ms | {"total": per_step},
        # against the same bed alone: the soil-alone cost per particle-step measured at smoke scale, times the count
        "ms_per_step_soil_alone": soil_alone,
        "coupled_over_soil_alone": per_step / soil_alone,
        "wall_seconds_per_simulated_second": per_step * 1e-3 / dt,
        "protocol_simulated_seconds": simulated,
        "protocol_wall_hours": per_step * 1e-3 * steps / 3600.0,
        "peak_rss_mib": dem["peak_rss_mib"] + fe["peak_rss_mib"] - base["peak_rss_mib"],
        "peak_rss_parts_mib": {"soil_388k": dem["peak_rss_mib"], "wheel_full": fe["peak_rss_mib"],
                               "interpreter_and_taichi": base["peak_rss_mib"]},
    }


def compare_pinning(args) -> int:
    """Alternating processes with the worker threads pinned (``WHEELSOIL_PIN_THREADS=1``) and not (``0``): the
    coupled step, its cores busy and the soil alone, per pair and as medians of the paired ratios."""
    rows = []
    keys = ("ms_per_step", "cores_busy", "ms_per_step_soil_alone", "soil_alone_cores_busy")
    for k in range(args.compare_pinning):
        row = {}
        for label, value in (("pinned", "1"), ("unpinned", "0")):
            out = _child("smoke", args.arch, args.steps, drive_time=args.drive_time, env={"WHEELSOIL_PIN_THREADS": value})
            row[label] = {key: out[key] for key in keys}
        rows.append(row)
        p, u = row["pinned"], row["unpinned"]
        print(f"pair {k + 1}: coupled {p['ms_per_step']:.2f} ms ({p['cores_busy']:.2f} cores) pinned, "
              f"{u['ms_per_step']:.2f} ms ({u['cores_busy']:.2f} cores) unpinned; soil alone "
              f"{p['ms_per_step_soil_alone']:.2f} / {u['ms_per_step_soil_alone']:.2f} ms", flush=True)
    ratio = statistics.median(r["pinned"]["ms_per_step"] / r["unpinned"]["ms_per_step"] for r in rows)
    soil = statistics.median(r["pinned"]["ms_per_step_soil_alone"] / r["unpinned"]["ms_per_step_soil_alone"] for r in rows)
    print(f"median pinned / unpinned time: coupled step {ratio:.3f}, soil alone {soil:.3f} ({len(rows)} pairs)")
    report = {"machine": machine(), "versions": versions(), "command": " ".join(sys.argv), "pairs": rows,
              "median_pinned_over_unpinned": {"coupled_step": ratio, "soil_alone": soil}}
    out = args.out.with_name(args.out.stem + "-pinning.json")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(report, indent=2, default=float))
    print(f"wrote {out}")
    return 0


def _write_report(out: Path, report: dict) -> int:
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(report, indent=2, default=float))
    print(f"wrote {out}")
    return 0


def cmu_scale(args) -> int:
    """The CMU twin's coupled step against its bed alone; prints and writes ``--out``."""
    runtime.init(args.arch)
    report = {"machine": machine(), "versions": versions(), "command": " ".join(sys.argv)}
    cmu = report["cmu"] = smoke_part(args.steps, args.drive_time, args.arch, COUPLED_PARTS["cmu"], args.rounds,
                                     tuple(args.set), args.half_skin_too, tuple(args.sphere_skins), args.narrow_too)
    print(f"CMU scale ({cmu['case']}): {cmu['particles']} particles, rigid wheel of {cmu['fe_elements']} elements; "
          f"{cmu['wall_seconds_per_simulated_second']:.0f} s wall per simulated s over the protocol; per DEM step "
          f"{cmu['ms_per_step']:.2f} ms = soil {cmu['ms_per_step_soil']:.2f} + wheel {cmu['ms_per_step_wheel']:.2f} + "
          f"contact {cmu['ms_per_step_contact_evaluation']:.2f} + rebuild {cmu['ms_per_step_contact_rebuild']:.2f} "
          f"({cmu['cores_busy']:.2f} cores busy); the bed alone {cmu['ms_per_step_soil_alone']:.2f} ms "
          f"({cmu['soil_alone_cores_busy']:.2f} cores): coupled / soil alone {cmu['coupled_over_soil_alone']:.2f} "
          f"in all, median of {cmu['rounds']} alternating rounds {cmu['coupled_over_soil_alone_median']:.2f} ("
          f"{', '.join(f'{x:.2f}' for x in cmu['coupled_over_soil_alone_per_round'])}) (goal <= 1.2); "
          f"CPU per step {cmu['cpu_ms_per_step']:.2f} ms, the bed alone "
          f"{cmu['cpu_ms_per_step_soil_alone']:.2f}; peak RSS {cmu['peak_rss_mib']:.0f} MiB; "
          f"{cmu['dem_neighbor_rebuilds']} neighbour rebuilds", flush=True)
    if args.half_skin_too:
        print(f"the half-skin rule in the same rounds: {cmu['half_skin_ms_per_step']:.2f} ms per step, "
              f"{cmu['half_skin_dem_neighbor_rebuilds']} neighbour rebuilds, coupled / soil alone "
              f"{cmu['half_skin_coupled_over_soil_alone']:.2f}; half skin / allowance "
              f"{cmu['half_skin_over_today']:.2f}", flush=True)
    for name, fig in cmu.get("variants", {}).items():
        print(f"{name} (today {cmu['sphere_skins']:g}) in the same rounds: {fig['ms_per_step']:.2f} ms per step "
              f"(contact {fig['ms_per_step_contact_evaluation']:.2f}), {fig['dem_neighbor_rebuilds']} neighbour "
              f"rebuilds, coupled / soil alone {fig['coupled_over_soil_alone']:.2f}; over today's "
              f"{fig['over_today']:.2f}", flush=True)
    return _write_report(args.out, report)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("benchmarks/results/testbed.json"))
    ap.add_argument("--steps", type=int, default=600, help="DEM steps timed in steady driving (default 600)")
    ap.add_argument("--rounds", type=int, default=6,
                    help="alternating chunks of the coupled steps and the soil alone (default 6)")
    ap.add_argument("--drive-time", type=float, default=0.3, help="smoke protocol drive time [s] (default 0.3)")
    ap.add_argument("--arch", default=None, help="Taichi backend (default cpu)")
    ap.add_argument("--compare-pinning", type=int, default=0, metavar="PAIRS",
                    help="only compare worker threads pinned and not (WHEELSOIL_PIN_THREADS): PAIRS alternating "
                         "pairs of processes, each timing --steps coupled steps and the soil alone at smoke scale")
    ap.add_argument("--cmu", action="store_true",
                    help="only the CMU twin's scale (cmu-grouser: rigid wheel, about 21,500 particles): the coupled "
                         "step by part against the same bed alone (issue 37 item 2)")
    ap.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE",
                    help="with --cmu: the case's settings as in wheelsoil run --set, e.g. soil.diameter_min=0.003072 "
                         "soil.diameter_max=0.004608 for the rig at about 100,000 particles")
    ap.add_argument("--half-skin-too", action="store_true",
                    help="with --cmu: each round also steps the testbed under the half-skin rebuild rule (every "
                         "sphere's allowance half the skin, as before the per-sphere allowance), timed apart")
    ap.add_argument("--sphere-skins", nargs="+", type=float, default=[], metavar="K",
                    help="with --cmu: each round also steps the testbed with the wheel contact's margin for the "
                         "spheres' motion (the least allowance it leaves a sphere near it) at K scene skins, timed "
                         "apart")
    ap.add_argument("--narrow-too", action="store_true",
                    help="with --cmu: each round also steps the testbed with the allowance as before the widened "
                         "clearance search and the wheel's per-sphere bound (27 cells, every allowance capped at the "
                         "wheel candidates' margin of then, two skins), timed apart")
    ap.add_argument("--part", choices=("fe-seed004", "dem-seed004", "base", "smoke", "cmu"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.set and not args.cmu:
        ap.error("--set applies to the CMU part only (--cmu)")
    if (args.half_skin_too or args.sphere_skins or args.narrow_too) and not args.cmu:
        ap.error("--half-skin-too, --sphere-skins and --narrow-too apply to the CMU part only (--cmu)")
    if any(not (math.isfinite(k) and k > 0) for k in args.sphere_skins):
        ap.error(f"--sphere-skins {args.sphere_skins}: each must be a number of skins > 0")
    if args.rounds < 1 or args.steps < 10 * args.rounds:
        ap.error(f"--rounds {args.rounds} and --steps {args.steps}: give at least one round and 10 steps per round")
    if args.part:
        fn = {"fe-seed004": lambda: fe_seed004_part(min(args.steps, 200), args.arch),
              "dem-seed004": lambda: dem_seed004_part(args.arch), "base": lambda: base_part(args.arch),
              "smoke": lambda: smoke_part(args.steps, args.drive_time, args.arch, rounds=args.rounds),
              "cmu": lambda: smoke_part(args.steps, args.drive_time, args.arch, COUPLED_PARTS["cmu"], args.rounds)}[args.part]
        print(json.dumps(fn(), default=float))
        return 0
    if args.compare_pinning:
        return compare_pinning(args)
    if args.cmu:
        return cmu_scale(args)
    runtime.init(args.arch)
    report = {"machine": machine(), "versions": versions(), "command": " ".join(sys.argv)}
    print("smoke scale: whole protocol, then timed steady driving ...", flush=True)
    smoke = report["smoke"] = smoke_part(args.steps, args.drive_time, args.arch, rounds=args.rounds)
    print(f"  {smoke['particles']} particles, {smoke['fe_elements']} elements: "
          f"{smoke['wall_seconds_per_simulated_second']:.1f} s wall per simulated s over the protocol "
          f"({smoke['protocol_wall_seconds']:.0f} s for {smoke['protocol_simulated_seconds']:.2f} s); per DEM step "
          f"{smoke['ms_per_step']:.2f} ms = soil {smoke['ms_per_step_soil']:.2f} + wheel {smoke['ms_per_step_wheel']:.2f}"
          f" ({smoke['fe_substeps_per_dem_step']:.0f} sub-steps) + contact {smoke['ms_per_step_contact_evaluation']:.2f}"
          f" + rebuild {smoke['ms_per_step_contact_rebuild']:.2f}; {smoke['cores_busy']:.2f} cores busy "
          f"({smoke['protocol_cores_busy']:.2f} over the whole protocol); the soil alone {smoke['ms_per_step_soil_alone']:.2f}"
          f" ms per step ({smoke['soil_alone_cores_busy']:.2f} cores): coupled / soil alone "
          f"{smoke['coupled_over_soil_alone']:.2f} (goal <= 1.5); peak RSS {smoke['peak_rss_mib']:.0f} MiB", flush=True)
    print(f"  CPU time per DEM step {smoke['cpu_ms_per_step']:.2f} ms = soil {smoke['cpu_ms_per_step_soil']:.2f} + wheel "
          f"{smoke['cpu_ms_per_step_wheel']:.2f} + contact {smoke['cpu_ms_per_step_contact_evaluation']:.2f} + rebuild "
          f"{smoke['cpu_ms_per_step_contact_rebuild']:.2f}; the soil alone {smoke['cpu_ms_per_step_soil_alone']:.2f}; "
          f"with all {smoke['cores']} cores busy throughout, coupled / soil alone would be "
          f"{smoke['coupled_over_soil_alone_all_cores_busy']:.2f} at best", flush=True)
    print("seed-004 scale parts (own processes) ...", flush=True)
    fe = report["seed004_wheel"] = _child("fe-seed004", args.arch, args.steps)
    print(f"  wheel {fe['fe_elements']} elements, {fe['contact_facets']} contact facets: "
          f"{fe['ms_per_substep']:.2f} ms per sub-step of {fe['fe_time_step_s']:.3g} s; RSS {fe['peak_rss_mib']:.0f} MiB",
          flush=True)
    dem = report["seed004_soil"] = _child("dem-seed004", args.arch, args.steps)
    base = report["base"] = _child("base", args.arch, args.steps)
    print(f"  soil {dem['particles']} spheres: RSS {dem['peak_rss_mib']:.0f} MiB; interpreter + Taichi "
          f"{base['peak_rss_mib']:.0f} MiB", flush=True)
    ext = report["seed004_extrapolated"] = extrapolate(smoke, fe, dem, base)
    ms = ext["ms_per_step"]
    print(f"seed-004 scale (extrapolated): DEM step {ext['dem_time_step_s']:.3g} s, {ext['fe_substeps_per_dem_step']} "
          f"wheel sub-steps; per step {ms['total']:.0f} ms = soil {ms['soil']:.0f} + wheel {ms['wheel']:.0f} + contact "
          f"{ms['contact_evaluation']:.1f} + rebuild {ms['contact_rebuild']:.1f} (the bed alone "
          f"{ext['ms_per_step_soil_alone']:.0f} ms: coupled / soil alone {ext['coupled_over_soil_alone']:.2f}); "
          f"{ext['wall_seconds_per_simulated_second'] / 3600:.2f} h wall per simulated s; one case "
          f"({ext['protocol_simulated_seconds']:.2f} s simulated) {ext['protocol_wall_hours']:.1f} h; "
          f"peak RSS {ext['peak_rss_mib']:.0f} MiB", flush=True)
    return _write_report(args.out, report)


if __name__ == "__main__":
    raise SystemExit(main())
