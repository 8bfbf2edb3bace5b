//! `haptic2d sweep walls [--rate HZ] [--points N] [--out DIR]`: stiffness × damping sweep of every wall
//! law on the 1-D Fig. 4 harness, classified by energy gain, with a Z-width style chart.

use haptic2d_lab::sweep::{sweep_walls, SweepConfig, WallClass};
use std::path::Path;

/// Runs sweep `target` (only `walls` exists).
pub fn run(target: &str, rate: f64, points: usize, out: &Path) -> Result<(), String> {
    if target != "walls" {
        return Err(format!("unknown sweep `{target}`; valid: walls"));
    }
    let cfg = SweepConfig {
        rate_hz: rate,
        points,
        ..SweepConfig::default()
    };
    let s = sweep_walls(&cfg, out, true)?;
    for (model, _) in haptic2d_lab::sweep::MODELS {
        let of = |c| {
            s.points
                .iter()
                .filter(|p| p.model == model && p.class == c)
                .count()
        };
        println!(
            "{model:>10}: {:3} dissipative, {:3} marginal, {:3} gain energy",
            of(WallClass::Dissipative),
            of(WallClass::Marginal),
            of(WallClass::GainsEnergy)
        );
    }
    println!("wrote {} files to {}", s.files.len(), out.display());
    Ok(())
}
