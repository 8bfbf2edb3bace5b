#!/usr/bin/env bash
# The split loop under Linux netem (issue 41 item 3): where this machine can put a netem qdisc on the
# loopback of a fresh network namespace (root, util-linux's unshare, iproute2's tc, the sch_netem
# kernel module), run the end-to-end test that puts both processes of the split loop in such a
# namespace at 25 ms delay and 5 % loss each way (crates/haptic2d-cli/tests/it/cli_teleop.rs,
# `netem_in_a_namespace_…`). Where it cannot, say exactly why and run nothing: the test itself is
# never reported as passed without netem (it is #[ignore]d in the normal suite and fails when run
# without netem).
set -uo pipefail
cd "$(dirname "$0")/.."
probe="ip link set lo up && tc qdisc add dev lo root netem delay 1ms"
if ! command -v unshare >/dev/null || ! command -v tc >/dev/null; then
  echo "netem test not run: unshare (util-linux) or tc (iproute2) is missing"
  exit 0
fi
if ! why=$(unshare -n sh -c "$probe" 2>&1); then
  echo "netem test not run: no netem qdisc in a network namespace on this machine ($why)"
  echo "  (needs root and the sch_netem kernel module; run it where they exist:"
  echo "   cargo test -p haptic2d-cli --test it cli_teleop::netem -- --ignored)"
  exit 0
fi
echo "netem is available: running the split loop under it"
exec cargo test -p haptic2d-cli --test it cli_teleop::netem -- --ignored
