#!/usr/bin/env bash
# What the test suite needs beyond Rust, installed if missing (Debian/Ubuntu; as root or with sudo):
# - OpenSSL headers and pkg-config: the Inverse3 driver's `haply` crate (reqwest with native TLS);
# - a C compiler: the reference UDP device in C and haptic2d's board firmware are built natively by
#   their tests;
# - python3: the reference UDP device in Python;
# - Debian's Chromium, node and the pinned playwright-core: the display's browser test
#   (crates/haptic2d-view/e2e/install.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
need=()
pkg-config --exists openssl 2>/dev/null || need+=(libssl-dev pkg-config)
command -v cc >/dev/null 2>&1 || need+=(gcc libc6-dev)
command -v python3 >/dev/null 2>&1 || need+=(python3)
command -v node >/dev/null 2>&1 || need+=(nodejs npm)
if [ ${#need[@]} -gt 0 ]; then
  echo "install-test-deps: apt-get install ${need[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}" >/dev/null
fi
bash crates/haptic2d-view/e2e/install.sh
