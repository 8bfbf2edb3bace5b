//! Issue 11: does a principled stable design meet more of the Figs. 5–11 claims than the default?
//!
//! Candidates: local force feedback `C6 ∈ {−1, −0.75, −0.5}` (force reflection `C2 = 1 + C6`), master
//! damping injection `D_m ∈ {0, 0.5, 1, 2, 5, 10} N·s/m` (θ: `D_m·1e-3`), and slave-side local force
//! feedback `C5 = ±0.5` with the default's `C6 = −1`, `D_m = 2`. A candidate is *stable* if
//! `haptic2d stability` would call every axis stable (held and released, decay ≥ 2 1/s) with the
//! one sample of output delay that `run` assumes for a real device, on box-in-walls at 500 Hz (Figs.
//! 5–6) and on peg-in-hole at scale 2 and 1 kHz (Figs. 8–11). Each candidate then runs the 4 Fig. 5–6
//! walls and the 5 Fig. 8–11 friction models with their unchanged pass criteria.
//!
//! Finding (measured with this test, `cargo test -p haptic2d-lab --test design_search -- --ignored
//! --nocapture`, ≈ 1 min on 2 cores): no stable candidate passes more than the default's 2 of 9 (the
//! pulse and hysteretic walls; no Fig. 8–11 claim). The candidates that pass a Fig. 8–11 slip claim
//! (`C6 = −0.5, D_m = 5`: classical and Salcudean–Vlaar; `C6 = −0.75, D_m ∈ {2, 5}`: Salcudean–Vlaar)
//! keep part of the force reflection `C2 > 0` and are unstable released on the peg with the output
//! delay (sampled growth +2.1 to +28 1/s on its x or y axis): the slip needs the handle to be pushed
//! back by the peg's contact force, which is the released-unstable path of §11.4. Fig. 5's "keeps
//! bouncing" (SEH, ZOH) fails for every candidate: with `C2 ≤ 0.5` the handle does not stop with the
//! box, and the box leaves the wall at most twice.

use haptic2d::control::four_channel::FourChannelGains;
use haptic2d::haptic::config::{ControllerKind, HapticConfig};
use haptic2d::scene::{Scene, BUILTIN};
use haptic2d_lab::experiments::{fig5, fig8};
use haptic2d_lab::stability::{analyse_config, Verdict};
use rayon::prelude::*;

/// Whether every axis is stable (with margin) with one sample of output delay on `scene`.
fn stable(cfg: &HapticConfig, scene: &str, rate: f64, scale: f64, x0: Option<[f64; 3]>) -> bool {
    let text = BUILTIN.iter().find(|b| b.0 == scene).expect("scene").2;
    let w = Scene::from_toml(text, scene, Some(rate))
        .expect("scene")
        .world;
    let mut c = cfg.clone();
    c.scale = scale;
    c.device_origin = x0;
    analyse_config(&c, &w, rate, 1, "candidate")
        .map(|r| r.axes.iter().all(|a| a.verdict() == Verdict::Stable))
        .unwrap_or(false)
}

/// `(stable on both scenes, claims passed, which)`.
fn evaluate(g: &FourChannelGains) -> (bool, usize, Vec<String>) {
    let cfg = HapticConfig {
        controller: ControllerKind::FourChannel(*g),
        ..HapticConfig::default()
    };
    let ok = stable(&cfg, "box-in-walls", 500.0, 1.0, None)
        && stable(&cfg, "peg-in-hole", 1000.0, 2.0, Some([-0.03, 0.14, 0.0]));
    let mut passed = Vec::new();
    let p5 = fig5::Fig5Params {
        haptic: cfg.clone(),
        ..fig5::Fig5Params::default()
    };
    for c in fig5::run(&p5).expect("fig5 runs") {
        if c.metrics.pass {
            passed.push(format!("fig5/{}", c.name));
        }
    }
    let p8 = fig8::Fig8Params {
        haptic: cfg,
        ..fig8::Fig8Params::default()
    };
    for c in fig8::run(&p8).expect("fig8 runs") {
        if c.metrics.pass && c.stopped.is_none() {
            passed.push(format!("fig8/{}", c.name));
        }
    }
    (ok, passed.len(), passed)
}

#[test]
#[ignore = "long: 15 candidate gain sets × 9 device-in-the-loop runs (about 1 min on 2 cores)"]
fn no_stable_design_meets_more_claims_than_the_default() {
    let base = FourChannelGains::default();
    let inj = |d: f64| [d, d, d * 1e-3];
    let mut cands: Vec<(String, FourChannelGains)> = Vec::new();
    for d in [0.0, 0.5, 1.0, 2.0, 5.0] {
        cands.push((
            format!("C6 = -1, D_m = {d}"),
            FourChannelGains {
                d_m: inj(d),
                ..base
            },
        ));
    }
    for c6 in [-0.75, -0.5] {
        for d in [2.0, 5.0, 10.0] {
            cands.push((
                format!("C6 = {c6}, D_m = {d}"),
                FourChannelGains {
                    c6: [c6; 3],
                    d_m: inj(d),
                    ..base
                },
            ));
        }
    }
    for c5 in [-0.5, 0.5] {
        cands.push((
            format!("C6 = -1, C5 = {c5}, D_m = 2"),
            FourChannelGains {
                c5: [c5; 3],
                ..base
            },
        ));
    }
    let (default_stable, default_count, default_passed) = evaluate(&base);
    println!("default: stable {default_stable}, {default_count}/9 {default_passed:?}");
    assert!(default_stable);
    let results: Vec<_> = cands
        .par_iter()
        .map(|(name, g)| (name, evaluate(g)))
        .collect();
    for (name, (st, n, which)) in &results {
        println!("{name}: stable {st}, {n}/9 {which:?}");
    }
    for (name, (st, n, which)) in &results {
        assert!(
            !st || *n <= default_count,
            "{name} is stable and passes {n} claims ({which:?}), more than the default's {default_count}: consider it as the default"
        );
    }
}
