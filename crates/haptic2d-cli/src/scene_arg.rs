//! Resolves a SCENE argument: a file path, or a built-in scene name.

use haptic2d::scene::{builtin, builtin_names, Scene, MAX_FILE_BYTES, MAX_RATE_HZ};
use std::path::Path;

/// Loads the scene named by `arg` (path or built-in), with an optional rate override (Hz). Bodies
/// that start overlapping deeper than `δ_c` are an error unless the scene sets
/// `world.allow_initial_overlap = true`.
pub fn load(arg: &str, rate: Option<f64>) -> Result<Scene, String> {
    load_allowing(arg, rate, false)
}

/// [`load`], with `allow_overlap` (the `check --allow-overlap` flag) also accepting bodies that
/// start overlapping; accepted overlaps become warnings.
pub fn load_allowing(arg: &str, rate: Option<f64>, allow_overlap: bool) -> Result<Scene, String> {
    let mut scene = load_unchecked(arg, rate)?;
    let (found, capped) = scene.initial_overlaps();
    if found.is_empty() {
        return Ok(scene);
    }
    let mut lines: Vec<String> = found.iter().take(20).map(|o| o.to_string()).collect();
    if found.len() > 20 || capped {
        lines.push(format!(
            "… {}{} overlapping pairs in all",
            found.len(),
            if capped { "+" } else { "" }
        ));
    }
    let delta_c = scene.world.params.delta_c;
    if allow_overlap || scene.allow_initial_overlap {
        for l in lines {
            scene.warnings.push(format!(
                "{l} at the start (accepted; deeper than δ_c = {} mm, the contact model may push them apart violently)",
                delta_c * 1e3
            ));
        }
        return Ok(scene);
    }
    Err(format!(
        "{}: bodies start overlapping (separating-axis depth beyond δ_c = {} mm):\n  - {}\n    fix: move the bodies apart, or accept it with world.allow_initial_overlap = true in the scene (check: --allow-overlap)",
        scene.source,
        delta_c * 1e3,
        lines.join("\n  - ")
    ))
}

fn load_unchecked(arg: &str, rate: Option<f64>) -> Result<Scene, String> {
    if let Some(rate) = rate {
        if !(rate.is_finite() && rate > 0.0 && rate <= MAX_RATE_HZ) {
            return Err(format!(
                "--rate must be a positive number of Hz up to {MAX_RATE_HZ:e}, got {rate}\n    fix: e.g. --rate 1000"
            ));
        }
    }
    let path = Path::new(arg);
    if path.exists() {
        let text = read_bounded(path, MAX_FILE_BYTES, "scene file")?;
        return Scene::from_toml(&text, arg, rate).map_err(|e| e.to_string());
    }
    if let Some(s) = builtin(arg, rate) {
        return s.map_err(|e| e.to_string());
    }
    Err(format!(
        "no scene file or built-in scene named \"{arg}\"\n    fix: give a path to a .toml scene file, or one of the built-in scenes: {} (or pile:N)",
        builtin_names().collect::<Vec<_>>().join(", ")
    ))
}

/// The capped text-file read of every input file (shared with the device drivers' files).
pub use haptic2d_devices::file_read::read_bounded;
