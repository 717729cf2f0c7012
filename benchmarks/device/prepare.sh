#!/bin/bash
# Issue 37 item 3: what a lent GPU machine needs to run wheelsoil, packed here into .device/ (ignored by git, carried by
# the device tool: `carry: [".device"]`). The device image has Python 3.12 with numpy, scipy, h5py, matplotlib, rich,
# pandas, pytest and PyTorch (/work/.library/device/KINDS.md), and nothing can be fetched there, so this brings the rest:
# taichi (its wheel is 54 MiB; repacked without the C API library and the examples, which Python never loads, it is
# about 23 MiB as tar.xz, so the working tree and it stay under the tool's 64 MiB), pydantic and its core, dill, meshio.
# pyvista/vtk are not brought (100+ MiB; only rendering imports them, lazily), so the checks render nothing.
# Usage, from the repository root (needs the network, a few minutes for the xz):
#   bash benchmarks/device/prepare.sh            # for the device's Python 3.12
#   PYVER=3.11 bash benchmarks/device/prepare.sh  # for a local rehearsal on this machine's Python
set -euo pipefail
PYVER=${PYVER:-3.12}
PIP=${PIP:-python3 -m pip}
out=.device
rm -rf "$out" && mkdir -p "$out/wheels" "$out/tmp"
taichi=$(python3 - <<'PY'
import re, pathlib
text = pathlib.Path("pyproject.toml").read_text()
print(re.search(r'"taichi([^"]*)"', text).group(1))
PY
)
$PIP download --no-deps --only-binary=:all: --python-version "$PYVER" --platform manylinux_2_27_x86_64 \
  --platform manylinux2014_x86_64 --platform manylinux_2_17_x86_64 -d "$out/tmp" "taichi$taichi" "pydantic>=2.5,<3" \
  pydantic-core annotated-types typing-inspection dill colorama meshio
# pydantic pins its core exactly: fetch the core version that pydantic asks for
core=$(unzip -p "$out"/tmp/pydantic-2*.whl '*/METADATA' | sed -n 's/^Requires-Dist: pydantic-core==\([0-9.]*\).*/\1/p')
rm -f "$out"/tmp/pydantic_core-*.whl
$PIP download --no-deps --only-binary=:all: --python-version "$PYVER" --platform manylinux_2_17_x86_64 \
  --platform manylinux2014_x86_64 -d "$out/tmp" "pydantic-core==$core"
mv "$out"/tmp/*.whl "$out/wheels/" && rmdir "$out/tmp"
mkdir "$out/taichi" && (cd "$out/taichi" && unzip -q ../wheels/taichi-*.whl)
rm "$out"/wheels/taichi-*.whl
tar -C "$out/taichi" --exclude=taichi/_lib/c_api --exclude=taichi/examples -cf - . | xz -6 -T0 > "$out/taichi.tar.xz"
rm -rf "$out/taichi"
du -sh "$out" "$out"/* && echo "carry .device with the device tool's run (benchmarks/device/checks.sh)"
