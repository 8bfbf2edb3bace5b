//! [`McapSink`]: writes haptic2d records into an MCAP file, one channel per topic of
//! [`schemas`](super::schemas). Modelled on the `mcap` crate's writer habits: every schema and
//! channel is registered once at construction and its id kept; each message goes through
//! `write_to_known_channel` with a JSON body encoded into one reused buffer; `finish` writes the
//! summary and index and its statistics are folded into the [`McapStats`] returned.
//!
//! Timestamps ([`clock`](super::clock)): a tick's `log_time` (and `publish_time`) is its deadline
//! (`CLOCK_MONOTONIC` ns) moved to the Unix epoch by the offset read when the log started, and its
//! `sequence` the tick index (mod 2³²; the full index is in the message). A world sample of
//! `haptic2d simulate` has `log_time` = the Unix time the simulation started + `round(t · 10⁹)`,
//! and `sequence` = the sample number. A tick log converted from CSV keeps the recorded deadline
//! (or `t`). The metadata record `haptic2d.clock` says which.

use crate::mcap::clock::{clock_metadata, monotonic_to_unix_offset_ns, unix_now_ns, LogClock};
use crate::mcap::columns::{tick_json_schema, tick_row, TickRow};
use crate::mcap::encode::{
    encode_bodies, encode_contacts, encode_energy, encode_frame_transforms, encode_scene_update,
    encode_tick_row,
};
use crate::mcap::record::{LoggedTick, WorldSample};
use crate::mcap::schemas::*;
use ::mcap::records::{MessageHeader, Metadata};
use ::mcap::{WriteOptions, Writer};
use haptic2d::haptic::TickRecord;
use haptic2d::world::World;
use std::collections::BTreeMap;
use std::io::{Seek, Write};

/// Default rate of the Foxglove `SceneUpdate` messages in a log (Hz): enough for smooth playback,
/// small next to the full-rate channels.
pub const DEFAULT_SCENE_UPDATE_HZ: f64 = 60.0;

pub use crate::mcap::encode::{BodyGeom, FORCE_LINE_M_PER_N};

/// What a log says about its run, fixed at the start.
#[derive(Clone, Debug, Default)]
pub struct McapSetup {
    /// Strings of the `/haptic2d/scene` message and the `haptic2d.scene` metadata record: scene
    /// name, scene file text, device file text, rate, controller, …
    pub scene: BTreeMap<String, String>,
    /// The bodies (in world order).
    pub bodies: Vec<BodyGeom>,
    /// Rate of the `SceneUpdate` messages (Hz); ≤ 0 writes none.
    pub scene_update_hz: f64,
    /// Register `/haptic2d/tick` (false for `haptic2d simulate`, which has no haptic loop).
    pub ticks: bool,
    /// Register the world channels (bodies, contacts, energy, `SceneUpdate`); false for a tick log
    /// converted from CSV, which has no world samples.
    pub world: bool,
    /// What the `log_time`s count (written as the metadata record `haptic2d.clock`).
    pub clock: LogClock,
}

impl McapSetup {
    /// A setup for `world`'s bodies, with the scene strings `scene`.
    pub fn for_world(world: &World, scene: BTreeMap<String, String>, ticks: bool) -> Self {
        let bodies = world
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| BodyGeom {
                name: b.name.clone(),
                dynamic: b.is_dynamic(),
                outlines: world
                    .colliders
                    .iter()
                    .filter(|c| c.body == i)
                    .map(|c| c.local.vertices().iter().map(|v| [v.x, v.y]).collect())
                    .collect(),
            })
            .collect();
        let clock = if ticks {
            LogClock::UnixFromMonotonic {
                offset_ns: monotonic_to_unix_offset_ns(),
            }
        } else {
            LogClock::UnixFromSimTime {
                start_ns: unix_now_ns(),
            }
        };
        Self {
            scene,
            bodies,
            scene_update_hz: DEFAULT_SCENE_UPDATE_HZ,
            ticks,
            world: true,
            clock,
        }
    }

    /// A setup for a tick log without world samples (`haptic2d log convert` of a CSV).
    pub fn ticks_only(scene: BTreeMap<String, String>) -> Self {
        Self {
            scene,
            bodies: Vec::new(),
            scene_update_hz: 0.0,
            ticks: true,
            world: false,
            clock: LogClock::Converted,
        }
    }
}

/// Counts of what a finished log holds (from the writer's summary statistics).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct McapStats {
    /// Messages in the file.
    pub messages: u64,
    /// Messages per topic, in topic order.
    pub per_topic: Vec<(String, u64)>,
}

impl McapStats {
    /// Messages on `topic` (0 if none).
    pub fn count(&self, topic: &str) -> u64 {
        self.per_topic
            .iter()
            .find(|(t, _)| t == topic)
            .map_or(0, |(_, n)| *n)
    }
}

