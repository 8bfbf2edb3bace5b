//! `haptic2d sweep walls [--rate HZ] [--points N] [--out DIR]`: stiffness × damping sweep of every wall
//! law on the 1-D Fig. 4 harness, classified by energy gain, with a Z-width style chart.

use crate::exit::Failure;
use haptic2d_lab::sweep::{sweep_walls, SweepConfig, WallClass};
use std::path::Path;

/// Runs sweep `target` (only `walls` exists). Rejected options are bad input (exit 2), checked
/// before anything runs; a sweep that cannot write its files is a runtime failure (exit 1).
pub fn run(target: &str, rate: f64, points: usize, out: &Path) -> Result<(), Failure> {
    if target != "walls" {
        return Err(format!(
            "unknown sweep `{target}`; valid: walls\n    fix: haptic2d sweep walls"
        )
        .into());
    }
    let cfg = SweepConfig {
        rate_hz: rate,
        points,
        ..SweepConfig::default()
    };
    cfg.validate()?;
    if out.exists() && !out.is_dir() {
        return Err(format!("--out: `{}` exists and is not a folder", out.display()).into());
    }
    let s = sweep_walls(&cfg, out, true).map_err(Failure::error)?;
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
