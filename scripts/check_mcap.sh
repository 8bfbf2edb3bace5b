#!/usr/bin/env bash
# Checks a haptic2d MCAP recording with the `mcap` PyPI package (issue 14): installs `mcap` into a
# venv under target/, records a 2 s headless run as MCAP and the same deterministic run as CSV, and
# runs scripts/read_mcap.py on them. Usage: scripts/check_mcap.sh [PATH/TO/haptic2d]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/checker_venv.sh
VENV=target/mcap-venv
checker_venv "$VENV" mcap 'mcap>=1.2'
OUT=$(mktemp -d target/mcap-check.XXXXXX)
trap 'rm -rf "$OUT"' EXIT
"$BIN" run --headless --no-rt --duration 2 --log "$OUT/run.mcap" >/dev/null
"$BIN" run --headless --no-rt --duration 2 --log "$OUT/run.csv" >/dev/null
"$VENV/bin/python" scripts/read_mcap.py "$OUT/run.mcap" --csv "$OUT/run.csv"
