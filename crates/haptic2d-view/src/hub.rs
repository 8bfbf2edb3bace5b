//! The loop's end of the display: [`ViewHub`] lives on the haptic thread, [`ServerEnd`] goes to the
//! server thread. Everything between them is wait-free:
//!
//! - frames: a triple buffer of preallocated [`Frame`]s (the loop fills the back buffer in place and
//!   publishes; the server reads the latest one at its own pace);
//! - scene descriptions: a small `rtrb` ring of [`SceneInfo`] (built by the loop when it loads a
//!   scene, freed on the server thread);
//! - commands: an `rtrb` ring of [`Command`]s the loop drains between ticks;
//! - the number of connected viewers: an atomic counter, so the loop can skip capturing frames
//!   nobody watches.

use crate::command::Command;
use crate::frame::{Frame, FrameInputs, StudyView};
use crate::scene_info::SceneInfo;
use haptic2d::world::World;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// Commands the ring holds; further commands are refused with an error to the page.
pub const COMMAND_CAPACITY: usize = 256;
/// Scene descriptions the ring holds (the loop publishes one per scene change).
pub const SCENE_CAPACITY: usize = 4;
/// Default frame rate sent to viewers (Hz).
pub const DEFAULT_FRAME_RATE_HZ: f64 = 60.0;

/// The haptic loop's end: publish frames and scenes, poll commands. Never blocks, never allocates
/// after construction (except inside [`Frame::capture`] if a world outgrows the frame's capacity).
pub struct ViewHub {
    frames: triple_buffer::Input<Frame>,
    scenes: rtrb::Producer<SceneInfo>,
    commands: rtrb::Consumer<Command>,
    viewers: Arc<AtomicUsize>,
    frame_period_s: f64,
    next_frame_s: f64,
    frame_seq: u64,
    scene_seq: u64,
    study: Option<StudyView>,
}

/// The server thread's end of a [`ViewHub`]; give it to [`ViewServer::start`](crate::ViewServer::start).
pub struct ServerEnd {
    pub(crate) frames: triple_buffer::Output<Frame>,
    pub(crate) scenes: rtrb::Consumer<SceneInfo>,
    pub(crate) commands: rtrb::Producer<Command>,
    pub(crate) viewers: Arc<AtomicUsize>,
    pub(crate) frame_rate_hz: f64,
}

impl ViewHub {
    /// A hub whose frames are preallocated like `prototype` (see [`Frame::for_world`]), sent at
    /// `frame_rate_hz` (Hz, e.g. [`DEFAULT_FRAME_RATE_HZ`]; at most 1000). Returns the loop's end
    /// and the server's end.
    pub fn new(prototype: &Frame, frame_rate_hz: f64) -> Result<(ViewHub, ServerEnd), String> {
        if !(frame_rate_hz.is_finite() && frame_rate_hz > 0.0 && frame_rate_hz <= 1000.0) {
            return Err(format!(
                "frame_rate_hz = {frame_rate_hz}: must be in (0, 1000] Hz (default 60)"
            ));
        }
        let (fin, fout) = triple_buffer::triple_buffer(prototype);
        let (stx, srx) = rtrb::RingBuffer::new(SCENE_CAPACITY);
        let (ctx, crx) = rtrb::RingBuffer::new(COMMAND_CAPACITY);
        let viewers = Arc::new(AtomicUsize::new(0));
        Ok((
            ViewHub {
                frames: fin,
                scenes: stx,
                commands: crx,
                viewers: viewers.clone(),
                frame_period_s: 1.0 / frame_rate_hz,
                next_frame_s: 0.0,
                frame_seq: 0,
                scene_seq: 0,
                study: None,
            },
            ServerEnd {
                frames: fout,
                scenes: srx,
                commands: ctx,
                viewers,
                frame_rate_hz,
            },
        ))
    }

    /// The next command from the page, if any. Call it between ticks until it returns `None`
    /// (see [`Command`] for what each one must do). Wait-free.
    #[inline]
    pub fn poll_command(&mut self) -> Option<Command> {
        self.commands.pop().ok()
    }

    /// Number of viewers connected now.
    #[inline]
    pub fn viewers(&self) -> usize {
        self.viewers.load(Ordering::Relaxed)
    }

    /// True when a frame is due at loop time `now_s` (s, monotonic: the runner's `TickInfo::t_s`)
    /// and someone is watching. Frames are spaced by the frame period; a late one does not cause a
    /// burst.
    #[inline]
    pub fn frame_due(&self, now_s: f64) -> bool {
        now_s >= self.next_frame_s && self.viewers() > 0
    }

    /// Captures `world` and `inputs` into the back buffer and publishes it (see
    /// [`Frame::capture`]), then schedules the next frame one period after `now_s` (s). Call it when
    /// [`frame_due`](Self::frame_due) says so. Wait-free; no allocation once the frames have their
    /// capacity.
    pub fn publish_frame(&mut self, now_s: f64, world: &World, inputs: &FrameInputs<'_>) {
        let (seq, scene_seq) = (self.frame_seq, self.scene_seq);
        let f = self.frames.input_buffer_mut();
        f.capture(world, inputs);
        f.study = self.study;
        f.seq = seq;
        f.scene_seq = scene_seq;
        self.frames.publish();
        self.frame_seq += 1;
        // Skip ahead if the loop fell behind, so that frames never come in a burst.
        let next = self.next_frame_s + self.frame_period_s;
        self.next_frame_s = if next > now_s {
            next
        } else {
            now_s + self.frame_period_s
        };
    }

    /// Publishes a new scene description (after loading or resetting a scene). Frames published
    /// from now on carry its sequence number. Wait-free (the `SceneInfo` was built by the caller;
    /// it is freed on the server thread). Errors, returning nothing, if
    /// [`SCENE_CAPACITY`] descriptions are still waiting for the server.
    pub fn publish_scene(&mut self, mut info: SceneInfo) -> Result<u64, String> {
        let seq = self.scene_seq + 1;
        info.seq = seq;
        self.scenes
            .push(info)
            .map_err(|_| "the display server is not taking scene descriptions".to_string())?;
        self.scene_seq = seq;
        Ok(seq)
    }

    /// The study trial the next frames show (`None` outside a study). Wait-free, no allocation.
    #[inline]
    pub fn set_study(&mut self, study: Option<StudyView>) {
        self.study = study;
    }

    /// Sequence number of the last published scene (0 before the first).
    pub fn scene_seq(&self) -> u64 {
        self.scene_seq
    }
}
