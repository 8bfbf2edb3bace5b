#!/usr/bin/env bash
# Checks the live Foxglove server of `haptic2d run --foxglove` with a client independent of haptic2d
# (issue 14): installs `websockets` and `jsonschema` into a venv under target/ and runs
# scripts/foxglove_client_check.py (a foxglove.websocket.v1 client written from the protocol spec;
# the Foxglove Python packages ship servers only). About 10 s plus the pip install.
# Usage: scripts/check_foxglove.sh [PATH/TO/haptic2d]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/checker_venv.sh
VENV=target/foxglove-venv
checker_venv "$VENV" "websockets.sync.client, jsonschema" 'websockets>=13' 'jsonschema>=4'
"$VENV/bin/python" scripts/foxglove_client_check.py "$BIN"
