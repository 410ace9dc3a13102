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
# cargo-nextest when it is installed (a process per test, faster; doctests apart); otherwise
# cargo's own runner, doctests included. Both take cargo's default targets, so a target with
# `test = false` (a binary without unit tests) is not linked as a test.
if cargo nextest --version >/dev/null 2>&1; then
    say "Rust tests (cargo nextest, then the doctests)"
    cargo nextest run --workspace --release
    cargo test --workspace --release --doc
else
    say "Rust tests and doctests (cargo test; cargo-nextest is not installed)"
    cargo test --workspace --release
fi
say "ruff"
.venv/bin/ruff check .
.venv/bin/ruff format --check .
say "Wheel: pip wheel ./python in a fresh venv, every env id with both backends"
bash scripts/wheel-smoke.sh
say "Python system tests (pytest)"
# On up to 4 workers, one per core (pytest-xdist): most suites wait on processes and sockets,
# and the training tests keep one core each. One worker more than the cores (3 on 2) cut
# pytest from 868 to 751-790 s but failed a real-time PX4 offboard flight under the load
# (policy in Python, load 10). conftest.py keeps the tests that share a resource on one
# worker, and prints where each worker's time went.
workers=$(( $(nproc) < 4 ? $(nproc) : 4 ))
# The slowest tests at the end of the log: the groups that set how long CI takes.
.venv/bin/pytest -q -n "$workers" --dist loadgroup --durations=25
