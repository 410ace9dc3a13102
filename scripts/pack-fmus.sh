#!/usr/bin/env bash
# Builds the FMU library and tools (release) and packs dist/fmu/Quadrotor.fmu, Lander2D.fmu,
# Hexacopter.fmu, RateController.fmu and AttitudeController.fmu (FMI 2.0) and their FMI 3.0 twins dist/fmu/<Model>-fmi3.fmu.
# Usage: bash scripts/pack-fmus.sh [out-dir]    (honours CARGO_TARGET_DIR)
set -euo pipefail
cd "$(dirname "$0")/.."

out="${1:-dist/fmu}"
target="${CARGO_TARGET_DIR:-target}"

cargo build --release -q -p flyloop-fmu --lib --bins
"$target/release/flyloop-fmu-pack" fmus "$target/release/libflyloop_fmu.so" "$out"
