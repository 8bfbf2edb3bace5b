#!/usr/bin/env bash
# The README's test command: installs what the tests need (idempotent, quick once done), then runs
# every test of the workspace, the optional device drivers included. Nothing is skipped: a test whose
# prerequisite is missing fails with the command that installs it.
#
#   bash scripts/test.sh                 # everything
#   bash scripts/test.sh -p haptic2d     # extra arguments go to `cargo test`
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-test-deps.sh
exec cargo test --workspace --features haptic2d-cli/inverse3 "$@"