#[derive(Clone, Copy)]
struct Channels {
    tick: Option<u16>,
    bodies: Option<u16>,
    contacts: Option<u16>,
    energy: Option<u16>,
    scene: u16,
    scene_update: Option<u16>,
    tf: Option<u16>,
}

/// An MCAP file being written (not thread-bound: the [`McapLogger`](super::McapLogger) thread and
/// `haptic2d simulate` both drive one).
pub struct McapSink<W: Write + Seek> {
    w: Writer<W>,
    ch: Channels,
    setup: McapSetup,
    /// Body names as JSON strings (quoted, escaped), encoded once.
    names_json: Vec<String>,
    buf: Vec<u8>,
    scene_written: bool,
    next_scene_update_ns: u64,
    scene_update_period_ns: u64,
    ticks: u64,
}

fn io_err(e: std::io::Error) -> ::mcap::McapError {
    ::mcap::McapError::Io(e)
}

impl<W: Write + Seek> McapSink<W> {
    /// Starts an MCAP file on `out`: header, schemas and channels.
    pub fn new(out: W, setup: McapSetup) -> ::mcap::McapResult<Self> {
        let opts = WriteOptions::new()
            .profile("")
            .library(concat!("haptic2d ", env!("CARGO_PKG_VERSION")))
            .compression(None);
        let mut w = opts.create(out)?;
        let none = BTreeMap::new();
        let add = |w: &mut Writer<W>, schema: &str, data: &str, topic: &str| {
            let s = w.add_schema(schema, "jsonschema", data.as_bytes())?;
            w.add_channel(s, topic, "json", &none)
        };
        let tick = if setup.ticks {
            Some(add(&mut w, SCHEMA_TICK, &tick_json_schema(), TOPIC_TICK)?)
        } else {
            None
        };
        let (bodies, contacts, energy) = if setup.world {
            (
                Some(add(&mut w, SCHEMA_BODIES, BODIES_SCHEMA, TOPIC_BODIES)?),
                Some(add(
                    &mut w,
                    SCHEMA_CONTACTS,
                    CONTACTS_SCHEMA,
                    TOPIC_CONTACTS,
                )?),
                Some(add(&mut w, SCHEMA_ENERGY, ENERGY_SCHEMA, TOPIC_ENERGY)?),
            )
        } else {
            (None, None, None)
        };
        let scene = add(&mut w, SCHEMA_SCENE, SCENE_SCHEMA, TOPIC_SCENE)?;
        let scene_update = if setup.world && setup.scene_update_hz > 0.0 {
            Some(add(
                &mut w,
                SCHEMA_SCENE_UPDATE,
                SCENE_UPDATE_SCHEMA,
                TOPIC_SCENE_UPDATE,
            )?)
        } else {
            None
        };
        let tf = if setup.world && setup.scene_update_hz > 0.0 {
            Some(add(&mut w, SCHEMA_TF, TF_SCHEMA, TOPIC_TF)?)
        } else {
            None
        };
        w.write_metadata(&Metadata {
            name: "haptic2d.scene".into(),
            metadata: setup.scene.clone(),
        })?;
        w.write_metadata(&clock_metadata(setup.clock))?;
        let names_json = setup
            .bodies
            .iter()
            .map(|b| serde_json::Value::String(b.name.clone()).to_string())
            .collect();
        let period = if setup.scene_update_hz > 0.0 {
            (1e9 / setup.scene_update_hz).round() as u64
        } else {
            u64::MAX
        };
        Ok(Self {
            w,
            ch: Channels {
                tick,
                bodies,
                contacts,
                energy,
                scene,
                scene_update,
                tf,
            },
            setup,
            names_json,
            buf: Vec::with_capacity(16 * 1024),
            scene_written: false,
            next_scene_update_ns: 0,
            scene_update_period_ns: period.max(1),
            ticks: 0,
        })
    }

    fn emit(&mut self, channel_id: u16, seq: u64, log_time: u64) -> ::mcap::McapResult<()> {
        let header = MessageHeader {
            channel_id,
            sequence: seq as u32,
            log_time,
            publish_time: log_time,
        };
        self.w.write_to_known_channel(&header, &self.buf)
    }

    fn scene_once(&mut self, log_time: u64) -> ::mcap::McapResult<()> {
        if self.scene_written {
            return Ok(());
        }
        self.scene_written = true;
        self.buf.clear();
        serde_json::to_writer(&mut self.buf, &self.setup.scene).map_err(|e| io_err(e.into()))?;
        self.emit(self.ch.scene, 0, log_time)
    }

