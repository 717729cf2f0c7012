#!/usr/bin/env bash
# Before a session stops: pack every unfinished run under RUNS (default /work/runs) into docs/inflight, at most 40 MB
# of checkpoint each, removing the carries of runs finished here, and the finished cases of issue 35's smoke-scale
# sweeps without their frames (a sweep outlasts a session and has no record of its own elsewhere); then commit
# docs/inflight (README.md beside this).
#   bash docs/inflight/pack.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/../.."
RUNS=${1:-/work/runs}
PY=${PYTHON:-.venv/bin/python}
"$PY" -m wheelsoil.cases.cli carry pack "$RUNS" --to docs/inflight --max-mb 40 \
  --finished-in seed004-like --finished-in seed001-flexible-rigid
du -sh docs/inflight
