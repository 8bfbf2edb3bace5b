#!/usr/bin/env bash
# Installs what the browser end-to-end test (crates/haptic2d-cli/tests/it/browser_e2e.rs) needs: Debian's Chromium and the
# pinned playwright-core (from package-lock.json). Idempotent; CI calls it before `cargo test`.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

if ! command -v chromium >/dev/null 2>&1 && [ ! -x /usr/bin/chromium ]; then
  echo "e2e/install.sh: installing chromium (apt-get)"
  if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium >/dev/null
fi

if ! command -v node >/dev/null 2>&1; then
  echo "e2e/install.sh: node is missing (install nodejs >= 20 and npm)" >&2
  exit 1
fi

cd "$here"
if [ ! -f node_modules/playwright-core/package.json ] || \
   ! diff -q <(node -p "require('./package-lock.json').packages['node_modules/playwright-core'].version") \
             <(node -p "require('./node_modules/playwright-core/package.json').version") >/dev/null; then
  echo "e2e/install.sh: npm ci (playwright-core, pinned)"
  npm ci --no-audit --no-fund --loglevel=error
fi
echo "e2e/install.sh: chromium $(/usr/bin/chromium --version 2>/dev/null | awk '{print $2}'), node $(node --version), playwright-core $(node -p "require('./node_modules/playwright-core/package.json').version")"
