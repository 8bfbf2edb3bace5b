//! The HTTP/1.1 accept loop, with a header-read timeout.
//!
//! `axum::serve` gives hyper no timer, so hyper's `header_read_timeout` never fires and a client
//! that sends its request line and then one header byte a minute (slowloris) holds its connection
//! open forever. This loop serves each connection with hyper's HTTP/1 builder given a tokio timer:
//! a request (the first, or the next on a kept-alive connection) whose headers are not complete
//! within the timeout closes the connection. An upgraded WebSocket is no longer HTTP and is not
//! affected; it ends with the page, or at shutdown.

use axum::extract::ConnectInfo;
use axum::{Extension, Router};
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use std::time::Duration;
use tokio::sync::watch;

/// Default time a client has to send a request's headers (s).
pub const DEFAULT_HEADER_READ_TIMEOUT: Duration = Duration::from_secs(10);

/// Accepts connections on `listener` and serves `app` on each, until `shutdown` turns true; then
/// stops accepting and asks every open connection to finish its request and close.
pub(crate) async fn serve(
    listener: tokio::net::TcpListener,
    app: Router,
    header_read_timeout: Duration,
    mut shutdown: watch::Receiver<bool>,
) {
    loop {
        let accepted = tokio::select! {
            r = listener.accept() => r,
            _ = crate::server::stopped(&mut shutdown) => return,
        };
        let (stream, peer) = match accepted {
            Ok(a) => a,
            Err(e) => {
                // Out of file descriptors and the like: say so, back off, keep serving.
                eprintln!("haptic2d-view: cannot accept a connection: {e}");
                tokio::time::sleep(Duration::from_millis(50)).await;
                continue;
            }
        };
        let _ = stream.set_nodelay(true);
        // The handlers read the peer's address through `ConnectInfo`, as with axum::serve.
        let service = TowerToHyperService::new(app.clone().layer(Extension(ConnectInfo(peer))));
        let mut stop = shutdown.clone();
        tokio::spawn(async move {
            let mut builder = hyper::server::conn::http1::Builder::new();
            builder
                .timer(TokioTimer::new())
                .header_read_timeout(header_read_timeout);
            let conn = builder
                .serve_connection(TokioIo::new(stream), service)
                .with_upgrades();
            tokio::pin!(conn);
            tokio::select! {
                _ = conn.as_mut() => {}
                _ = crate::server::stopped(&mut stop) => {
                    conn.as_mut().graceful_shutdown();
                    let _ = conn.await;
                }
            }
        });
    }
}
