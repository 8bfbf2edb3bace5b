"""sweep_walls (locally, on a thread pool, on a Dask cluster, against the CLI), reproduce, read_log."""

from __future__ import annotations

import csv
import json
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import haptic2d
from haptic2d import World, read_log

SMALL = dict(models=["zoh", "colgate", "paper"], points=3, duration=2.0)


def _equal(a, b):
    assert list(a) == list(b)
    for k in a:
        if a[k].dtype.kind == "f":
            assert np.array_equal(a[k], b[k], equal_nan=True), k
        else:
            assert np.array_equal(a[k], b[k]), k


def test_sweep_equals_the_cli_sweep(cli, tmp_path):
    cli("sweep", "walls", "--points", "3", "--out", str(tmp_path))
    rows = list(csv.DictReader((tmp_path / "walls.csv").open()))
    s = haptic2d.sweep_walls(points=3)
    assert len(rows) == len(s["model"]) == 8 * 9
    for i, r in enumerate(rows):
        assert r["model"] == s["model"][i]
        assert float(r["k_n_m"]) == s["k_n_m"][i]
        assert float(r["damping_n_s_m"]) == s["damping_n_s_m"][i]
        assert r["damping_kind"] == s["damping_kind"][i]
        assert int(r["separations"]) == s["separations"][i]
        mean = float(r["mean_ratio"]) if r["mean_ratio"] else float("nan")
        assert np.array_equal(mean, s["mean_ratio"][i], equal_nan=True)
        assert r["class"] == s["class"][i]


def test_sweep_on_a_thread_pool_equals_the_local_run():
    local = haptic2d.sweep_walls(**SMALL)
    with ThreadPoolExecutor(max_workers=2) as ex:
        _equal(haptic2d.sweep_walls(**SMALL, executor=ex), local)


def test_sweep_on_a_dask_local_cluster_equals_the_local_run():
    distributed = pytest.importorskip("distributed")
    local = haptic2d.sweep_walls(**SMALL)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        remote = haptic2d.sweep_walls(**SMALL, executor=client)
    _equal(remote, local)


def test_reproduce_writes_the_report(tmp_path):
    s = haptic2d.reproduce("fig7", tmp_path)
    assert (tmp_path / "REPORT.md").is_file()
    assert (tmp_path / "fig7" / "metrics.json").is_file()
    f = s["figures"]["fig7"]
    assert f["total"] > 0 and 0 <= f["passed"] <= f["total"]
    m = json.loads((tmp_path / "fig7" / "metrics.json").read_text())
    assert sum(c["pass"] for c in m["cases"] if not c.get("comparison")) == f["passed"]
    with pytest.raises(ValueError, match="unknown figure"):
        haptic2d.reproduce("fig99", tmp_path)


def test_read_log_round_trips_a_simulate_csv(cli, tmp_path):
    out = tmp_path / "box.csv"
    cli("simulate", "box-in-walls", "--duration", "0.5", "--out", str(out))
    log = read_log(out)
    _equal(log, {k: v.astype(np.float64) for k, v in World.load("box-in-walls").run(0.5).items()})


def test_read_log_names_the_bad_line(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("t,x\n0,1\n0.1,oops\n")
    with pytest.raises(ValueError, match=r"line 3, column 'x'"):
        read_log(p)
    p.write_text("t,x\n0,1,2\n")
    with pytest.raises(ValueError, match="line 2 has 3 fields"):
        read_log(p)
