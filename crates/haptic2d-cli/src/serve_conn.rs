//! The study server's client protocol (`haptic2d study serve`, docs/STUDIES.md "Driving trials
//! from Python or PsychoPy on the device"): one JSON object per line each way, over TCP on loopback.
//!
//! Requests (`cmd`): `present` {`condition`, `delta` (a number, or null/absent for the reference),
//! `duration_s` (a number, or null/absent: until `end`)}, `end`, `status`, `stop`. Every reply has
//! `ok` and `cmd`; an error has `error` (the reason). A timed `present` is answered when its interval
//! ends, with what the loop measured; an open-ended one is acknowledged at once (`"until": "end"`)
//! and `end` is answered with the measures. While an answer is pending, `status` and `stop` are
//! served; any other request is refused (one presentation at a time).
//!
//! This is the main thread's side: it builds the stimulus (allocating, never in a tick), hands it to
//! the loop through a wait-free ring and turns the loop's reports into replies.

use crate::serve_present::{FromLoop, Measured, Request, ToLoop};
use crate::study_browser::stimulus_laws;
use haptic2d_lab::study::Study;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Longest request line (bytes); a longer one is refused and the client disconnected.
pub const MAX_LINE: usize = 64 * 1024;

/// Longest presentation a client may ask for (s).
pub const MAX_DURATION_S: f64 = 600.0;

/// What the connection loop must do after a request.
#[derive(Debug, PartialEq)]
pub enum Action {
    /// Keep serving.
    Continue,
    /// The client asked to stop the server.
    Stop,
}

/// The presentation whose answer is pending.
#[derive(Clone, Debug)]
struct Pending {
    id: u32,
    /// The reply's `cmd`: `present` (timed) or `end` (open-ended, ended).
    reply_cmd: &'static str,
    condition: String,
    delta: Option<f64>,
    /// Open-ended (until `end`).
    open: bool,
    /// The client sent `end` (its answer is this presentation's measures).
    ended: bool,
    started_s: Option<f64>,
}

/// The protocol's state on the main thread.
pub struct Protocol<'a> {
    study: &'a Study,
    to_loop: rtrb::Producer<ToLoop>,
    pending: Option<Pending>,
    next_id: u32,
    done: u32,
    trials_dir: Option<PathBuf>,
    device: String,
}

fn error(cmd: &str, why: impl Into<String>) -> Value {
    json!({"ok": false, "cmd": cmd, "error": why.into()})
}

/// An optional finite number field of `v` (null or absent: `None`).
fn number(v: &Value, key: &str) -> Result<Option<f64>, String> {
    match v.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(x) => match x.as_f64() {
            Some(f) if f.is_finite() => Ok(Some(f)),
            _ => Err(format!("`{key}` must be a finite number or null (got {x})")),
        },
    }
}

impl<'a> Protocol<'a> {
    /// The protocol for `study`, sending to the loop through `to_loop`; the presentations' MCAP
    /// logs are in `trials_dir` (`--out`), if any; `device` names the device in `status`.
    pub fn new(
        study: &'a Study,
        to_loop: rtrb::Producer<ToLoop>,
        trials_dir: Option<PathBuf>,
        device: String,
    ) -> Self {
        Self {
            study,
            to_loop,
            pending: None,
            next_id: 1,
            done: 0,
            trials_dir,
            device,
        }
    }

    /// Handles one request line; returns the replies to send now and what to do next.
    pub fn request(&mut self, line: &str, t_s: f64) -> (Vec<Value>, Action) {
        let v: Value = match serde_json::from_str(line) {
            Ok(v @ Value::Object(_)) => v,
            Ok(_) => {
                return (
                    vec![error("", "a request is a JSON object")],
                    Action::Continue,
                )
            }
            Err(e) => return (vec![error("", format!("not JSON: {e}"))], Action::Continue),
        };
        let cmd = v.get("cmd").and_then(Value::as_str).unwrap_or("");
        match cmd {
            "status" => (vec![self.status(t_s)], Action::Continue),
            "stop" => {
                let mut out = Vec::new();
                if let Some(p) = self.pending.take() {
                    out.push(error(p.reply_cmd, "the server was stopped by the client"));
                }
                out.push(json!({"ok": true, "cmd": "stop"}));
                (out, Action::Stop)
            }
            "present" => (self.present(&v).into_iter().collect(), Action::Continue),
            "end" => (self.end().into_iter().collect(), Action::Continue),
            "" => (
                vec![error("", "no `cmd`: give present, end, status or stop")],
                Action::Continue,
            ),
            other => (
                vec![error(
                    other,
                    format!("unknown command `{other}`: give present, end, status or stop"),
                )],
                Action::Continue,
            ),
        }
    }

