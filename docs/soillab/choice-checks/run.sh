#!/bin/bash
# Issue 33's owed checks, on the wide-box calibration's choice (docs/soillab/README.md, "What is missing"). Fixed on
# 2026-11-29 before the calibration's tenth candidate had finished (so before its choice was known) and before any of
# these ran. The choice is read from the calibration by its rule (`docs/soillab_calibration.py choice`); the script
# refuses to start until all ten candidates have finished. Each step is kept once its JSON exists, and the plates keep
# their state every 10 samples, so the script resumes across sessions. In order (cheapest first):
#   1. repose: the draw-down with seeds 0, 1 and 2 (seed 0 is the calibration's own: it must give its angle again);
#   2. shear speed: the shear box at the calibration's 20 mm/s and at half of it (10 mm/s), seed 0. Quasi-static when
#      every normal stress's peak shear stress changes by less than 10 % (the lab's tolerance);
#   3. plate replicas: both plates in the wide box (0.6 x 0.6 x 0.12 m) with seeds 1 and 2 (seed 0 is the
#      calibration's). For cmu_sand's own particles the 100 mm plate's seeds 1 and 2 exist already (docs/soillab/box/
#      wide-seed1, wide-seed2: the same command), so only the 60 mm plate runs;
#   4. wheel replicas: the held-out wheel check (docs/soillab/cmu-sand/run.sh: both CMU wheels at x0.8 particles, the
#      twin's scale; its command, without checkpoints) with seeds 1 and 2, and seed 0 too when the choice is not
#      cmu_sand's particles;
#   5. particle scale: the 100 mm plate in the wide box at x1, x0.8 and x0.64 particles, seed 0 (x1 repeats the
#      calibration's own plate: the same bed and press, so the same curve), extrapolated to zero size with the
#      x1 replicas of step 3 as further points (python docs/soillab_choice_checks.py).
# The summary: python docs/soillab_choice_checks.py [--out docs/soillab/choice-checks]
# Cost on 2 cores beside one other job, from the lab's earlier runs: 1 about 3 min, 2 about 10 min, 3 about an hour
# (bed 10 min and plate 20 min a seed), 4 about an hour (15 min a wheel), 5 about five hours (x0.64: ~300,000 spheres).
# Usage: CACHE=RUNS/lab-cache bash docs/soillab/choice-checks/run.sh
set -euo pipefail
cd "$(dirname "$0")/../../.."
PY=${PYTHON:-.venv/bin/python}
WHEELSOIL=${WHEELSOIL:-$(dirname "$PY")/wheelsoil}
out=${OUT:-docs/soillab/choice-checks}
# CALIBRATION, DESIGN: another calibration's choice (default the wide-box one, which the checks were fixed for)
choice=$("$PY" docs/soillab_calibration.py choice "${CALIBRATION:-docs/soillab/calibration-epsd-box}" \
  --design "${DESIGN:-epsd-box}" | tail -n 1)
values=$("$PY" -c "import json, sys; r = json.load(open(sys.argv[1])); \
print(r['friction'], r['rolling_friction'], r['density'], r['rolling_model'])" "$choice")
read -r mu mur rho law <<< "$values"
echo "choice: $choice (sliding $mu, rolling $mur, density $rho, $law)"
cmu_sand=$("$PY" -c "from wheelsoil.parameters import cmu_sand as s; import sys; \
print(int((s.PARTICLE_PAIR.static_friction, s.PARTICLE_PAIR.rolling_friction, s.PARTICLE_MATERIAL.density, \
s.PARTICLE_PAIR.rolling_model) == (float(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), sys.argv[4])))" \
  "$mu" "$mur" "$rho" "$law" | tail -n 1)
particles=(--friction "$mu" --rolling-friction "$mur" --density "$rho" --rolling-model "$law")
lab=(--dmin 0.0064 --dmax 0.0096)
twin=(--dmin 0.00512 --dmax 0.00768)
step() {  # step NAME TEST ARGS...: wheelsoil soil-lab TEST into $out/NAME unless its TEST.json exists
  local name=$1 test=$2; shift 2
  if [ -f "$out/$name/$test.json" ]; then echo "$name: done before, kept"; return; fi
  /usr/bin/time -f "$name: %e s wall, %M KiB peak" "$WHEELSOIL" soil-lab "$test" "${particles[@]}" "$@" \
    --out "$out/$name" ${CACHE:+--cache "$CACHE"}
}
step repose repose "${lab[@]}" --seeds 0 1 2
step shear-20mms shear "${lab[@]}" --speed 0.02 --seeds 0
step shear-10mms shear "${lab[@]}" --speed 0.01 --seeds 0
plates=(0.06 0.1)
[ "$cmu_sand" = 1 ] && plates=(0.06)
for seed in 1 2; do
  step "plate-seed$seed" plate "${lab[@]}" --plate "${plates[@]}" --box 0.6 0.6 0.12 --seeds "$seed" \
    --checkpoint-every 10
done
seed_plates=("$out/plate-seed1" "$out/plate-seed2")
[ "$cmu_sand" = 1 ] && seed_plates+=(docs/soillab/box/wide-seed1 docs/soillab/box/wide-seed2)
"$PY" docs/soillab_calibration.py figure "${CALIBRATION:-docs/soillab/calibration-epsd-box}" \
  --design "${DESIGN:-epsd-box}" --seed-plates "${seed_plates[@]}"   # the plates of every seed in one figure
wheel_seeds=(1 2)
[ "$cmu_sand" = 1 ] || wheel_seeds=(0 1 2)
for wheel in grouser smooth; do
  for seed in "${wheel_seeds[@]}"; do
    step "wheel-$wheel-seed$seed" wheel "${twin[@]}" --wheel "$wheel" --seeds "$seed"
  done
done
"$PY" docs/soillab_scale.py run --out "$out/scale" --candidate "$choice" --box 0.6 0.6 0.12 --scales 1 0.8 0.64 \
  --seeds 0 --resume --checkpoint-every 10 ${CACHE:+--cache "$CACHE"}
"$PY" docs/soillab_choice_checks.py --out "$out"
