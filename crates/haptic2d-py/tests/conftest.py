"""Shared fixtures: the `haptic2d` CLI binary the equality tests compare against.

The binary is `$HAPTIC2D_BIN`, else the repository's target/{release,debug}/haptic2d. Without one the
comparison tests are skipped, unless `$HAPTIC2D_REQUIRE_CLI` is set (ci.sh sets it), where they fail.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]


def _find_cli() -> Path | None:
    env = os.environ.get("HAPTIC2D_BIN")
    if env:
        return Path(env)
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    for profile in ("release", "debug"):
        p = target / profile / "haptic2d"
        if p.is_file():
            return p
    return None


@pytest.fixture(scope="session")
def cli():
    """A function running the CLI with arguments; returns the completed process (checked)."""
    exe = _find_cli()
    if exe is None or not exe.is_file():
        msg = f"haptic2d CLI not found (HAPTIC2D_BIN={os.environ.get('HAPTIC2D_BIN')!r}); build it with cargo build -p haptic2d-cli"
        if os.environ.get("HAPTIC2D_REQUIRE_CLI"):
            pytest.fail(msg)
        pytest.skip(msg)

    def run(*args: str) -> subprocess.CompletedProcess:
        r = subprocess.run([str(exe), *args], capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, f"haptic2d {' '.join(args)} failed:\n{r.stderr}"
        return r

    return run


@pytest.fixture(scope="session")
def fig_dir(cli, tmp_path_factory):
    """`haptic2d reproduce fig4` and `fig7` written once per session; returns the output folder."""
    out = tmp_path_factory.mktemp("reproduction")
    cli("reproduce", "fig4", "--out", str(out))
    cli("reproduce", "fig7", "--out", str(out))
    return out
