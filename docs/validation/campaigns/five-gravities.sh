#!/usr/bin/env bash
# The gravity ties, as a question of design (campaigns.md, "The gravity ties: five gravity levels"), fixed on 2026-11-29
# before any of its draws: the same rule as not-worse.sh (validation/selection.py, PREDICTION_NOT_WORSE; no change),
# the whole-domain design at five gravity levels instead of three (--design whole-domain-5g), fresh seeds 121-124.
# The single goal first, then wrong names outside the catalogue, pairs, null data. (Wrong names with the load and
# gravity varied independently have their own design, unchanged: ooc-load-115, 0 of 40.) Each resumable: rerun this
# script after an interruption and finished draws are kept.
#   nohup bash docs/validation/campaigns/five-gravities.sh >> /work/runs/five-gravities.out 2>&1 &
set -u
cd "$(dirname "$0")/../../.."
PY=${PYTHON:-.venv/bin/python}
for spec in "single 44 122 whole-domain-5g" "ooc 35 124 whole-domain-5g" "pair 30 123 whole-domain-5g" \
            "null 50 121 whole-domain-5g"; do
  set -- $spec
  "$PY" docs/validation_campaign.py "$1" --draws "$2" --seed "$3" --design "$4" --workers 1 \
    --resume >> "docs/validation/campaigns/$1-$3.log" 2>&1
done
