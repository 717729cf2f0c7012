#!/bin/bash
# The held-out check of wheelsoil.parameters.cmu_sand (issue 33): the CMU K10-mini wheels pressed into the calibrated
# soil, compared with the sand's measured wheel-sinkage curves, which no calibration step used. The wheel is 50 mm
# wide, so it runs on the particles scaled x0.8 (5.12-7.68 mm, 6.5 across: the lab's resolution rule), the scale of
# the CMU twin's cases; the calibration itself ran at 6.4-9.6 mm (the plate's scale change at x0.8 is in
# docs/soillab/scale). Seed 0, each wheel once.
# Usage: CACHE=/tmp/lab/cache bash docs/soillab/cmu-sand/run.sh [WHEEL ...]
set -e
wheels=("$@")
[ ${#wheels[@]} -eq 0 ] && wheels=(grouser smooth)
for wheel in "${wheels[@]}"; do
  out=docs/soillab/cmu-sand/wheel-$wheel
  [ -f $out/wheel.json ] && { echo "$out: done before, kept"; continue; }
  /usr/bin/time -f "wheel $wheel: %e s wall, %M KiB peak" wheelsoil soil-lab wheel --wheel $wheel \
    --dmin 0.00512 --dmax 0.00768 --density 2541 --friction 0.52 --rolling-friction 0.5 --rolling-model epsd \
    --seeds 0 --out $out ${CACHE:+--cache $CACHE}
done
