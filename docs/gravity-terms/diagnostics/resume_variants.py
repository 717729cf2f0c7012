"""Resume the soil-stiffness seed-2 run from its carry under a change of the coupling, and print the wheel's fastest
node every five samples (the table "Why the first attempt blew up" in ../README.md). Diagnostic, not part of the package.

    git show 678042d:docs/inflight/26e1edf5e01e2de0.carry.h5 > /tmp/ss2.carry.h5
    WHEELSOIL_CPU_THREADS=1 python docs/gravity-terms/diagnostics/resume_variants.py /tmp/ss2.carry.h5 VARIANT 8.1

VARIANT: ``none`` (the code as it is), ``lead0`` (no anchor lead), ``dt=1.3e-4`` (the DEM step set after the restore).
The case is the one the carry holds; its bed is prepared (or read from the cache) as the run's was. The rigid-velocity
lead of the table was a change of ``coupling/kernels.py: node_load`` (commit cc411d2), run with ``none``. The table's
``none`` row ran before the node-speed guard (coupling/node_speed.py); with it, that row stops at the guard's 17 m/s.
"""

import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np


def main() -> None:
    carry, variant, t_stop = sys.argv[1], sys.argv[2], float(sys.argv[3])
    import wheelsoil.coupling.contact as contact
    from wheelsoil.cases import build
    from wheelsoil.cases.schema import load_case
    from wheelsoil.coupling.testbed import Testbed
    from wheelsoil.granular import prepare_bed
    from wheelsoil.state_file import load_state

    if variant == "lead0":
        contact.anchor_lead = lambda interval, substeps: 0.0
    with h5py.File(carry, "r") as f:
        toml = f.attrs["case_toml"]
    case_file = Path(tempfile.mkdtemp()) / "case.toml"
    case_file.write_text(toml if isinstance(toml, str) else toml.decode())
    plan = build.plan(load_case(case_file))
    tb = Testbed(prepare_bed(plan.bed), plan=plan.rig)
    state, _ = load_state(carry)
    tb.restore_state(state)
    if variant.startswith("dt="):
        tb.scene.time_step = tb.dt = float(variant[3:])
        tb.steps_per_sample = max(1, int(round(tb.spec.sample_interval / tb.dt)))
    print(variant, "resumed at", tb.scene.time, "DEM step", tb.scene.time_step, flush=True)
    while tb.scene.time < t_stop:
        try:
            done = tb._sample()
        except Exception as exc:  # the blow-up this looks for
            print("STOPPED", type(exc).__name__, str(exc)[:200])
            return
        v = np.linalg.norm(tb.structure.velocities(), axis=1)
        if len(tb.rows["t"]) % 5 == 0:
            print(f"t={tb.scene.time:.3f} fastest node {v.max():.2f} m/s (node {int(v.argmax())}), "
                  f"median {np.median(v):.3f}, sub-steps {tb.contact._last_substeps}", flush=True)
        if done:
            return


if __name__ == "__main__":
    main()
