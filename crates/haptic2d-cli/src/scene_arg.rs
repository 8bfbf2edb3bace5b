//! Resolves a SCENE argument: a file path, or a built-in scene name.

use haptic2d::scene::{builtin, builtin_names, Scene};
use std::path::Path;

/// Loads the scene named by `arg` (path or built-in), with an optional rate override (Hz).
pub fn load(arg: &str, rate: Option<f64>) -> Result<Scene, String> {
    if let Some(rate) = rate {
        if !(rate.is_finite() && rate > 0.0) {
            return Err(format!(
                "--rate must be a positive number of Hz, got {rate}"
            ));
        }
    }
    let path = Path::new(arg);
    if path.exists() {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read scene file {arg}: {e}"))?;
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
