# Sourced by the scripts that check haptic2d's outputs with independent Python packages
# (check_mcap.sh, check_foxglove.sh). Sets BIN to the haptic2d binary to check (the first
# argument, else target/debug/haptic2d, built when missing) and defines `checker_venv DIR IMPORTS
# PACKAGE…`: a venv at DIR (created once) in which `import IMPORTS` works (PACKAGEs installed with
# pip when it does not).
BIN="${1:-target/debug/haptic2d}"
[ -x "$BIN" ] || cargo build -q -p haptic2d-cli

checker_venv() {
  local venv="$1" imports="$2"
  shift 2
  [ -x "$venv/bin/python" ] || python3 -m venv "$venv"
  "$venv/bin/python" -c "import $imports" 2>/dev/null ||
    "$venv/bin/pip" install -q --disable-pip-version-check "$@"
}
