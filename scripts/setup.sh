#!/usr/bin/env bash
# Sets up everything on a fresh machine (Debian packages, a Python venv in .venv, the Rust
# build) and runs the main demo. Usage: bash scripts/setup.sh [--no-demo]
set -euo pipefail
cd "$(dirname "$0")/.."

demo=1
[[ "${1:-}" == "--no-demo" ]] && demo=0

say() { printf '\n==> %s (at %d s)\n' "$*" "$SECONDS"; }
fail() { printf '\nsetup.sh: %s\n' "$*" >&2; exit 1; }

# The toolchains first, so a missing one is one clear line and not a failure 15 minutes in.
# Rust: the workspace uses edition 2024 (rust-version in Cargo.toml), i.e. Rust >= 1.85.
rust_min=$(sed -n 's/^rust-version = "\(.*\)"/\1/p' Cargo.toml)
command -v cargo >/dev/null && command -v rustc >/dev/null ||
    fail "cargo and rustc not found: install Rust >= $rust_min (e.g. with rustup), then re-run."
rust_version=$(rustc --version | awk '{print $2}')
[[ $(printf '%s\n%s\n' "$rust_min" "${rust_version%%-*}" | sort -V | head -1) == "$rust_min" ]] ||
    fail "Rust $rust_version is too old: the workspace needs >= $rust_min (edition 2024); run 'rustup update stable'."
command -v python3 >/dev/null || fail "python3 not found: install Python >= 3.10."
python3 -c 'import sys; sys.exit(sys.version_info < (3, 10))' ||
    fail "$(python3 --version) is too old: flyloop needs Python >= 3.10."

packages=$(grep -v '^#' scripts/apt-packages.txt | xargs)
missing=$(for p in $packages; do dpkg -s "$p" >/dev/null 2>&1 || echo "$p"; done | xargs)
if [[ -n "$missing" ]]; then
    say "Debian packages: $missing"
    if [[ $(id -u) -eq 0 ]]; then
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing >/dev/null
    else
        sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing >/dev/null
    fi
fi

say "Python venv .venv (test peers: fmpy, libcosimpy, pymavlink, MAVProxy, pytest), beside the Rust build"
[[ -x .venv/bin/python ]] || python3 -m venv .venv
# pip mostly downloads and unpacks (torch, ray: ~2.5 min) while cargo keeps both cores busy
# compiling: run side by side, they save most of pip's time. The build only needs .venv's
# interpreter (scripts/cargo-env.sh), which exists now.
(.venv/bin/pip install -q --upgrade pip && .venv/bin/pip install -q -r tests/requirements.txt) &
pip_job=$!

. scripts/cargo-env.sh
say "Rust build (release: the SITL, the FMU library, the extension's crate, the hover demo)"
# Tests are built by scripts/test.sh, benchmarks by `cargo bench`. pack-fmus.sh, maturin and
# the test suites reuse this build: scripts/cargo-env.sh and the workspace-hack crate keep
# their cargo runs on the same dependency builds.
if ! cargo build --release --workspace --lib --bins --example hover; then
    wait "$pip_job" || true
    fail "the Rust build failed (above)."
fi
say "Waiting for pip (the Python packages)"
wait "$pip_job" || fail "pip install -r tests/requirements.txt failed (above)."

say "Python package flyloop with its extension flyloop._native (editable, maturin)"
# maturin builds the extension into the workspace's target/ with the release profile, so it
# reuses what the cargo build above compiled. --no-build-isolation: maturin comes from
# tests/requirements.txt (PATH lets pip's maturin hook find it).
PATH="$PWD/.venv/bin:$PATH" .venv/bin/pip install -q --no-build-isolation -e python

say "FMUs → dist/fmu/"
bash scripts/pack-fmus.sh

if [[ $demo -eq 1 ]]; then
    say "Demo 1: the Hover task flown by a PD controller in the Rust core"
    # The example the workspace build above made (`cargo run -p flyloop-core` would resolve
    # features for that crate alone and recompile shared dependencies).
    target/release/examples/hover
    say "Demo 2: Quadrotor.fmu simulated with fmpy (plot)"
    .venv/bin/python examples/fmu_fmpy_demo.py
    say "Demo 3: the SITL flown through the gym env by a PD controller (GIF)"
    .venv/bin/python examples/demo_gym_pd.py
fi
