#!/usr/bin/env bash
# Checks a haptic2d MCAP recording with the `mcap` PyPI package (issue 14): installs `mcap` into a
# venv under target/, records a 2 s headless run as MCAP and the same deterministic run as CSV, and
# runs scripts/read_mcap.py on them. Usage: scripts/check_mcap.sh [PATH/TO/haptic2d]
set -euo pipefail
cd "$(dirname "$0")/.."
BIN="${1:-target/debug/haptic2d}"
[ -x "$BIN" ] || cargo build -q -p haptic2d-cli
VENV=target/mcap-venv
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV"
fi
"$VENV/bin/python" -c 'import mcap' 2>/dev/null || "$VENV/bin/pip" install -q 'mcap>=1.2'
OUT=$(mktemp -d target/mcap-check.XXXXXX)
trap 'rm -rf "$OUT"' EXIT
"$BIN" run --headless --no-rt --duration 2 --log "$OUT/run.mcap" >/dev/null
"$BIN" run --headless --no-rt --duration 2 --log "$OUT/run.csv" >/dev/null
"$VENV/bin/python" scripts/read_mcap.py "$OUT/run.mcap" --csv "$OUT/run.csv"