    fn present(&mut self, v: &Value) -> Option<Value> {
        if let Some(p) = &self.pending {
            return Some(error(
                "present",
                format!("presentation {} is still running: one at a time", p.id),
            ));
        }
        let Some(condition) = v.get("condition").and_then(Value::as_str) else {
            return Some(error("present", "`condition` (a string) is missing"));
        };
        let Some(c) = self
            .study
            .conditions
            .iter()
            .position(|x| x.name == condition)
        else {
            return Some(error(
                "present",
                format!(
                    "unknown condition `{condition}`; the study's: {}",
                    self.condition_names().join(", ")
                ),
            ));
        };
        let (delta, duration) = match (number(v, "delta"), number(v, "duration_s")) {
            (Ok(d), Ok(t)) => (d, t),
            (Err(e), _) | (_, Err(e)) => return Some(error("present", e)),
        };
        if let Some(t) = duration.filter(|t| !(*t > 0.0 && *t <= MAX_DURATION_S)) {
            return Some(error(
                "present",
                format!("duration_s = {t}: give 0 < duration_s <= {MAX_DURATION_S} s, or null (until end)"),
            ));
        }
        let laws = match stimulus_laws(self.study, c, delta.is_some(), delta.unwrap_or(0.0)) {
            Ok(l) => l,
            Err(e) => return Some(error("present", format!("the stimulus is invalid: {e}"))),
        };
        let id = self.next_id;
        let req = Request {
            id,
            laws,
            duration_s: duration,
        };
        if self.to_loop.push(ToLoop::Present(req)).is_err() {
            return Some(error("present", "the loop is not taking requests"));
        }
        self.next_id += 1;
        self.pending = Some(Pending {
            id,
            reply_cmd: "present",
            condition: condition.to_string(),
            delta,
            open: duration.is_none(),
            ended: false,
            started_s: None,
        });
        duration
            .is_none()
            .then(|| json!({"ok": true, "cmd": "present", "id": id, "until": "end"}))
    }

    fn end(&mut self) -> Option<Value> {
        match &mut self.pending {
            Some(p) if p.open && !p.ended => {
                p.ended = true;
                p.reply_cmd = "end";
                let id = p.id;
                if self.to_loop.push(ToLoop::End(id)).is_err() {
                    return Some(error("end", "the loop is not taking requests"));
                }
                None
            }
            _ => Some(error(
                "end",
                "no open-ended presentation is running (present with duration_s null first)",
            )),
        }
    }

    /// The names of the study's conditions, in file order.
    fn condition_names(&self) -> Vec<&str> {
        let c = &self.study.conditions;
        c.iter().map(|c| c.name.as_str()).collect()
    }

    /// The reply to `status` at loop time `t_s` (s).
    pub fn status(&self, t_s: f64) -> Value {
        let state = match &self.pending {
            None => "idle",
            Some(p) if p.started_s.is_none() => "waiting_for_free_space",
            Some(_) => "presenting",
        };
        let conditions = self.condition_names();
        json!({
            "ok": true, "cmd": "status", "state": state, "study": self.study.name,
            "conditions": conditions, "device": self.device, "presented": self.done,
            "current": self.pending.as_ref().map(|p| p.id), "t_s": t_s,
        })
    }

    /// Turns a report of the loop into the reply it completes, if any.
    pub fn on_report(&mut self, ev: FromLoop) -> Option<Value> {
        match ev {
            FromLoop::Started { id, t_s } => {
                if let Some(p) = self.pending.as_mut().filter(|p| p.id == id) {
                    p.started_s = Some(t_s);
                }
                None
            }
            FromLoop::Done { id, measured } => {
                let p = self.pending.take_if(|p| p.id == id)?;
                self.done += 1;
                Some(done_reply(&p, &measured, self.trials_dir.as_deref()))
            }
            FromLoop::NotFree { id, waited_s } => {
                let p = self.pending.take_if(|p| p.id == id)?;
                Some(error(
                    p.reply_cmd,
                    format!("presentation {id} did not start: the probe stayed in contact for {waited_s:.1} s of loop time (the stimulus is switched only in free space; lift the handle off)"),
                ))
            }
            FromLoop::Busy { id } => {
                let p = self.pending.take_if(|p| p.id == id)?;
                Some(error(p.reply_cmd, "the loop was still presenting"))
            }
        }
    }

    /// The pending presentation's error reply when the server ends with `why` (the client lost,
    /// the loop stopped): taken, so that it is sent once.
    pub fn abandon(&mut self, why: &str) -> Option<Value> {
        self.pending.take().map(|p| error(p.reply_cmd, why))
    }

    /// The pending presentation the loop must end because the client went away.
    pub fn drop_client(&mut self) -> Option<u32> {
        let id = self.pending.as_ref()?.id;
        let _ = self.to_loop.push(ToLoop::End(id));
        Some(id)
    }
}

fn done_reply(p: &Pending, m: &Measured, trials: Option<&Path>) -> Value {
    let mcap = trials.map(|d| crate::study_mcap::trial_path(d, p.id).display().to_string());
    json!({
        "ok": true, "cmd": p.reply_cmd, "id": p.id, "condition": p.condition, "delta": p.delta,
        "start_s": m.start_s, "end_s": m.end_s, "peak_force_n": m.peak_force_n,
        "mean_force_n": m.mean_force_n(), "deepest_m": m.deepest_m, "contact_s": m.contact_s,
        "ticks": m.ticks, "mcap": mcap,
    })
}
