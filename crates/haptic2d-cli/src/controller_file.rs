//! `--controller-file FILE.toml` of `run`, `stability` and `reproduce`: a controller's architecture
//! and gains from a file (format: `haptic2d::control::file`; examples in `controllers/`). The file
//! wins over `--controller`.

use haptic2d::control::file::{controller_from_toml, CONTROLLER_EXAMPLES};
use haptic2d::haptic::ControllerKind;
use haptic2d::scene::MAX_FILE_BYTES;
use std::path::Path;

/// The controller of `--controller NAME` or, when given, of `--controller-file FILE`; and the label
/// used in reports and plot names (the name, or the file's stem).
pub fn resolve(name: &str, file: Option<&Path>) -> Result<(ControllerKind, String), String> {
    match file {
        None => {
            let kind = ControllerKind::from_name(name).map_err(|e| format!("--controller: {e}"))?;
            Ok((kind, name.to_string()))
        }
        Some(path) => {
            let kind = load(path)?;
            let stem = path
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("controller-file")
                .to_string();
            Ok((kind, stem))
        }
    }
}

/// Reads and validates a controller file (bounded like a scene file).
pub fn load(path: &Path) -> Result<ControllerKind, String> {
    let text =
        crate::scene_arg::read_bounded(path, MAX_FILE_BYTES, "controller file").map_err(|e| {
            format!(
                "{e}\n    fix: give the path of a TOML controller file, e.g. {CONTROLLER_EXAMPLES}"
            )
        })?;
    controller_from_toml(&text, &format!("controller file {}", path.display()))
        .map(|f| f.kind)
        .map_err(|e| e.to_string().trim_end().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic2d::control::four_channel::FourChannelGains;

    fn shipped(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../controllers")
            .join(name)
    }

    /// `controllers/default.toml` is the default of `run` and `reproduce`, `paper-4ch.toml` the §11.1
    /// table; every shipped file is valid.
    #[test]
    fn shipped_controller_files_match_the_named_configurations() {
        assert_eq!(
            load(&shipped("default.toml")).unwrap(),
            ControllerKind::default()
        );
        assert_eq!(
            load(&shipped("paper-4ch.toml")).unwrap(),
            ControllerKind::FourChannel(FourChannelGains::spec())
        );
        // The paper-rate study's coupling is the one `reproduce fig8` runs at 500 Hz / scale 1.
        assert_eq!(
            load(&shipped("coupling-paper-rate.toml")).unwrap(),
            ControllerKind::Coupling(haptic2d_lab::figures::fig8::PAPER_RATE_COUPLING)
        );
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../controllers");
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            assert!(load(&p).is_ok(), "{}: {:?}", p.display(), load(&p));
        }
    }

    #[test]
    fn controller_file_wins_over_the_name_and_labels_by_stem() {
        let (k, label) = resolve("coupling", Some(&shipped("paper-4ch.toml"))).unwrap();
        assert_eq!(k, ControllerKind::FourChannel(FourChannelGains::spec()));
        assert_eq!(label, "paper-4ch");
        let (k, label) = resolve("coupling", None).unwrap();
        assert_eq!(label, "coupling");
        assert!(matches!(k, ControllerKind::Coupling(_)));
        assert!(resolve("nope", None).unwrap_err().contains("--controller"));
    }
}
