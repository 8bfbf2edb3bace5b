"""haptic2d.present: one stimulus of a study file explored by the simulated hand (issue 40, item 7),
and the PsychoPy-style staircase example that drives it."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

import haptic2d

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..")
STUDY = os.path.join(ROOT, "studies", "stiffness-walls.toml")


def test_present_feels_twice_the_corner_stiffness_of_reference_and_comparison():
    # The paper wall's box face rests on two corner contacts: the hand feels 2*kc (docs/STUDIES.md).
    ref = haptic2d.present(STUDY, "spring-1000")
    assert ref["vary"] == "normal.kc" and ref["reference_value"] == 1000.0 and ref["value"] == 1000.0
    assert abs(ref["stiffness"] / 2000.0 - 1) < 0.01, ref
    cmp = haptic2d.present(STUDY, "spring-1000", 480.0)
    assert cmp["value"] == 1480.0
    assert abs(cmp["stiffness"] / 2960.0 - 1) < 0.01, cmp


def test_present_refuses_an_unknown_condition_and_a_bad_delta_with_the_valid_names():
    with pytest.raises(ValueError, match="spring-1000"):
        haptic2d.present(STUDY, "nope")
    with pytest.raises(ValueError, match="finite"):
        haptic2d.present(STUDY, "spring-1000", float("nan"))
    with pytest.raises(ValueError):
        haptic2d.present(os.path.join(ROOT, "studies", "missing.toml"), "spring-1000")


def test_staircase_example_runs_without_psychopy_or_a_display():
    example = os.path.join(ROOT, "examples", "python", "study_staircase.py")
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    out = subprocess.run([sys.executable, example, "--trials", "30"], capture_output=True, text=True,
                         env=env, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "trial  30:" in out.stdout
    try:
        import psychopy  # noqa: F401
        assert "psychopy.data.StairHandler" in out.stdout
    except ImportError:
        assert "stand-in staircase" in out.stdout and "not PsychoPy" in out.stdout
