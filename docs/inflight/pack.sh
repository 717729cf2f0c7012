#!/usr/bin/env bash
# Before a session stops: pack every unfinished run under RUNS (default /work/runs) into docs/inflight, at most 40 MB
# of checkpoint each, removing the carries of runs finished here; then commit docs/inflight (README.md beside this).
#   bash docs/inflight/pack.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/../.."
RUNS=${1:-/work/runs}
PY=${PYTHON:-.venv/bin/python}
"$PY" -m wheelsoil.cases.cli carry pack "$RUNS" --to docs/inflight --max-mb 40
du -sh docs/inflight
