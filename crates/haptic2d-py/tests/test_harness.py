"""The 1-D harnesses equal the Rust harness (as `haptic2d reproduce` writes it), for every model."""

from __future__ import annotations

import json

import numpy as np
import pytest

from haptic2d import harness, read_log

# Fig. 4 cases (haptic2d-lab fig4::CASES): name -> keyword arguments of harness.wall.
FIG4 = {
    "zoh": dict(law="zoh"),
    "seh": dict(law="seh"),
    "minsky": dict(law="minsky"),
    "colgate_passive": dict(law="colgate", damping=2.4),
    "colgate_violated": dict(law="colgate", damping=1.0),
    "pi": dict(law="pi"),
    "hysteretic": dict(law="hysteretic"),
    "pulse": dict(law="pulse"),
    "paper": dict(law="paper", impulse=True),
    "paper_no_damping": dict(law="paper", impulse=True, bc=0.0),
}

# Fig. 7 cases (haptic2d-lab fig7::MODELS): case -> friction model.
FIG7 = {
    "classical": "classical",
    "salcudean_vlaar": "salcudean-vlaar",
    "reset_integrator": "reset-integrator",
    "hayward_armstrong": "hayward-armstrong",
    "nahvi": "nahvi",
}


def _metrics(fig_dir, figure):
    m = json.loads((fig_dir / figure / "metrics.json").read_text())
    return {(c["model"], c["dimension"]): c for c in m["cases"]}


@pytest.mark.parametrize("case", sorted(FIG4))
def test_wall_equals_rust_harness(fig_dir, case):
    kw = dict(FIG4[case])
    law = kw.pop("law")
    r = harness.wall(law, m=0.5, T=0.002, push=2.0, duration=10, **kw)
    ref = read_log(fig_dir / "fig4" / f"{case}_1d.csv")
    for mine, theirs in (("t", "t_s"), ("x", "gap_m"), ("v", "v_m_s"), ("f", "f_wall_n")):
        assert np.array_equal(getattr(r, mine), ref[theirs]), (case, mine)
    measured = _metrics(fig_dir, "fig4")[(case, "1d")]
    assert r.metrics["separations"] == measured["separations"]
    assert np.array_equal(r.metrics["ratios"], np.array(measured["contact_ratios"], dtype=float))
    assert r.metrics["settle_time"] == measured["settle_time_s"]


@pytest.mark.parametrize("case", sorted(FIG7))
@pytest.mark.parametrize("f_pk", [2.1, 1.8])
def test_peg_equals_rust_harness(fig_dir, case, f_pk):
    r = harness.peg(FIG7[case], f_pk=f_pk, duration=5.2)
    ref = read_log(fig_dir / "fig7" / f"{case}_{f_pk}N_1d.csv")
    for mine, theirs in (("t", "t_s"), ("x", "x_m"), ("v", "v_m_s"), ("f_push", "f_push_n"),
                         ("f_friction", "f_friction_n"), ("u_f", "u_f_j")):
        assert np.array_equal(getattr(r, mine), ref[theirs]), (case, mine)


def test_issue_example_seh_bounces_and_settles_in_the_wall():
    r = harness.wall("seh", K=2000, m=0.5, T=0.002, push=2.0, duration=10)
    assert r.law == "seh" and len(r.t) == 5000
    assert r.metrics["separations"] >= 1
    # Entry speed sqrt(2 F g0 / m) = 0.4 m/s, sampled within one step.
    assert r.metrics["entry_speeds"][0] == pytest.approx(0.4, rel=0.02)
    # A stiffer wall penetrates less at the same push.
    stiff = harness.wall("seh", K=8000, duration=10)
    assert stiff.metrics["max_penetration"] < r.metrics["max_penetration"]


@pytest.mark.parametrize("law", harness.WALL_LAWS)
@pytest.mark.parametrize("integration", harness.INTEGRATIONS)
def test_every_wall_law_and_integration_runs(law, integration):
    r = harness.wall(law, duration=1.0, integration=integration)
    assert len(r.t) == 500 and np.all(np.isfinite(r.x))
    assert np.all(r.f_env >= 0.0)  # walls push, never pull


def test_passivity_controller_reports_its_damping():
    r = harness.wall("zoh", duration=5.0, passivity=True)
    assert r.metrics["max_alpha"] > 0.0
    assert np.any(r.alpha > 0.0)


@pytest.mark.parametrize("model", harness.FRICTION_MODELS)
def test_every_friction_model_runs(model):
    r = harness.peg(model, duration=2.2)
    assert len(r.t) == 1101 and np.all(np.isfinite(r.x))
    assert r.slip.dtype == np.bool_
    if model == "none":
        assert np.all(r.f_friction == 0.0)


def test_friction_parameters_change_the_result():
    a = harness.peg("reset-integrator", duration=2.2)
    b = harness.peg("reset-integrator", duration=2.2, mu_s=0.9, mu_k=0.8)
    assert not np.array_equal(a.x, b.x)
    assert b.metrics["max_abs_x"] <= a.metrics["max_abs_x"]


def test_law_params_lists_the_declared_keys_and_their_defaults():
    paper = {p["key"]: p for p in harness.law_params("paper")}
    assert set(paper) == {"kc", "bc"}
    assert paper["kc"]["unit"] == "N/m" and paper["kc"]["aliases"] == ["k"]
    # The per-contact default is half the 1-D one (a face rests on two contacts, §5).
    per = {p["key"]: p["default"] for p in harness.law_params("paper", per_contact=True)}
    assert per["kc"] == 0.5 * paper["kc"]["default"]
    keys = [p["key"] for p in harness.law_params("reset-integrator")]
    assert keys == ["kr", "mu_s", "mu_k", "beta", "p0"]
    assert harness.law_params("none") == []
    # Every declared key is accepted by the harness it belongs to.
    for law in harness.WALL_LAWS:
        for p in harness.law_params(law):
            assert p["rule"] and p["meaning"]
    with pytest.raises(ValueError, match="unknown normal law"):
        harness.law_params("no-such-law")
