//! `haptic2d simulate --out FILE.mcap`: the world's samples as an MCAP log (bodies, contacts,
//! energy, Foxglove scene; no tick channel, there is no haptic loop). Same calls as the world CSV
//! writer ([`WorldCsv`](crate::csv_out::WorldCsv)), so `cmd_simulate` picks one by extension.

use crate::csv_out::WorldCsv;
use haptic2d::world::World;
use haptic2d_rt::mcap::{McapSetup, McapSink, Metadata, WorldSample};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

/// The world output of `simulate`: CSV (docs/CSV.md) or MCAP (docs/LOGS.md).
pub enum WorldOut {
    /// `--out FILE.csv` (any extension but `.mcap`).
    Csv(WorldCsv<BufWriter<File>>),
    /// `--out FILE.mcap`.
    Mcap {
        /// The file being written.
        sink: Box<McapSink<BufWriter<File>>>,
        /// The sample being filled, reused.
        sample: Box<WorldSample>,
        /// Samples written so far.
        seq: u64,
    },
}

fn other(e: impl std::fmt::Display) -> std::io::Error {
    std::io::Error::other(e.to_string())
}

impl WorldOut {
    /// Creates `path` for `world` (of the scene `scene_arg`, named `scene_name`, at `rate_hz`).
    pub fn create(
        path: &Path,
        world: &World,
        scene_arg: &str,
        scene_name: &str,
    ) -> std::io::Result<Self> {
        let file = BufWriter::with_capacity(1 << 20, File::create(path)?);
        if !crate::run_log::is_mcap(path) {
            return Ok(Self::Csv(WorldCsv::new(file, world)?));
        }
        let scene: BTreeMap<String, String> = crate::run_log::scene_strings(
            scene_arg,
            scene_name,
            None,
            &[
                ("rate_hz", (1.0 / world.params.dt).to_string()),
                ("command", "simulate".to_string()),
            ],
        );
        let sink = McapSink::new(file, McapSetup::for_world(world, scene, false)).map_err(other)?;
        Ok(Self::Mcap {
            sink: Box::new(sink),
            sample: Box::default(),
            seq: 0,
        })
    }

    /// Writes the current state of `world` (log_time = the Unix time the file was started +
    /// round(t · 10⁹) ns); `overlap` has just [sampled](OverlapSummary::sample) it (the CSV's
    /// overlap column).
    pub fn row(&mut self, world: &World, overlap: &OverlapSummary) -> std::io::Result<()> {
        match self {
            Self::Csv(c) => c.row(world, overlap.end_m),
            Self::Mcap { sink, sample, seq } => {
                sample.capture(world);
                let log_time = sink.sim_log_time(world.time());
                sink.write_world(*seq, log_time, sample).map_err(other)?;
                *seq += 1;
                Ok(())
            }
        }
    }

    /// Finishes the file (flush; an MCAP log gets its summary and index, and the metadata
    /// record `haptic2d.overlap` with the run's largest overlap of two bodies, `overlap`).
    pub fn finish(self, overlap: &OverlapSummary) -> std::io::Result<()> {
        match self {
            Self::Csv(c) => c.finish(),
            Self::Mcap { sink, .. } => sink
                .finish(&[overlap.metadata()])
                .map(|_| ())
                .map_err(other),
        }
    }
}

/// The largest overlap of two bodies over a run (separating-axis depth, issue 35): what the
/// summary prints and the MCAP log's `haptic2d.overlap` metadata record holds.
#[derive(Clone, Debug, Default)]
pub struct OverlapSummary {
    /// Largest separating-axis depth over the run (m).
    pub max_m: f64,
    /// Time of it (s).
    pub at_s: f64,
    /// The two bodies' names then (empty if no overlap).
    pub bodies: (String, String),
    /// The overlap at the end of the run (m).
    pub end_m: f64,
}

impl OverlapSummary {
    /// Takes the world's overlap now into the summary.
    pub fn sample(&mut self, world: &World) {
        let o = world.max_overlap();
        self.end_m = o.depth;
        if o.depth > self.max_m {
            let name = |c: u32| world.bodies[world.colliders[c as usize].body].name.clone();
            self.max_m = o.depth;
            self.at_s = world.time();
            self.bodies = (name(o.pair.0), name(o.pair.1));
        }
    }

    /// The metadata record `haptic2d.overlap`: `max_m`, `at_s`, `body_a`, `body_b`, `end_m`.
    pub fn metadata(&self) -> Metadata {
        let mut m = BTreeMap::new();
        m.insert("max_m".to_string(), self.max_m.to_string());
        m.insert("at_s".to_string(), self.at_s.to_string());
        m.insert("body_a".to_string(), self.bodies.0.clone());
        m.insert("body_b".to_string(), self.bodies.1.clone());
        m.insert("end_m".to_string(), self.end_m.to_string());
        Metadata {
            name: "haptic2d.overlap".into(),
            metadata: m,
        }
    }
}
