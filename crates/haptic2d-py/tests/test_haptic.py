"""HapticSystem: ticks from encoders, runs closed around the simulated device, device files."""

from __future__ import annotations

import numpy as np
import pytest

from haptic2d import HapticSystem, SceneError, World

from conftest import REPO


def test_run_simulated_returns_one_row_per_tick():
    hs = HapticSystem(World.load("box-in-walls"), controller="four-channel", hand="hold")
    rec = hs.run_simulated(0.5)
    assert hs.fault is None and hs.safety_trip is None
    assert list(rec) == hs.columns
    n = int(round(0.5 / hs.dt))
    for v in rec.values():
        assert v.shape == (n,) and v.dtype == np.float64
    assert np.array_equal(rec["t"], np.arange(n) * hs.dt)
    # Held still at the start pose, the slave stays where it began (no scene push in the loop).
    assert np.max(np.abs(rec["slave.x"] - rec["slave.x"][0])) < 1e-3


def _pushed_into_the_wall(hs: HapticSystem, duration: float) -> dict:
    """Runs ``duration`` and checks the push drove the slave into the left wall and held it there."""
    rec = hs.run_simulated(duration)
    assert hs.fault is None and hs.safety_trip is None, (hs.fault, hs.safety_trip)
    n = int(round(duration / hs.dt))
    assert len(rec["t"]) == n
    cols = [c for c in hs.columns if c.startswith("tau")]
    assert len(cols) == 4
    tau = np.stack([rec[c] for c in cols], axis=1)
    assert np.all(np.isfinite(tau)) and np.max(np.abs(tau)) > 0.0
    # The push drives the slave (box centre 0.04 m, left face 0.02 m right of it) into the left
    # wall at x = 0: x decreases to the contact and stays there, the box's left face within 5 mm
    # of the wall surface, and the device feels the wall (its command pushes back, +x).
    x = rec["slave.x"]
    assert x[-1] < x[0] - 0.015
    assert np.all(np.abs(x[-n // 10 :] - 0.02) < 0.005), x[-n // 10 :]
    assert np.mean(rec["f_cm.x"][-n // 10 :]) > 1.0
    return rec


def test_a_push_after_holding_through_the_start_up_ramp_drives_the_slave_into_the_wall():
    # As a user does: hold the handle while the torques ramp in (0.5 s), then push with 2 N.
    hs = HapticSystem(World.load("box-in-walls"), hand="script:0.5,-2,0,0,1.0")
    rec = _pushed_into_the_wall(hs, 1.5)
    assert hs.ramp == 1.0
    assert np.max(np.abs(rec["slave.x"][: int(0.4 / hs.dt)] - 0.04)) < 1e-3, "still while held"


def test_a_constant_push_drives_the_slave_into_the_wall_without_the_start_up_ramp():
    hs = HapticSystem(World.load("box-in-walls"), hand="constant:-2,0,0", ramp_time=0.0)
    _pushed_into_the_wall(hs, 1.0)


def test_a_push_from_the_first_tick_during_the_start_up_ramp_trips_the_workspace_latch():
    # Traced regression of session 4 (the two xfail tests): the 0.5 s ramp scales the rendered wall
    # and the workspace bound, so a 2 N push from tick 0 on the light handle reaches the workspace
    # edge (x = -0.032 m) at a third of the ramp and passes it by the trip distance (10 mm): the
    # latch zeroes the torques that tick and says why; the unresisted handle then leaves the plant's
    # reach and the run stops there (`fault`). The slave, released by the latch from deep in the
    # wall, springs back +x; that was the "+x under a -x push".
    hs = HapticSystem(World.load("box-in-walls"), hand="constant:-2,0,0")
    rec = hs.run_simulated(1.0)
    trip = hs.safety_trip
    assert trip is not None and "workspace edge" in trip, trip
    assert hs.fault is not None and "out of reach" in hs.fault, hs.fault
    n = len(rec["t"])
    assert n < int(round(1.0 / hs.dt))
    latched = rec["flag.safety"] > 0
    first = int(np.argmax(latched))
    assert latched[first] and np.all(latched[first:])
    assert rec["t"][first] < 0.25, "within the ramp"
    cols = [c for c in hs.columns if c.startswith("tau")]
    assert all(np.all(rec[c][first:] == 0.0) for c in cols), "zero torques from the trip on"


def test_tick_from_encoders_matches_the_simulated_loop():
    a = HapticSystem(World.load("box-in-walls"), hand="free")
    b = HapticSystem(World.load("box-in-walls"), hand="free")
    q = a.plant_encoders()
    assert q.shape == (4,)
    tau = a.tick(q)
    assert tau.shape == (4,) and np.all(np.isfinite(tau))
    rec = b.run_simulated(b.dt)  # one tick from the same encoders
    cols = [c for c in b.columns if c.startswith("tau")]
    assert np.array_equal(tau, np.array([rec[c][0] for c in cols]))
    assert a.last_record()["t"] == 0.0


def test_controllers_and_hands():
    w = World.load("box-in-walls")
    for ctrl in ("four-channel", "coupling"):
        for hand in ("hold", "free", ("sine", 1.0, 1.0), "script:0.1,-1,0,0,0.2"):
            hs = HapticSystem(w, controller=ctrl, hand=hand)
            rec = hs.run_simulated(0.2)
            assert hs.controller == ctrl
            assert np.all(np.isfinite(rec["slave.x"]))
    with pytest.raises(ValueError, match="unknown hand"):
        HapticSystem(w, hand="wave")
    with pytest.raises(ValueError, match="takes"):
        HapticSystem(w, hand="constant:1,2")
    with pytest.raises(ValueError, match="ramp_time"):
        HapticSystem(w, ramp_time=-1.0)
    with pytest.raises(ValueError, match="ramp_time"):
        HapticSystem(w, ramp_time=float("nan"))


def test_device_file_template_loads_and_bad_ones_name_the_field(tmp_path):
    w = World.load("box-in-walls")
    hs = HapticSystem(w, device_file=REPO / "devices" / "twin-pantograph.toml")
    assert np.all(np.isfinite(hs.run_simulated(0.1)["device.x"]))
    bad = tmp_path / "bad.toml"
    bad.write_text("[device]\nmass = -1.0\n")
    with pytest.raises(SceneError) as e:
        HapticSystem(w, device_file=bad)
    assert e.value.field
    with pytest.raises(ValueError, match="cannot read device file"):
        HapticSystem(w, device_file=tmp_path / "missing.toml")


def test_world_copy_is_taken():
    w = World.load("box-in-walls")
    hs = HapticSystem(w, hand="script:0.2,-2,0,0,0.3")
    hs.run_simulated(0.5)
    assert w.tick == 0
    assert hs.world().tick == 250
