#!/bin/bash
# The quasi-static check of the plate test (issue 33): the 100 mm plate on the grid's best particles (sliding 0.5,
# rolling 0.5, density 2469.6 kg/m^3 for the sand's bulk density), pressed at the lab's 30 mm/s, at half and at a
# quarter of it (seed 0), and again at 30 and 15 mm/s on a second packing (seed 1).
# Usage: CACHE=/tmp/lab/cache bash docs/soillab/speed/run.sh [SEED SPEED ...]  (about an hour on 2 cores)
set -e
runs=("$@")
[ ${#runs[@]} -eq 0 ] && runs=(0 0.03 0 0.015 0 0.0075 1 0.03 1 0.015)
for ((k = 0; k < ${#runs[@]}; k += 2)); do
  seed=${runs[k]}; speed=${runs[k+1]}
  out=docs/soillab/speed/seed$seed-$speed
  [ -f $out/plate.json ] && { echo "$out: done before, kept"; continue; }
  /usr/bin/time -f "seed $seed, speed $speed: %e s wall, %M KiB peak" wheelsoil soil-lab plate --friction 0.5 \
    --rolling-friction 0.5 --density 2469.6 --plate 0.1 --seeds $seed --speed $speed --out $out ${CACHE:+--cache $CACHE}
done
