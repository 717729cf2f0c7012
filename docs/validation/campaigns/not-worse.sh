#!/usr/bin/env bash
# The prediction check as its purpose states it (validation/selection.py PREDICTION_NOT_WORSE; campaigns.md, "The
# held-out check asks only that a fit not predict worse"), judged on fresh seeds 111-115, fixed on 2026-11-29 before
# any of their draws: the single goal it was chosen for first, then the two that guard against wrong names (outside
# the catalogue on the whole domain, and with the load and gravity varied independently), then pairs and null data.
# Each resumable: rerun this script after an interruption and finished draws are kept.
#   nohup bash docs/validation/campaigns/not-worse.sh >> /work/runs/not-worse.out 2>&1 &
set -u
cd "$(dirname "$0")/../../.."
PY=${PYTHON:-.venv/bin/python}
for spec in "single 44 112 whole-domain" "ooc 35 114 whole-domain" "ooc-load 40 115 factorial" \
            "pair 30 113 whole-domain" "null 50 111 whole-domain"; do
  set -- $spec
  "$PY" docs/validation_campaign.py "$1" --draws "$2" --seed "$3" --design "$4" --workers 1 \
    --resume >> "docs/validation/campaigns/$1-$3.log" 2>&1
done
