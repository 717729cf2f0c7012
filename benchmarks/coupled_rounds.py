"""The coupled testbed's DEM steps by part against the same bed alone, in alternating rounds, under today's rebuild
rule and others (the half-skin rule, other margins, the allowance before the widened search) timed apart in the same
rounds (:mod:`.testbed_throughput`, part 1 and ``--cmu``)."""

import os
import statistics
import time
from dataclasses import dataclass, field

from wheelsoil.benchmarks.common import own_peak_rss_mib


def _timed(obj, name: str, totals: dict, key: str) -> None:
    """Replace ``obj.name`` by a wrapper that adds its wall time to ``totals[key]`` and the CPU time of all the
    process's threads to ``totals[key + "_cpu"]``."""
    inner = getattr(obj, name)
    totals.setdefault(key + "_cpu", 0.0)

    def wrapper(*args, **kwargs):
        t0, cpu0 = time.perf_counter(), time.process_time()
        try:
            return inner(*args, **kwargs)
        finally:
            totals[key] += time.perf_counter() - t0
            totals[key + "_cpu"] += time.process_time() - cpu0

    setattr(obj, name, wrapper)


#: The wheel candidates' margin for the spheres' motion, in skins, before the widened search (2026-11-29): the
#: ``narrow_too`` variant's (:func:`coupled_against_soil`).
FORMER_SPHERE_SKINS = 2.0

#: The coupled step's timed parts (wrapped methods of the wheel contact), each with its CPU time beside.
_PARTS = ("wheel", "contact", "rebuild", "wheel_cpu", "contact_cpu", "rebuild_cpu")


@dataclass
class _Tally:
    """What the coupled steps under one rebuild rule took, summed over the rounds."""

    seconds: float = 0.0
    cpu: float = 0.0
    wheel_rebuilds: int = 0
    dem_rebuilds: int = 0
    contacts: int = 0
    parts: dict = field(default_factory=lambda: dict.fromkeys(_PARTS, 0.0))
    per_round: list = field(default_factory=list)

    def step(self, bench, blocks: int, totals: dict, fresh: bool) -> float:
        """``blocks`` of 10 coupled steps (``fresh``: from a neighbour rebuild), added to the tally; their wall time
        [s]."""
        c, scene = bench.contact, bench.scene
        if fresh:  # the round starts from a rebuild under its own rule
            scene.request_neighbor_rebuild()
        r0, d0, before = c.rebuilds, scene.neighbor_rebuilds, dict(totals)
        t0, cpu0 = time.perf_counter(), time.process_time()
        for _ in range(blocks):
            scene.step(10)
            self.contacts += c.contact_count
        seconds = time.perf_counter() - t0
        self.seconds += seconds
        self.cpu += time.process_time() - cpu0
        self.wheel_rebuilds += c.rebuilds - r0
        self.dem_rebuilds += scene.neighbor_rebuilds - d0
        for key in _PARTS:
            self.parts[key] += totals[key] - before[key]
        return seconds


