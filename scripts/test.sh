#!/usr/bin/env bash
# Runs every check and test: formatting, lints, Rust tests, Python lint and system tests.
# Needs scripts/setup.sh to have run once (it creates .venv).
set -euo pipefail
cd "$(dirname "$0")/.."

say() { printf '\n==> %s (at %d s)\n' "$*" "$SECONDS"; }
. scripts/cargo-env.sh

say "cargo fmt --check"
cargo fmt --all --check
say "cargo clippy (all targets, warnings are errors)"
cargo clippy --workspace --all-targets -- -D warnings
say "cargo check of the fuzz target (sitl/fuzz: its own workspace; fuzzing itself needs nightly)"
# With the workspace's lock file and target directory it reuses what clippy just checked.
cp Cargo.lock sitl/fuzz/Cargo.lock
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}" cargo check --quiet --manifest-path sitl/fuzz/Cargo.toml
# cargo-nextest when it is installed (a process per test, faster); otherwise cargo's own
# runner over the same targets (lib, bins, integration tests; doctests below).
if cargo nextest --version >/dev/null 2>&1; then
    say "Rust tests (cargo nextest)"
    cargo nextest run --workspace --release
else
    say "Rust tests (cargo test; cargo-nextest is not installed)"
    cargo test --workspace --release --lib --bins --tests
fi
say "Rust doctests"
cargo test --workspace --release --doc
say "ruff"
.venv/bin/ruff check .
.venv/bin/ruff format --check .
say "Wheel: pip wheel ./python in a fresh venv, every env id with both backends"
bash scripts/wheel-smoke.sh
say "Python system tests (pytest)"
# On up to 4 workers (pytest-xdist): most suites wait on processes and sockets, and the
# training tests keep one core each. conftest.py keeps the tests that share a resource on one.
workers=$(( $(nproc) < 4 ? $(nproc) : 4 ))
.venv/bin/pytest -q -n "$workers" --dist loadgroup
