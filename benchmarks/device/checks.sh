#!/bin/bash
# Issue 37 item 3: the GPU checks as one prepared script, for a session whose task is lent a device machine.
# From this machine, after `bash benchmarks/device/prepare.sh` (once per session; .device/ is ignored by git):
#   device run: command "bash benchmarks/device/checks.sh", carry [".device"], timeout_s 580
# It installs nothing system-wide: the packages of .device/ and wheelsoil (its packages laid out as pyproject.toml's
# package-dir maps them) go into one folder on PYTHONPATH. Then, each step under its own time limit so one that hangs
# leaves the others their time, with WHEELSOIL_ARCH=cuda (the same code; ARCH=cpu rehearses it here):
#   1. the backend answers (runtime.init, the device named);
#   2. verification tests on that backend, those of tests/portable.txt: the Hertz / Mindlin contact checks, the beam
#      and ring elements, the sphere-wheel contact, the bed and the force balance (the tests read WHEELSOIL_ARCH,
#      tests/conftest.py; tests/test_backends.py runs the same list on every device backend a machine has);
#   3. benchmarks/dem_throughput.py without LIGGGHTS on the 53k bed (its bed prepared there: no cache travels);
#   4. (STEPS="dem388k", a second run) the seed-004 388k bed as well (--memory-check).
# Everything it writes goes to $OUT (checks.log, a log per step, nvidia-smi.txt, dem-throughput-*.json), which the
# device tool brings back. The default steps take at most 9 minutes (their limits), most of it Taichi compiling for
# the device the first time and the beds' preparation; rehearsed on the CPU backend they run to their limits.
set -uo pipefail
OUT=${OUT:-/tmp/device-out}
ARCH=${ARCH:-cuda}
SITE=${SITE:-/tmp/wheelsoil-site}
mkdir -p "$OUT"
log() { echo "[$(date +%T) +$SECONDS s] $*" | tee -a "$OUT/checks.log"; }
step() {  # step LIMIT_S NAME COMMAND...: run with a limit, log its exit status
  local limit=$1 name=$2; shift 2
  log "start $name (limit ${limit} s)"
  timeout "$limit" "$@" 2>&1 | tee -a "$OUT/$name.log"
  log "end $name: exit ${PIPESTATUS[0]}"
}
[ -f .device/taichi.tar.xz ] || { log "no .device/taichi.tar.xz: run benchmarks/device/prepare.sh here and carry .device"; exit 2; }
rm -rf "$SITE" && mkdir -p "$SITE"
tar -xJf .device/taichi.tar.xz -C "$SITE" || { log "unpacking taichi failed"; exit 3; }
python3 -m pip install -q --no-deps --no-index --target "$SITE" .device/wheels/*.whl 2>&1 | tee -a "$OUT/checks.log" \
  || { log "the wheels do not install: .device/ prepared for another Python (PYVER of prepare.sh)?"; exit 4; }
python3 - "$SITE" <<'PY' || exit 5
import shutil, sys, tomllib
site = sys.argv[1]
dirs = tomllib.load(open("pyproject.toml", "rb"))["tool"]["setuptools"]["package-dir"]
for package, folder in sorted(dirs.items()):  # wheelsoil first, its sub-packages into it
    shutil.copytree(folder, f"{site}/{package.replace('.', '/')}", dirs_exist_ok=True,
                    ignore=shutil.ignore_patterns("__pycache__"))
PY
export PYTHONPATH="$SITE" WHEELSOIL_ARCH="$ARCH" PYTHONUNBUFFERED=1 WHEELSOIL_TAICHI_CACHE=/tmp/wheelsoil-taichi-cache
log "python $(python3 -c 'import sys; print(sys.version.split()[0])'), arch $ARCH, site ready"
(nvidia-smi || echo "no nvidia-smi") > "$OUT/nvidia-smi.txt" 2>&1
# STEPS: which checks, in this order (default the first three; dem388k, the seed-004 bed, in a second run if the
# session's device time allows: 15 minutes in all, the machine's start included)
STEPS=${STEPS:-"backend tests dem53k"}
for name in $STEPS; do
  case $name in
    backend) step 90 backend python3 -P -c \
      "from wheelsoil import runtime; import taichi as ti; print('arch in use:', runtime.init())" ;;
    tests) step 180 tests python3 -P -m pytest -v --tb=short -p no:cacheprovider -m "not slow" \
      $(grep -v '^#' tests/portable.txt) ;;
    dem53k) step 240 dem53k python3 -P -m wheelsoil.benchmarks.dem_throughput --no-liggghts --rounds 2 --steps 1000 \
      --out "$OUT/dem-throughput-53k-$ARCH.json" ;;
    dem388k) step 420 dem388k python3 -P -m wheelsoil.benchmarks.dem_throughput --no-liggghts --rounds 1 \
      --steps 500 --memory-check --out "$OUT/dem-throughput-388k-$ARCH.json" ;;
    *) log "unknown step $name: choose from backend tests dem53k dem388k"; exit 6 ;;
  esac
done
log "done"
