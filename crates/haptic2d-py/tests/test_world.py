"""World: loading, stepping, state, energy, drives, poses, contacts."""

from __future__ import annotations

import numpy as np
import pytest

import haptic2d
from haptic2d import World

from conftest import REPO


def test_load_builtin_and_path_give_the_same_world():
    a = World.load("box-in-walls")
    b = World.load(REPO / "scenes" / "box-in-walls.toml")
    c = World.from_toml((REPO / "scenes" / "box-in-walls.toml").read_text())
    assert a.bodies == b.bodies == c.bodies
    assert a.source == "built-in:box-in-walls"
    for w in (a, b, c):
        w.step(100)
    for k in ("x", "y", "theta", "vx", "vy", "omega"):
        assert np.array_equal(a.state()[k], b.state()[k])
        assert np.array_equal(a.state()[k], c.state()[k])


def test_step_advances_time_by_whole_samples():
    w = World.load("box-in-walls")
    assert w.time == 0.0 and w.tick == 0
    w.step()
    w.step(9)
    assert w.tick == 10
    assert w.time == pytest.approx(10 * w.dt)
    w.step(0)
    assert w.tick == 10
    with pytest.raises(ValueError, match="n must be >= 0"):
        w.step(-1)


def test_rate_override_sets_the_period():
    w = World.load("box-in-walls", rate=1000.0)
    assert w.dt == pytest.approx(1e-3)


def test_state_has_one_entry_per_body_and_is_a_copy():
    w = World.load("box-in-walls")
    s = w.state()
    assert set(s) == {"x", "y", "theta", "vx", "vy", "omega"}
    for v in s.values():
        assert v.dtype == np.float64 and v.shape == (len(w.bodies),)
    s["x"][:] = 99.0
    assert not np.any(w.state()["x"] == 99.0)


def test_push_reaches_the_wall_and_contacts_are_reported():
    # box-in-walls: a box pushed by 2 N into a wall; after 2 s it rests against it.
    w = World.load("box-in-walls")
    c0 = w.contacts()
    assert c0.dtype == haptic2d.CONTACT_DTYPE and len(c0) == 0
    w.step(1000)
    c = w.contacts()
    assert len(c) >= 1
    assert set(c["state"]) <= {"colliding", "continuous"}
    assert np.all(c["normal_force"] >= 0.0)
    assert np.all(c["penetration"] >= 0.0)
    assert np.all(c["penetration"] == np.maximum(0.0, -c["distance"]))
    assert np.allclose(np.linalg.norm(c["normal"], axis=1), 1.0)
    dyn = [i for i, d in enumerate(w.dynamic) if d]
    assert set(c["body_a"]) | set(c["body_b"]) & set(dyn)
    # At rest the normal forces balance the 2 N push.
    assert c["normal_force"].sum() == pytest.approx(2.0, rel=0.05)


def test_energy_ledger_keys_and_work_of_the_push():
    w = World.load("box-in-walls")
    w.step(40)  # 0.08 s: the box reaches the wall (0.02 m at 4 m/s^2) only after 0.1 s
    e = w.energy()
    assert set(e) == {
        "kinetic",
        "stored",
        "applied_work",
        "impact_loss",
        "initial",
        "impact_energy_fallbacks",
    }
    assert e["impact_energy_fallbacks"] == 0
    assert e["applied_work"] > 0.0 and e["kinetic"] > 0.0
    # Before contact, semi-implicit Euler under a constant force F: v_k = k*a*T and the work is
    # sum F*T*v_k = m*a^2*T^2*n(n+1)/2, while KE = m*(n*a*T)^2/2, so W = KE*(n+1)/n.
    assert e["stored"] == 0.0 and e["impact_loss"] == 0.0 and e["initial"] == 0.0
    assert e["applied_work"] == pytest.approx(e["kinetic"] * 41 / 40, rel=1e-12)
    w.step(960)  # after the impact: the ledger records what the impact removed
    e = w.energy()
    assert e["impact_loss"] > 0.0 and e["stored"] > 0.0


