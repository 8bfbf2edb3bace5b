"""Bad inputs raise clear Python exceptions and never crash the interpreter."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

import haptic2d
from haptic2d import SceneError, World, harness

NON_CONVEX = """
name = "bad"
[[body]]
name = "arrow"
mass = 1.0
polygon = [[0.0, 0.0], [0.1, 0.0], [0.05, 0.02], [0.1, 0.05], [0.0, 0.05]]
"""


def test_non_convex_polygon_names_the_field_and_the_fix(cli, tmp_path):
    with pytest.raises(SceneError) as e:
        World.from_toml(NON_CONVEX, source="bad.toml")
    err = e.value
    assert isinstance(err, ValueError)
    assert "body[0]" in err.field and "polygon" in err.field
    assert "convex" in err.fix and "pieces" in err.fix
    assert err.source == "bad.toml"
    assert err.errors[0][0] == err.field and "convex" in err.errors[0][1]
    # The message is the one the CLI prints for the same file.
    f = tmp_path / "bad.toml"
    f.write_text(NON_CONVEX)
    r = subprocess.run([*_cli_argv(cli), "check", str(f)], capture_output=True, text=True)
    with pytest.raises(SceneError) as e2:
        World.load(f)
    assert r.returncode != 0
    for line in str(e2.value).splitlines():
        assert line.strip() in r.stdout + r.stderr, line


def _cli_argv(cli):
    # The fixture checks the exit code; here the command is meant to fail, so find the binary path.
    from conftest import _find_cli

    return [str(_find_cli())]


def test_unknown_scene_lists_the_builtins():
    with pytest.raises(SceneError, match="box-in-walls") as e:
        World.load("no-such-scene")
    assert e.value.field == "scene"


def test_toml_syntax_error_names_the_line():
    with pytest.raises(SceneError) as e:
        World.from_toml("name = \n[[body]\n")
    assert e.value.field.startswith("line")


@pytest.mark.parametrize(
    "call",
    [
        lambda: harness.wall("seh", K=float("nan")),
        lambda: harness.wall("seh", m=float("nan")),
        lambda: harness.wall("seh", T=-0.002),
        lambda: harness.peg("reset-integrator", mu_s=float("nan")),
        lambda: World.load("box-in-walls", rate=float("nan")),
        lambda: World.load("box-in-walls").set_drive("box", float("nan"), 0.0, 0.0),
        lambda: World.load("box-in-walls").set_pose("box", 0.0, float("inf"), 0.0),
    ],
)
def test_nan_parameters_raise_value_error(call):
    with pytest.raises(ValueError, match="finite|> 0"):
        call()


def test_unknown_model_names_list_the_valid_ones():
    with pytest.raises(ValueError, match="hysteretic"):
        harness.wall("spring")
    with pytest.raises(ValueError, match="reset-integrator"):
        harness.peg("sticky")
    with pytest.raises(ValueError, match="valid parameters"):
        harness.wall("seh", stiffness=1.0)
    with pytest.raises(ValueError, match="four-channel"):
        haptic2d.HapticSystem(World.load("box-in-walls"), controller="pid")
    with pytest.raises(ValueError, match="unknown sweep model"):
        haptic2d.sweep_walls(["spring"])


def test_negative_durations_raise_value_error():
    w = World.load("box-in-walls")
    with pytest.raises(ValueError, match="duration"):
        w.run(-1.0)
    with pytest.raises(ValueError, match="duration"):
        harness.wall("zoh", duration=-1.0)
    with pytest.raises(ValueError, match="duration"):
        harness.peg("classical", duration=-1.0)
    with pytest.raises(ValueError, match="duration"):
        haptic2d.HapticSystem(w).run_simulated(-0.1)
    with pytest.raises(ValueError, match="duration"):
        haptic2d.sweep_walls(["zoh"], duration=-1.0)


def test_wrong_types_raise_type_error():
    w = World.load("box-in-walls")
    with pytest.raises(TypeError):
        w.step("ten")
    with pytest.raises(TypeError):
        w.set_drive(1.5, 0.0, 0.0, 0.0)
    with pytest.raises(TypeError):
        harness.wall("zoh", push="hard")


def test_bad_inputs_never_crash_the_interpreter():
    # The same bad calls in a fresh interpreter: it must survive them all and exit normally.
    code = textwrap.dedent(
        """
        import haptic2d
        from haptic2d import World, harness
        bad = [
            lambda: World.from_toml(%r),
            lambda: World.load("no-such-scene"),
            lambda: harness.wall("seh", K=float("nan")),
            lambda: harness.wall("spring"),
            lambda: World.load("box-in-walls").run(-1.0),
            lambda: World.load("box-in-walls").step(-5),
            lambda: haptic2d.HapticSystem(World.load("box-in-walls")).tick([float("nan")] * 4),
            lambda: haptic2d.HapticSystem(World.load("box-in-walls")).tick([0.0] * 3),
            lambda: haptic2d.read_log("/no/such/file.csv"),
        ]
        caught = 0
        for f in bad:
            try:
                f()
            except (ValueError, TypeError):
                caught += 1
        print(caught)
        """
        % NON_CONVEX
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "9", r.stdout + r.stderr
