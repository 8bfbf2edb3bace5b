//! One viewer's WebSocket: forwards broadcasts, handles the page's messages, enforces the access
//! rules of [`crate::access`] (view-only connections, the token and its tries) and the scene budget
//! of [`crate::scene_budget`].

use crate::access::{token_eq, Access, MAX_TOKEN_TRIES};
use crate::command::MAX_MESSAGE_BYTES;
use crate::command::{parse_client_message, scene_names, ClientMessage, Command, ControllerKind};
use crate::server::{stopped, to_text, AppState, Options, Outgoing, HARD_MESSAGE_LIMIT};
use axum::extract::ws::{close_code, CloseFrame, Message, Utf8Bytes, WebSocket};
use haptic2d::laws::friction::FrictionModel;
use haptic2d::laws::normal::NORMAL_MODEL_NAMES;
use std::net::SocketAddr;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use tokio::sync::broadcast;

/// Error lines logged per connection before that connection's errors are no longer logged.
const LOG_BUDGET: u32 = 20;

/// What to do after a message from the page.
#[derive(Debug, PartialEq)]
pub(crate) enum Reply {
    /// Nothing to send.
    None,
    /// Send this text.
    Send(Utf8Bytes),
    /// Send this text, then close the connection (policy violation).
    Close(Utf8Bytes),
}

/// One connection to the page.
pub(crate) struct Viewer {
    state: Arc<AppState>,
    peer: SocketAddr,
    access: Access,
    /// Failed token tries so far (wrong tokens, or any token on a view-only connection); a wrong
    /// `?token=` in the URL counts.
    token_failures: u32,
    log_budget: u32,
}

impl Viewer {
    /// A viewer with the access decided at the upgrade, having already failed `token_failures`
    /// token tries (the URL's).
    pub(crate) fn new(
        state: Arc<AppState>,
        peer: SocketAddr,
        access: Access,
        token_failures: u32,
    ) -> Self {
        Self {
            state,
            peer,
            access,
            token_failures,
            log_budget: LOG_BUDGET,
        }
    }

    fn control(&self) -> bool {
        self.access == Access::Control
    }

    fn welcome(&self) -> Utf8Bytes {
        let view_only_reason = match &self.access {
            Access::Control => None,
            Access::NeedsToken => Some(
                "view only: commands need the token printed at startup (open the page with ?token=…)",
            ),
            Access::ViewOnly(why) => Some(why.as_str()),
        };
        to_text(&Outgoing::Welcome {
            control: self.control(),
            token_required: self.state.token.is_some(),
            view_only_reason,
            frame_rate_hz: self.state.frame_rate_hz,
            max_message_bytes: MAX_MESSAGE_BYTES,
            options: Options {
                scenes: scene_names(),
                scene_costs: &self.state.scene_costs,
                wall_laws: NORMAL_MODEL_NAMES.to_vec(),
                friction_models: FrictionModel::NAMES.to_vec(),
                impact_friction_modes: haptic2d::contact::ImpactFriction::NAMES.to_vec(),
                controllers: ControllerKind::ALL.iter().map(|c| c.name()).collect(),
            },
        })
    }

    /// Counts, logs (within the budget) and returns the error frame for a rejected message.
    fn reject(&mut self, message: &str) -> Utf8Bytes {
        self.state
            .counters
            .bad_messages
            .fetch_add(1, Ordering::Relaxed);
        self.log(message);
        to_text(&Outgoing::Error { message })
    }

    fn log(&mut self, message: &str) {
        if self.log_budget > 0 {
            self.log_budget -= 1;
            let more = if self.log_budget == 0 {
                " (further errors from this viewer are not logged)"
            } else {
                ""
            };
            eprintln!("haptic2d-view: viewer {}: {message}{more}", self.peer);
        }
    }

    /// A `hello` with `token`: one try. After [`MAX_TOKEN_TRIES`] failed tries the next one closes
    /// the connection, whatever the token; a view-only connection's tokens are never compared
    /// (every one fails).
    fn hello(&mut self, token: &str) -> Reply {
        if self.access == Access::Control {
            return Reply::Send(self.welcome());
        }
        if self.token_failures >= MAX_TOKEN_TRIES {
            self.state
                .counters
                .token_lockouts
                .fetch_add(1, Ordering::Relaxed);
            let msg = format!(
                "{MAX_TOKEN_TRIES} wrong tokens on this connection: closing it (reconnect and use the token printed at startup)"
            );
            return Reply::Close(self.reject(&msg));
        }
        match &self.access {
            Access::ViewOnly(why) => {
                self.token_failures += 1;
                let why = why.clone();
                Reply::Send(self.reject(&why))
            }
            Access::Control => Reply::Send(self.welcome()),
            Access::NeedsToken => {
                let right = self
                    .state
                    .token
                    .as_deref()
                    .is_some_and(|t| token_eq(t, token));
                if right {
                    self.access = Access::Control;
                    Reply::Send(self.welcome())
                } else {
                    self.token_failures += 1;
                    let left = MAX_TOKEN_TRIES - self.token_failures;
                    Reply::Send(self.reject(&format!(
                        "wrong token ({left} tries left on this connection)"
                    )))
                }
            }
        }
    }

