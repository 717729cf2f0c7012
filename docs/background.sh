#!/usr/bin/env bash
# The long campaigns that run in the background across sessions (issues 34, 35), each resumable: this script
# starts those not running, with the settings they share the machine's two cores under. Run it from the repository
# root at the start of a session (a fresh machine keeps the repository, not RUNS):
#   bash docs/background.sh [RUNS]        # RUNS: the runs folder outside the repository (default /work/runs)
#   python docs/background_status.py --runs RUNS   # where each stands (reads files only)
# Each job keeps what it finished (the twin's records in docs/cmu-twin/runs, the calibration's candidates in
# docs/soillab/calibration-epsd-box/candidates, the campaigns' draws in docs/validation/campaigns/*.jsonl); a job
# already running is left alone. The twin and the calibration get one Taichi thread each (two runs on two cores step
# 1.18-1.26 times faster in all than with a thread per core each); the campaigns, pure NumPy, at normal priority
# (a draw is 10-30 s of CPU; at nice 10 beside two DEM runs it got an eighth of a core).
# The jobs run the working tree's code: a Taichi kernel compiles at its first call, from its file as it is then, so
# editing a module with kernels under a running job that has not yet called them stops it (a soil-lab wheel replica
# died so on 2026-11-29, compiling the wheel contact's candidate kernels from the file changed under it). Edit kernel
# modules while the jobs run only once they are past their first wheel contact, or restart them after.
set -u
cd "$(dirname "$0")/.."
RUNS=${1:-/work/runs}
PY=${PYTHON:-.venv/bin/python}
mkdir -p "$RUNS"
export HDF5_USE_FILE_LOCKING=FALSE WHEELSOIL_CPU_THREADS=1
# Runs carried from the machine before (docs/inflight/README.md): their checkpoints go back under RUNS first, so that
# each job resumes them instead of starting them again; a run finished or further along here is kept as it is. Before
# a session stops: bash docs/inflight/pack.sh "$RUNS", and commit docs/inflight.
if compgen -G "docs/inflight/*.carry.h5" > /dev/null; then
  "$PY" -m wheelsoil.cases.cli carry unpack docs/inflight --into "$RUNS"
fi
running() { pgrep -f "$1" > /dev/null; }
start() {  # start NAME PATTERN LOG COMMAND...
  local name=$1 pattern=$2 log=$3; shift 3
  if running "$pattern"; then echo "$name: running"; return; fi
  nohup "$@" >> "$log" 2>&1 &
  echo "$name: started (log $log)"
}
start "CMU twin queue (issue 34)" "cmu_twin_queue.py" "$RUNS/cmu_queue.log" \
  "$PY" docs/cmu_twin_queue.py --runs "$RUNS" --queue docs/cmu-twin/queue.json
# The soil lab's calibration and the checks on its choice (issue 33) finished on 2026-12-07 (the x0.64 plate last;
# docs/soillab/choice-checks/summary.md): rerun them with CACHE=RUNS/lab-cache bash docs/soillab/choice-checks/run.sh
# (every finished step is kept).
# The five-gravity campaigns and the validation examples' leave-one-angle-out runs under the accepted rule finished on
# 2026-11-29 (docs/validation/campaigns.md, docs/validation/README.md); their core now runs issue 35's sweeps, each
# with its comparison fixed before any run: seed 004's own conditions at smoke scale (54 cases of 4-10 min;
# docs/sweeps/seed004-like/README.md), then seed 001's wheel and slips, flexible against rigid (10 cases, hours each;
# docs/sweeps/seed001-flexible-rigid/README.md). Finished cases are kept and a killed one resumes from its checkpoint;
# when cases finish, their tables are written into those folders (the commands are in their READMEs).
# First in that slot since 2026-11-30: the gravity terms (docs/gravity-terms/README.md; nine smoke runs of 15-60 min,
# each variant's seeds 0, 1, 2 in turn; its log $RUNS/gravity-terms.log), then the smoke-scale sweeps, and last the
# two seed-004 full-scale cases the issue asks for (193,000 particles; by the cost estimate 0.4-3 h each alone on 2
# cores, several times that beside the twin). Since 2026-12-07 the full-scale cases come last: their checkpoints
# (about 150 MB) are too large to carry between machines (docs/inflight), so beside the twin they are lost at each
# session's end, while a smoke case's checkpoint is carried; they run in a session that gives them both cores:
#   .venv/bin/python -m wheelsoil.cases.cli batch seed004-full-scale --out RUNS/seed004-full-scale --workers 1
start "issue 35's sweeps: gravity-terms, seed004-like, seed001-flexible-rigid, then seed004-full-scale" \
  "gravity_terms.py run|batch seed004-full-scale|batch seed004-like|batch seed001-flexible-rigid" \
  "$RUNS/issue35-sweeps.log" \
  bash -c '"$0" docs/gravity_terms.py run --runs "$1" --seeds 0 1 2 >> "$1/gravity-terms.log" 2>&1; \
    "$0" -m wheelsoil.cases.cli batch seed004-like --out "$1/seed004-like" --workers 1; \
    "$0" -m wheelsoil.cases.cli batch seed001-flexible-rigid --out "$1/seed001-flexible-rigid" --workers 1; \
    "$0" -m wheelsoil.cases.cli batch seed004-full-scale --out "$1/seed004-full-scale" --workers 1' \
  "$PY" "$RUNS"
