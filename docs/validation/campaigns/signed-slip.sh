#!/usr/bin/env bash
# The signed-slip rule's campaigns (docs/validation/campaigns.md, "A drift along the signed slip"), one after another
# at low priority, each resumable: rerun this script after an interruption and finished draws are kept.
#   nohup bash docs/validation/campaigns/signed-slip.sh >> /work/runs/signed-slip.out 2>&1 &
set -u
cd "$(dirname "$0")/../../.."
PY=${PYTHON:-.venv/bin/python}
# The signed-slip rival with withheld mechanisms tried again in context (seeds 101-104; campaigns.md, "A withheld
# mechanism is tried again in context"). The signed-slip rival's own campaigns (ooc-94, single-92, pair-93) are
# complete; pair-93 missed the pair goal, so null-91 is not run. A campaign whose file holds another rule's draws
# stops at once (rule digest).
for spec in "pair 30 103" "ooc 35 104" "single 44 102" "null 50 101"; do
  set -- $spec
  nice -n 10 "$PY" docs/validation_campaign.py "$1" --draws "$2" --seed "$3" --design whole-domain --workers 1 \
    --resume >> "docs/validation/campaigns/$1-$3.log" 2>&1
done