    /// A command from the page: forwarded to the loop if this viewer may command it and the
    /// command is one the loop can run.
    fn command(&mut self, cmd: Command) -> Reply {
        match &self.access {
            Access::Control => {}
            Access::NeedsToken => {
                return Reply::Send(self.reject(
                    "commands need the token printed at startup (open the page with ?token=…)",
                ))
            }
            Access::ViewOnly(why) => {
                let why = why.clone();
                return Reply::Send(self.reject(&why));
            }
        }
        if let Command::SwitchScene { name } = cmd {
            let refusal = self
                .state
                .scene_costs
                .iter()
                .find(|c| c.name == name && !c.runnable)
                .and_then(|c| c.reason.clone());
            if let Some(why) = refusal {
                return Reply::Send(self.reject(&format!("switch_scene refused: {why}")));
            }
        }
        let pushed = match self.state.commands.lock() {
            Ok(mut p) => p.push(cmd).is_ok(),
            Err(_) => false,
        };
        if !pushed {
            return Reply::Send(
                self.reject("command queue full: the haptic loop is not taking commands"),
            );
        }
        self.state
            .counters
            .commands_forwarded
            .fetch_add(1, Ordering::Relaxed);
        match cmd {
            Command::SetHandTarget { .. } => Reply::None,
            _ => Reply::Send(to_text(&Outgoing::Ack {
                command: cmd.kind(),
            })),
        }
    }

    /// The reply to one message from the page.
    fn handle(&mut self, msg: Message) -> Reply {
        let text = match msg {
            Message::Text(t) => t,
            Message::Binary(_) => {
                return Reply::Send(
                    self.reject("binary messages are not supported; send JSON text"),
                )
            }
            _ => return Reply::None,
        };
        match parse_client_message(text.as_str()) {
            Err(e) => Reply::Send(self.reject(&e)),
            Ok(ClientMessage::Hello { token }) => self.hello(&token),
            Ok(ClientMessage::Command(cmd)) => self.command(cmd),
        }
    }
}

/// Serves one upgraded connection until the page leaves, breaks a rule that closes it, or the
/// server shuts down.
pub(crate) async fn run(mut socket: WebSocket, mut v: Viewer) {
    let state = v.state.clone();
    state.viewers.fetch_add(1, Ordering::Relaxed);
    let mut rx = state.frames_tx.subscribe();
    let mut shutdown = state.shutdown.clone();
    let scene = state.scene_rx.borrow().clone();
    let mut ok = socket.send(Message::Text(v.welcome())).await.is_ok();
    if let (true, Some(s)) = (ok, scene) {
        ok = socket.send(Message::Text(s)).await.is_ok();
    }
    while ok {
        tokio::select! {
            r = rx.recv() => match r {
                Ok(text) => ok = socket.send(Message::Text(text)).await.is_ok(),
                Err(broadcast::error::RecvError::Lagged(_)) => {}
                Err(broadcast::error::RecvError::Closed) => ok = false,
            },
            m = socket.recv() => match m {
                Some(Ok(Message::Close(_))) | None => ok = false,
                Some(Ok(msg)) => match v.handle(msg) {
                    Reply::None => {}
                    Reply::Send(reply) => ok = socket.send(Message::Text(reply)).await.is_ok(),
                    Reply::Close(reply) => {
                        let _ = socket.send(Message::Text(reply)).await;
                        let _ = socket
                            .send(Message::Close(Some(CloseFrame {
                                code: close_code::POLICY,
                                reason: "too many token tries".into(),
                            })))
                            .await;
                        ok = false;
                    }
                },
                Some(Err(e)) => {
                    // A message over the hard limit ends the connection (tungstenite's capacity
                    // error): count and log it. Other errors are disconnects (a closed tab, a
                    // reset): not the viewer's fault, not logged.
                    let text = e.to_string();
                    if text.contains("Space limit exceeded") || text.contains("too long") {
                        let _ = v.reject(&format!(
                            "message over the hard limit of {HARD_MESSAGE_LIMIT} bytes, connection closed: {text}"
                        ));
                    }
                    ok = false;
                }
            },
            _ = stopped(&mut shutdown) => ok = false,
        }
    }
    state.viewers.fetch_sub(1, Ordering::Relaxed);
}
