#!/usr/bin/env bash
# The soil lab on its default (uncalibrated) particles, every test, with the CMU sand's measurements beside.
# Run from the repository root with ../shared beside it; beds are cached in $CACHE (default the user cache).
set -euo pipefail
OUT=docs/soillab/baseline
CACHE=${CACHE:+--cache $CACHE}
for test in poured repose shear; do
  /usr/bin/time -f "$test: %e s wall, %M KiB peak" wheelsoil soil-lab $test --out $OUT $CACHE
done
/usr/bin/time -f "plate: %e s wall, %M KiB peak" wheelsoil soil-lab plate --seeds 0 1 2 --shear-json $OUT/shear.json --out $OUT $CACHE
for wheel in smooth grouser; do
  /usr/bin/time -f "wheel $wheel: %e s wall, %M KiB peak" wheelsoil soil-lab wheel --wheel $wheel --out $OUT/wheel-$wheel $CACHE
done
