#!/usr/bin/env bash
# Builds the policy FMU library (flyloop-fmu-policy: tract-onnx) and packs the shipped hover
# policy: dist/fmu/HexaHoverPolicy.fmu (FMI 2.0) and HexaHoverPolicy-fmi3.fmu (FMI 3.0), from
# policies/hexa_hover (recipe.json + model.onnx, written by examples/train/export_onnx.py).
# Usage: bash scripts/pack-policy-fmus.sh [out-dir]    (honours CARGO_TARGET_DIR)
set -euo pipefail
cd "$(dirname "$0")/.."

out="${1:-dist/fmu}"
target="${CARGO_TARGET_DIR:-target}"

cargo build --release -q -p flyloop-fmu --bins
cargo build --release -q -p flyloop-fmu-policy --lib --bins
mkdir -p "$out"
"$target/release/flyloop-fmu-pack" policy policies/hexa_hover -o "$out/HexaHoverPolicy.fmu"
