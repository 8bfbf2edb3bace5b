"""world.run returns exactly the columns and numbers of `haptic2d simulate`'s CSV."""

from __future__ import annotations

import numpy as np
import pytest

from haptic2d import World, read_log


@pytest.mark.parametrize(
    "scene,duration,every",
    [("box-in-walls", 2.0, 1), ("box-in-walls-tilt", 1.5, 7), ("peg-in-hole", 1.0, 3)],
)
def test_run_equals_simulate_csv(cli, tmp_path, scene, duration, every):
    out = tmp_path / "sim.csv"
    cli("simulate", scene, "--duration", str(duration), "--every", str(every), "--out", str(out))
    header = out.read_text().splitlines()[0].split(",")
    cols = World.load(scene).run(duration, every=every)
    assert list(cols) == header
    ref = read_log(out)
    for name in header:
        assert cols[name].shape == ref[name].shape, name
        # Shortest round-trip decimal in the CSV parses back to the same f64: exact equality.
        assert np.array_equal(cols[name], ref[name]), name
    assert cols["contacts"].dtype == np.int64


def test_run_continues_from_the_current_state():
    w = World.load("box-in-walls")
    w.step(100)
    cols = w.run(0.2)
    assert cols["t"][0] == pytest.approx(100 * w.dt)
    assert len(cols["t"]) == 101
    assert w.tick == 200


def test_run_rejects_bad_duration_and_every():
    w = World.load("box-in-walls")
    for bad in (-1.0, 0.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="duration"):
            w.run(bad)
    with pytest.raises(ValueError, match="every"):
        w.run(1.0, every=0)
    assert w.tick == 0