def coupled_against_soil(bench, bed, case, steps: int, rounds: int, arch, half_skin_too: bool = False,
                          sphere_skins: tuple[float, ...] = (), narrow_too: bool = False) -> dict:
    """``steps`` DEM steps of the running testbed ``bench``, timed by part, alternating in ``rounds`` chunks with as
    many steps of its bed ``bed`` alone (:func:`smoke_part`). Each round can also step the testbed as many steps in
    other settings, timed apart: ``half_skin_too``, under the half-skin rule
    (:class:`~wheelsoil.granular.interaction.HalfSkinRule`; ``half_skin_*`` figures); ``sphere_skins``, with the wheel
    contact's margin for the spheres' motion (the least allowance it leaves a sphere near the wheel) at each of these
    many skins; ``narrow_too``, as before the widened clearance search and the wheel's per-sphere bound (the
    27-cell clearance, every allowance capped at the candidates' margin of then, :data:`FORMER_SPHERE_SKINS`:
    ``variants``)."""
    from wheelsoil.cases import build
    from wheelsoil.coupling.rig import soil_headroom
    from wheelsoil.granular.interaction import HalfSkinRule, SkinCap
    from wheelsoil.granular.scene import WIDEN_HORIZON_STEPS

    # where the time of one coupled step goes, in steady driving, against the soil alone: the same bed in its own bin
    # (periodic along x where the testbed holds a moving patch's ends instead) at the same step and in the same
    # domain, without the wheel. The two alternate in ``rounds`` chunks, so that the machine's drift over the minutes
    # of a run falls on both alike (one block of each in turn gave 1.15, 1.32 and 1.52 in three runs of the same code
    # on 2026-11-29: the soil alone's own time moved from 2.40 to 3.11 ms between them)
    c, scene = bench.contact, bench.scene
    soil = bed.to_scene(headroom=soil_headroom(bed.spec.depth, build.wheel_geometry(case)), arch=arch)
    soil.time_step = bench.dt
    soil.step(10)  # compile
    totals = {"wheel": 0.0, "contact": 0.0, "rebuild": 0.0}
    _timed(c, "after_drift", totals, "wheel")
    _timed(c, "add_forces", totals, "contact")
    _timed(c, "_rebuild", totals, "rebuild")
    blocks = max(1, steps // (10 * rounds))  # blocks of 10 steps per round
    default_skins, rule = c.sphere_skins, HalfSkinRule()
    # the other settings: (name, set up, undo); each round steps every one of them, then today's, then the soil alone
    others = [("half skin", lambda: scene.interactions.append(rule), lambda: scene.interactions.remove(rule))] \
        if half_skin_too else []
    if narrow_too:  # the allowance before the widened search and the wheel's per-sphere bound, at its margin then
        narrow = SkinCap(FORMER_SPHERE_SKINS)

        def enter_narrow():
            scene.widen_steps = 0
            scene.interactions.append(narrow)
            c.sphere_skins = FORMER_SPHERE_SKINS

        def leave_narrow():
            scene.widen_steps = WIDEN_HORIZON_STEPS
            scene.interactions.remove(narrow)
            c.sphere_skins = default_skins

        others.append(("27 cells, uniform cap", enter_narrow, leave_narrow))
    for k in sphere_skins:
        others.append((f"sphere skins {k:g}", lambda k=k: setattr(c, "sphere_skins", float(k)),
                       lambda: setattr(c, "sphere_skins", default_skins)))
    today, tallies = _Tally(), {name: _Tally() for name, _, _ in others}
    soil_total = soil_cpu = 0.0
    # With other settings in the rounds each round starts from a rebuild under its own rule, and then the bed alone's
    # rounds start from one too, so that neither side pays rebuilds the other does not (six forced starts of ~60 ms
    # were ~0.3 ms a step at 100,000 spheres, on the coupled side only, until 2026-11-29's evening); without other
    # settings no round is forced to rebuild.
    fresh = bool(others)
    for _ in range(rounds):
        other_rounds = {}
        for name, enter, leave in others:
            enter()
            other_rounds[name] = tallies[name].step(bench, blocks, totals, fresh)
            leave()
        seconds = today.step(bench, blocks, totals, fresh)
        if fresh:
            soil.request_neighbor_rebuild()
        t0, cpu0 = time.perf_counter(), time.process_time()
        soil.step(10 * blocks)
        soil_round = time.perf_counter() - t0
        soil_total += soil_round
        soil_cpu += time.process_time() - cpu0
        today.per_round.append(seconds / soil_round)
        for name, other in other_rounds.items():
            tallies[name].per_round.append(other / soil_round)
    out = _figures(today, 10 * blocks * rounds, rounds, soil_total, soil_cpu)
    out["sphere_skins"] = default_skins
    out["rounds_start_from_a_rebuild"] = fresh
    n = out["timed_steps"]
    for name, t in tallies.items():
        fig = {"ms_per_step": 1e3 * t.seconds / n, "dem_neighbor_rebuilds": t.dem_rebuilds,
               "ms_per_step_contact_evaluation": 1e3 * (t.parts["contact"] - t.parts["rebuild"]) / n,
               "coupled_over_soil_alone": t.seconds / soil_total, "coupled_over_soil_alone_per_round": t.per_round,
               "over_today": t.seconds / today.seconds}
        if name == "half skin":
            out.update({f"half_skin_{key}": value for key, value in fig.items()})
        else:
            out.setdefault("variants", {})[name] = fig
    return out


def _figures(t: _Tally, n: int, rounds: int, soil_total: float, soil_cpu: float) -> dict:
    """The figures of :func:`coupled_against_soil` from the tally of ``n`` coupled steps and the soil alone's wall and
    CPU time [s] over as many."""
    parts = t.parts
    contact_eval = parts["contact"] - parts["rebuild"]
    contact_eval_cpu = parts["contact_cpu"] - parts["rebuild_cpu"]
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return {
        "timed_steps": n,
        "rounds": rounds,
        "ms_per_step": 1e3 * t.seconds / n,
        "cores_busy": t.cpu / t.seconds,  # CPU time of all threads / wall time over the timed steps
        "ms_per_step_soil": 1e3 * (t.seconds - parts["wheel"] - parts["contact"]) / n,
        "ms_per_step_wheel": 1e3 * parts["wheel"] / n,
        "ms_per_step_contact_evaluation": 1e3 * contact_eval / n,
        "ms_per_step_contact_rebuild": 1e3 * parts["rebuild"] / n,
        # CPU time of all threads per DEM step, by part (the soil: the rest of the step)
        "cpu_ms_per_step": 1e3 * t.cpu / n,
        "cpu_ms_per_step_soil": 1e3 * (t.cpu - parts["wheel_cpu"] - parts["contact_cpu"]) / n,
        "cpu_ms_per_step_wheel": 1e3 * parts["wheel_cpu"] / n,
        "cpu_ms_per_step_contact_evaluation": 1e3 * contact_eval_cpu / n,
        "cpu_ms_per_step_contact_rebuild": 1e3 * parts["rebuild_cpu"] / n,
        "contact_rebuilds": t.wheel_rebuilds,
        "dem_neighbor_rebuilds": t.dem_rebuilds,
        "mean_wheel_contacts": t.contacts / (n // 10),
        "peak_rss_mib": own_peak_rss_mib(),
        "ms_per_step_soil_alone": 1e3 * soil_total / n,
        "cpu_ms_per_step_soil_alone": 1e3 * soil_cpu / n,
        "soil_alone_cores_busy": soil_cpu / soil_total,
        "coupled_over_soil_alone": t.seconds / soil_total,
        "coupled_over_soil_alone_per_round": t.per_round,
        "coupled_over_soil_alone_median": statistics.median(t.per_round),
        "cores": cores,
        # the ratio if the coupled step's CPU work were spread over every core with none idle and the soil alone
        # kept its measured wall time: the floor that scheduling alone cannot go below, for the present cost of
        # each part (CPU time counts work done, not waiting: Taichi's idle workers sleep)
        "coupled_over_soil_alone_all_cores_busy": t.cpu / cores / soil_total,
    }
