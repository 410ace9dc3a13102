#!/usr/bin/env bash
# Builds the wheel (`pip wheel ./python`, maturin: the extension with the SITL inside), installs
# it into a fresh venv with only its own dependencies (gymnasium, numpy, pymavlink; pip's
# cache is reused) and runs tests/wheel/smoke.py there with no cargo and no repository on
# PATH: every env id with both backends, and the `flyloop-sitl` console command.
# Needs .venv from scripts/setup.sh (maturin). Usage: bash scripts/wheel-smoke.sh
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

PATH="$repo/.venv/bin:$PATH" .venv/bin/pip wheel -q --no-deps --no-build-isolation ./python -w "$work/dist"
wheel=$(ls "$work"/dist/flyloop-*.whl)
echo "built $(basename "$wheel") ($(du -h "$wheel" | cut -f1))"
python3 -m venv "$work/venv"
"$work/venv/bin/pip" install -q "$wheel"
cd "$work"
env -u FLYLOOP_SITL -u CARGO_TARGET_DIR PATH="/usr/bin:/bin" "$work/venv/bin/python" "$repo/tests/wheel/smoke.py"
