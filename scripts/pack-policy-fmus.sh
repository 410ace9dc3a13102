#!/usr/bin/env bash
# Builds the policy FMU library (flyloop-fmu-policy: tract-onnx) and packs the shipped
# policies (recipe.json + model.onnx, written by examples/train/export_onnx.py), each as an
# FMI 2.0 FMU and its -fmi3.fmu twin: dist/fmu/HexaHoverPolicy.fmu from policies/hexa_hover
# (motor commands), dist/fmu/OffboardPolicy.fmu from policies/px4_offboard_hover
# (RateController.fmu's setpoint).
# Usage: bash scripts/pack-policy-fmus.sh [out-dir]    (honours CARGO_TARGET_DIR)
set -euo pipefail
cd "$(dirname "$0")/.."

out="${1:-dist/fmu}"
target="${CARGO_TARGET_DIR:-target}"

cargo build --release -q -p flyloop-fmu --bins
cargo build --release -q -p flyloop-fmu-policy --lib --bins
mkdir -p "$out"
"$target/release/flyloop-fmu-pack" policy policies/hexa_hover -o "$out/HexaHoverPolicy.fmu"
"$target/release/flyloop-fmu-pack" policy policies/px4_offboard_hover -o "$out/OffboardPolicy.fmu"