    /// Writes one haptic tick: `/haptic2d/tick`, and — when the tick carries a world sample — the
    /// bodies, contacts, energy and (decimated) `SceneUpdate`.
    pub fn write_tick(&mut self, t: &LoggedTick) -> ::mcap::McapResult<()> {
        let log_time = match self.setup.clock {
            LogClock::UnixFromMonotonic { offset_ns } => t.deadline_ns.saturating_add(offset_ns),
            _ => t.deadline_ns,
        };
        self.scene_once(log_time)?;
        let row = tick_row(t.index, t.deadline_ns, t.lateness_ns, &t.q, &t.rec);
        self.write_tick_row(t.index, log_time, &row)?;
        if t.world.body_count > 0 {
            self.write_world_of(t.index, log_time, &t.world, Some(&t.rec))?;
        }
        Ok(())
    }

    /// The `log_time` (ns) of a world sample at simulated time `t_s` (s): the Unix time the log
    /// started + `round(t · 10⁹)` ([`LogClock::UnixFromSimTime`]), else `round(t · 10⁹)`.
    pub fn sim_log_time(&self, t_s: f64) -> u64 {
        let t = (t_s.max(0.0) * 1e9).round() as u64;
        match self.setup.clock {
            LogClock::UnixFromSimTime { start_ns } => start_ns.saturating_add(t),
            _ => t,
        }
    }

    /// Writes one `/haptic2d/tick` message from a row (present cells only) at `log_time` (ns);
    /// nothing without a tick channel.
    pub fn write_tick_row(
        &mut self,
        seq: u64,
        log_time: u64,
        row: &TickRow,
    ) -> ::mcap::McapResult<()> {
        self.scene_once(log_time)?;
        if let Some(id) = self.ch.tick {
            self.buf.clear();
            encode_tick_row(&mut self.buf, row).map_err(io_err)?;
            self.emit(id, seq, log_time)?;
            self.ticks += 1;
        }
        Ok(())
    }

    /// Writes one world sample (bodies, contacts, energy, decimated `SceneUpdate`) at `log_time` (ns).
    pub fn write_world(
        &mut self,
        seq: u64,
        log_time: u64,
        s: &WorldSample,
    ) -> ::mcap::McapResult<()> {
        self.write_world_of(seq, log_time, s, None)
    }

    /// [`write_world`](Self::write_world); `tick`: the haptic tick's record, whose device and slave
    /// poses join the bodies' in the `FrameTransforms`.
    fn write_world_of(
        &mut self,
        seq: u64,
        log_time: u64,
        s: &WorldSample,
        tick: Option<&TickRecord>,
    ) -> ::mcap::McapResult<()> {
        self.scene_once(log_time)?;
        let (Some(bodies), Some(contacts), Some(energy)) =
            (self.ch.bodies, self.ch.contacts, self.ch.energy)
        else {
            return Ok(());
        };
        self.buf.clear();
        encode_bodies(&mut self.buf, &self.names_json, s).map_err(io_err)?;
        self.emit(bodies, seq, log_time)?;
        self.buf.clear();
        encode_contacts(&mut self.buf, &self.names_json, s).map_err(io_err)?;
        self.emit(contacts, seq, log_time)?;
        self.buf.clear();
        encode_energy(&mut self.buf, s).map_err(io_err)?;
        self.emit(energy, seq, log_time)?;
        if let Some(id) = self.ch.scene_update {
            if log_time >= self.next_scene_update_ns {
                self.next_scene_update_ns = log_time.saturating_add(self.scene_update_period_ns);
                self.buf.clear();
                encode_scene_update(
                    &mut self.buf,
                    &self.setup.bodies,
                    &self.names_json,
                    s,
                    log_time,
                )
                .map_err(io_err)?;
                self.emit(id, seq, log_time)?;
                if let Some(tf) = self.ch.tf {
                    self.buf.clear();
                    encode_frame_transforms(&mut self.buf, &self.names_json, s, tick, log_time)
                        .map_err(io_err)?;
                    self.emit(tf, seq, log_time)?;
                }
            }
        }
        Ok(())
    }

    /// Ticks written to `/haptic2d/tick` so far.
    pub fn ticks_written(&self) -> u64 {
        self.ticks
    }

    /// Writes the metadata records `extra` (e.g. the run's timing summary), then the summary section
    /// and index; returns the message counts.
    pub fn finish(mut self, extra: &[Metadata]) -> ::mcap::McapResult<McapStats> {
        for m in extra {
            self.w.write_metadata(m)?;
        }
        let summary = self.w.finish()?;
        self.w.into_inner().flush().map_err(io_err)?;
        let mut per_topic: Vec<(String, u64)> = Vec::new();
        let mut messages = 0;
        if let Some(st) = &summary.stats {
            messages = st.message_count;
            for (id, n) in &st.channel_message_counts {
                if let Some(c) = summary.channels.get(id) {
                    per_topic.push((c.topic.clone(), *n));
                }
            }
        }
        per_topic.sort();
        Ok(McapStats {
            messages,
            per_topic,
        })
    }
}
