//! # haptic2d-view
//!
//! Live display of a running haptic2d world in the browser.
//!
//! The haptic loop owns a [`ViewHub`]: between ticks it drains [`ViewHub::poll_command`], and when
//! [`ViewHub::frame_due`] it captures the world into a preallocated [`Frame`] and publishes it
//! ([`ViewHub::publish_frame`]); after loading a scene it publishes a [`SceneInfo`]. All of this is
//! wait-free and allocation-free in steady state. [`ViewServer::start`] runs axum on its own thread
//! with its own tokio runtime and serves the embedded page, the WebSocket and a health check.
//!
//! ```no_run
//! use haptic2d_view::{Frame, FrameInputs, SceneInfo, ViewHub, ViewOptions, ViewServer};
//! let scene = haptic2d::scene::builtin("box-in-walls", Some(1000.0)).unwrap().unwrap();
//! let mut world = scene.world;
//! let (mut hub, end) = ViewHub::new(&Frame::for_world(&world), 60.0).unwrap();
//! let server = ViewServer::start("127.0.0.1:8080".parse().unwrap(), end, ViewOptions::default())
//!     .unwrap();
//! eprintln!("{}", server.banner());
//! hub.publish_scene(SceneInfo::from_world(&world, &scene.name, "", Some(1), None)).unwrap();
//! // in the loop, between ticks:
//! while let Some(cmd) = hub.poll_command() { /* apply it */ let _ = cmd; }
//! world.step();
//! if hub.frame_due(world.time()) {
//!     hub.publish_frame(world.time(), &world, &FrameInputs::default());
//! }
//! ```
#![warn(missing_docs)]

pub mod access;
pub mod command;
mod connection;
pub mod frame;
pub mod http;
pub mod hub;
pub mod scene_budget;
pub mod scene_info;
pub mod server;
pub mod timing;

pub use command::{
    parse_client_message, ClientMessage, Command, ControllerKind, MAX_MESSAGE_BYTES,
};
pub use frame::{ContactView, DeviceView, Energies, Frame, FrameInputs, LoopTiming, StudyView};
pub use hub::{ServerEnd, ViewHub, DEFAULT_FRAME_RATE_HZ};
pub use scene_budget::{assess_builtin_scenes, SceneCost, DEFAULT_STEP_FRACTION};
pub use scene_info::{BodyShape, DeviceGeometry, SceneInfo};
pub use server::{ServerStats, ViewHandle, ViewOptions, ViewServer};
pub use timing::LiveTiming;
