//! The tick log of `haptic2d run --log FILE`: CSV (unchanged format) or MCAP, chosen by the
//! file's extension (`.mcap` → MCAP, anything else → CSV), behind one type for `cmd_run`.

use haptic2d::scene::{builtin, pile_toml, BUILTIN};
use haptic2d::world::World;
use haptic2d_rt::mcap::{LoggedTick, McapLogger, McapSetup, Metadata};
use haptic2d_rt::{CsvLogger, LoggerConfig, RecordRx, TimingSummary};
use std::collections::BTreeMap;
use std::path::Path;

/// True when `path` names an MCAP file (extension `.mcap`, any case).
pub fn is_mcap(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
}

/// The running logger.
pub enum RunLogger {
    /// `--log FILE.csv`.
    Csv(CsvLogger),
    /// `--log FILE.mcap`.
    Mcap(McapLogger),
}

/// The scene file's text: the file at `arg` if it exists, else the built-in scene's TOML.
pub fn scene_text(arg: &str) -> String {
    let p = Path::new(arg);
    if p.exists() {
        if let Ok(t) =
            crate::scene_arg::read_bounded(p, haptic2d::scene::MAX_FILE_BYTES, "scene file")
        {
            return t;
        }
    }
    if let Some(n) = arg.strip_prefix("pile:").and_then(|n| n.parse().ok()) {
        if builtin(arg, None).is_some() {
            return pile_toml(n);
        }
    }
    BUILTIN
        .iter()
        .find(|b| b.0 == arg)
        .map_or(String::new(), |b| b.2.to_string())
}

/// The strings of a log's `/haptic2d/scene` message and `haptic2d.scene` metadata: the scene
/// (argument, name, file text), the device file (path, text), and `settings` (rate, controller, …).
pub fn scene_strings(
    scene_arg: &str,
    scene_name: &str,
    device_file: Option<&Path>,
    settings: &[(&str, String)],
) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    m.insert("scene".into(), scene_arg.to_string());
    m.insert("scene_name".into(), scene_name.to_string());
    m.insert("scene_toml".into(), scene_text(scene_arg));
    if let Some(d) = device_file {
        m.insert("device_file".into(), d.display().to_string());
        m.insert(
            "device_toml".into(),
            crate::scene_arg::read_bounded(d, haptic2d::scene::MAX_FILE_BYTES, "device file")
                .unwrap_or_default(),
        );
    }
    for (k, v) in settings {
        m.insert((*k).to_string(), v.clone());
    }
    m.insert("haptic2d_version".into(), env!("CARGO_PKG_VERSION").into());
    m
}

impl RunLogger {
    /// Starts the logger for `path` draining `rx`; an MCAP log describes `world` and `scene`.
    pub fn start(
        path: &Path,
        rx: RecordRx<LoggedTick>,
        world: &World,
        scene: BTreeMap<String, String>,
    ) -> Result<Self, String> {
        if is_mcap(path) {
            let setup = McapSetup::for_world(world, scene, true);
            Ok(Self::Mcap(McapLogger::spawn_file(rx, path, setup)?))
        } else {
            Ok(Self::Csv(CsvLogger::spawn_file(
                rx,
                path,
                LoggerConfig::default(),
            )?))
        }
    }

    /// True when the log records the world (bodies, contacts): the loop then captures it.
    pub fn captures_world(&self) -> bool {
        matches!(self, Self::Mcap(_))
    }

    /// Finishes the log (an MCAP log gets the run's timing summary as metadata `haptic2d.timing`)
    /// and returns the report line.
    pub fn finish(self, summary: &TimingSummary) -> Result<String, String> {
        match self {
            Self::Csv(l) => Ok(l.finish()?.to_string()),
            Self::Mcap(l) => Ok(l.finish(vec![timing_metadata(summary)])?.to_string()),
        }
    }
}

/// The timing summary as the metadata record `haptic2d.timing` (numbers in their units, plus the
/// printed summary under `summary`).
pub fn timing_metadata(s: &TimingSummary) -> Metadata {
    let mut m = BTreeMap::new();
    let mut put = |k: &str, v: String| {
        m.insert(k.to_string(), v);
    };
    put("summary", s.to_string());
    put("rate_hz", s.rate_hz.to_string());
    put("ticks", s.ticks.to_string());
    put("deadlines", s.deadlines.to_string());
    put("skipped", s.skipped.to_string());
    put("overruns", s.overruns.to_string());
    put("on_time", s.on_time.to_string());
    put("on_time_fraction", s.on_time_fraction.to_string());
    put("on_time_limit_us", s.on_time_limit_us.to_string());
    put("elapsed_s", s.elapsed_s.to_string());
    put("achieved_rate_hz", s.achieved_rate_hz.to_string());
    for (name, p) in [
        ("lateness_us", &s.lateness_us),
        ("compute_us", &s.compute_us),
    ] {
        put(&format!("{name}.p50"), p.p50.to_string());
        put(&format!("{name}.p99"), p.p99.to_string());
        put(&format!("{name}.p999"), p.p999.to_string());
        put(&format!("{name}.max"), p.max.to_string());
        put(&format!("{name}.mean"), p.mean.to_string());
    }
    Metadata {
        name: "haptic2d.timing".into(),
        metadata: m,
    }
}