def test_set_drive_moves_a_free_body():
    text = """
name = "free"
[world]
rate = 1000
[[body]]
name = "puck"
box = [0.1, 0.1]
mass = 1.0
position = [0.0, 0.0]
"""
    w = World.from_toml(text)
    w.set_drive("puck", 1.0, 0.0, 0.0)
    w.step(1000)
    s = w.state()
    # x = F t^2 / 2m = 0.5 m after 1 s (semi-implicit Euler: within one sample's worth).
    assert s["x"][0] == pytest.approx(0.5, rel=2e-3)
    assert s["vx"][0] == pytest.approx(1.0, rel=1e-9)
    assert w.energy()["applied_work"] == pytest.approx(0.5, rel=2e-3)


def test_set_pose_and_velocity():
    w = World.load("box-in-walls")
    i = w.dynamic.index(True)
    w.set_pose(i, 0.01, 0.02, 0.1)
    w.set_velocity(w.bodies[i], 0.5, 0.0, 0.0)
    s = w.state()
    assert (s["x"][i], s["y"][i], s["theta"][i]) == (0.01, 0.02, 0.1)
    assert s["vx"][i] == 0.5
    fixed = w.dynamic.index(False)
    with pytest.raises(ValueError, match="fixed"):
        w.set_velocity(fixed, 1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="no body named"):
        w.set_pose("nobody", 0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="out of range"):
        w.set_pose(99, 0.0, 0.0, 0.0)


def test_copy_is_independent():
    w = World.load("box-in-walls")
    c = w.copy()
    w.step(10)
    assert c.tick == 0 and w.tick == 10


def _landing(mode: str) -> World:
    """A 1 kg box landing flat at 1 m/s down while sliding at 1 m/s (classical friction, mu = 0.5)."""
    text = f"""
name = "landing"
[world]
rate = 1000
[contact]
restitution = 0.0
impact_friction = "{mode}"
[friction]
model = "classical"
v_th = 0.001
mu_s = 0.5
mu_k = 0.5
[[body]]
name = "floor"
kind = "fixed"
polygon = [[-20.0, -0.1], [20.0, -0.1], [20.0, 0.0], [-20.0, 0.0]]
[[body]]
name = "box"
mass = 1.0
box = [0.1, 0.05]
position = [0.0, 0.0255]
velocity = [1.0, -1.0]
"""
    return World.from_toml(text)


def test_impact_friction_coulomb_brakes_a_sliding_landing():
    # A plastic frictional impact removes at most mu * |v_n| = 0.5 m/s of the sliding speed (Coulomb
    # bound on the tangential impulse); the frictionless impact removes none of it.
    runs = {}
    for mode in ("none", "coulomb"):
        w = _landing(mode)
        w.step(3)  # the impact sample, before friction in contact has had time to act much
        runs[mode] = (w.state()["vx"][1], w.energy())
    vx_none, e_none = runs["none"]
    vx_coul, e_coul = runs["coulomb"]
    assert vx_none > 0.99
    assert 0.45 <= vx_coul <= 0.6
    # No energy created: the impact loss of the frictional impact is the larger.
    assert e_coul["impact_loss"] > e_none["impact_loss"] > 0.0
    with pytest.raises(ValueError, match="impact_friction"):
        World.from_toml(
            '[world]\nrate = 1000\n[contact]\nimpact_friction = "sticky"\n'
            '[[body]]\nname = "b"\nbox = [0.1, 0.1]\nmass = 1.0\nposition = [0.0, 0.0]\n'
        )


def test_load_refuses_a_scene_file_above_the_cap():
    # Scene files are read with the CLI's 16 MiB cap: /dev/zero used to be read until memory ran out.
    with pytest.raises(ValueError, match="larger than the cap"):
        World.load("/dev/zero")
