#!/bin/bash
# The rolling-resistance law under the plate (issue 33): the 100 mm plate on the grid's best particles (sliding 0.5,
# rolling 0.5, density 2469.6 kg/m^3), poured and pressed with the EPSD law at 30, 7.5 and 15 mm/s (seed 0), and
# with the CDT law at 30 mm/s again on a bed of format 4 (walled box, history signs fixed) as the control.
# Usage: CACHE=/tmp/lab/cache bash docs/soillab/rolling-law/run.sh [LAW SPEED ...]  (about an hour on 2 cores)
set -e
runs=("$@")
[ ${#runs[@]} -eq 0 ] && runs=(epsd 0.03 epsd 0.0075 cdt 0.03 epsd 0.015)
for ((k = 0; k < ${#runs[@]}; k += 2)); do
  law=${runs[k]}; speed=${runs[k+1]}
  out=docs/soillab/rolling-law/$law-$speed
  [ -f $out/plate.json ] && { echo "$out: done before, kept"; continue; }
  /usr/bin/time -f "$law, speed $speed: %e s wall, %M KiB peak" wheelsoil soil-lab plate --friction 0.5 \
    --rolling-friction 0.5 --rolling-model $law --density 2469.6 --plate 0.1 --seeds 0 --speed $speed --out $out \
    ${CACHE:+--cache $CACHE}
done
