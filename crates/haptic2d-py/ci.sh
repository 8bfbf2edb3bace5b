#!/usr/bin/env bash
# CI for the Python API, as a user of a published wheel installs it: `maturin build --release`
# builds the abi3 wheel once (target/wheels), a fresh virtual environment (target/py-venv) installs
# that wheel with pip, then stubtest and pytest run against the installed package (docs/PYTHON.md).
# The Rust build shares the repository's target directory (CARGO_TARGET_DIR), so a second run
# rebuilds only what changed. Exits non-zero on any failure, including "no tests ran" (pytest 5).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$root"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"
export CARGO_TERM_COLOR=never
crate=crates/haptic2d-py
venv="$CARGO_TARGET_DIR/py-venv"
start=$(date +%s)
stage() { echo "== python [$(( $(date +%s) - start )) s]: $*"; }

stage "cargo fmt --check and clippy (crates/haptic2d-py is its own workspace)"
cargo fmt --manifest-path "$crate/Cargo.toml" -- --check
cargo clippy --manifest-path "$crate/Cargo.toml" --all-targets -- -D warnings

stage "build the abi3 wheel: maturin build --release (in its own venv)"
buildenv="$CARGO_TARGET_DIR/py-build"
python3 -m venv --clear "$buildenv"
"$buildenv/bin/python" -m pip install --quiet --disable-pip-version-check "maturin>=1.7,<2"
wheels="$CARGO_TARGET_DIR/wheels"
rm -rf "$wheels"
"$buildenv/bin/maturin" build --release --manifest-path "$crate/Cargo.toml" --out "$wheels"
wheel=$(ls "$wheels"/haptic2d-*-abi3-*.whl)
stage "fresh venv at $venv; pip install $(basename "$wheel")"
python3 -m venv --clear "$venv"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "$wheel"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check pytest "dask[distributed]" mypy

# The equality tests compare with the `haptic2d` binary's own output.
stage "the haptic2d CLI the tests compare against"
cargo build --quiet -p haptic2d-cli
export HAPTIC2D_BIN="$CARGO_TARGET_DIR/debug/haptic2d"
export HAPTIC2D_REQUIRE_CLI=1

cd "$root/$crate"
stage "stubtest (the .pyi stubs match the installed package)"
"$venv/bin/python" -m mypy.stubtest haptic2d

stage "pytest $crate/tests"
status=0
"$venv/bin/python" -m pytest tests -q -p no:cacheprovider || status=$?
stage "done in $(( $(date +%s) - start )) s (pytest exit $status)"
exit "$status"
