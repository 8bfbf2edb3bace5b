#!/usr/bin/env bash
# Issue 14: the 10 kHz loop's on-time fraction with `--log x.mcap` vs without, from the loop's own
# statistics (the run's "on time: P % of N deadlines" line), interleaved runs.
# Usage: scripts/mcap_ontime.sh [BIN] [REPS] [DURATION_S] [RATE_HZ]
# (defaults: target/release/haptic2d, 3, 20, 10000). Prints one line per run and the means.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN="${1:-target/release/haptic2d}"
REPS="${2:-3}"
DUR="${3:-20}"
RATE="${4:-10000}"
[ -x "$BIN" ] || { echo "no $BIN: cargo build --release -p haptic2d-cli" >&2; exit 2; }
OUT=$(mktemp -d target/mcap-ontime.XXXXXX)
trap 'rm -rf "$OUT"' EXIT
ontime() { sed -n 's/^on time: \([0-9.]*\) % of.*/\1/p' | tail -n1; }
plain=(); logged=()
for r in $(seq 1 "$REPS"); do
  p=$("$BIN" run --headless --rate "$RATE" --duration "$DUR" 2>&1 | ontime)
  out=$("$BIN" run --headless --rate "$RATE" --duration "$DUR" --log "$OUT/x.mcap" 2>&1)
  l=$(echo "$out" | ontime)
  w=$(echo "$out" | sed -n 's/.*log: \([0-9]*\) ticks written.*/\1/p' | tail -n1)
  echo "rep $r: without log ${p} %   with --log x.mcap ${l} % (${w} ticks written, $(du -k "$OUT/x.mcap" | cut -f1) KiB)"
  plain+=("$p"); logged+=("$l")
  rm -f "$OUT/x.mcap"
done
mean() { printf '%s\n' "$@" | awk '{s+=$1} END {printf "%.3f", s/NR}'; }
echo "mean on-time: without log $(mean "${plain[@]}") %, with --log x.mcap $(mean "${logged[@]}") %"
