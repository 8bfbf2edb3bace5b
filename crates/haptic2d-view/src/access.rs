//! Who may command the loop: the origin check of the WebSocket upgrade and the token.
//!
//! The display is a control surface for a device, and a browser will open a WebSocket to any
//! address for any page the user visits. The threat is a web page from elsewhere
//! (`http://evil.example`) open in the user's browser, talking to `ws://127.0.0.1:8080/ws`, or a
//! DNS-rebinding page whose own name resolves to this machine. The rules (docs/DISPLAY.md):
//!
//! 1. **Browsers.** A browser always sends `Origin` with a WebSocket upgrade, and a script cannot
//!    set or remove it (a forbidden header name of the Fetch standard). Commands are accepted only
//!    when `Origin`'s host and port equal the `Host` header the request was sent to — that is, the
//!    page is the one this server served. Any other origin (including `null`: sandboxed frames,
//!    `file://` pages) gets a **view-only** connection and a log line.
//! 2. **DNS rebinding.** A rebinding page *is* same-origin with its own name (`Origin:
//!    http://evil.example:8080`, `Host: evil.example:8080`). Without a token, same-origin is
//!    therefore trusted only when `Host` is an IP literal or `localhost`, names no other site can
//!    claim; with a token any name is fine (the page must have been opened with the token).
//! 3. **Browsers without an `Origin`.** A request that carries the fetch-metadata headers every
//!    current browser sends (`Sec-Fetch-Site`, `Sec-Fetch-Mode`, `Sec-Fetch-Dest`) but no
//!    `Origin` is treated like a foreign origin: view-only.
//! 4. **Non-browser clients** (no `Origin`, no fetch metadata: scripts, tests, `ws_viewers`) cannot
//!    be driven by a web page. They are treated like the page itself: they may command whenever the
//!    token is not required, and must present it where it is.
//! 5. **The token** (128 random bits, hex) is required off loopback and, with `--require-token`, on
//!    loopback too. It is compared in constant time ([`token_eq`]); a connection gets
//!    [`MAX_TOKEN_TRIES`] tries (the `?token=` of the URL counts as one) and the next one closes it.

use axum::http::header::{HeaderMap, HOST, ORIGIN};

/// Wrong tokens a connection may present; the next attempt closes the connection.
pub const MAX_TOKEN_TRIES: u32 = 3;

/// What kind of client opened a WebSocket, from its upgrade request's headers.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Client {
    /// A browser page served by this server (`Origin` = the `Host` it was sent to).
    SameOrigin {
        /// True when the host is an IP literal or `localhost` (no DNS rebinding possible).
        literal_host: bool,
    },
    /// A browser page from another origin (or `Origin: null`, or an unreadable `Origin`).
    Foreign {
        /// The `Origin` as sent (truncated for logs).
        origin: String,
    },
    /// A browser context (fetch-metadata headers) that sent no `Origin`.
    BrowserWithoutOrigin,
    /// No `Origin` and no fetch metadata: a program, not a page.
    NonBrowser,
}

/// Whether a connection may command the loop, decided at the upgrade.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Access {
    /// Commands are accepted now (no token needed, or the URL's token was right).
    Control,
    /// Commands are accepted once the right token is presented (`hello` or `?token=`).
    NeedsToken,
    /// View only, whatever the client sends; the reason is shown to the client and logged.
    ViewOnly(String),
}

/// Classifies the client of an upgrade request by its `Origin`, `Host` and fetch-metadata headers.
pub fn classify(headers: &HeaderMap) -> Client {
    let host = headers.get(HOST).and_then(|h| h.to_str().ok());
    match headers.get(ORIGIN) {
        Some(o) => {
            let origin = o.to_str().unwrap_or("<not ASCII>");
            match (origin_authority(origin), host) {
                (Some((scheme, oa)), Some(h)) if same_authority(scheme, oa, h) => {
                    Client::SameOrigin {
                        literal_host: is_literal_host(h),
                    }
                }
                _ => Client::Foreign {
                    origin: origin.chars().take(100).collect(),
                },
            }
        }
        None => {
            let browser = ["sec-fetch-site", "sec-fetch-mode", "sec-fetch-dest"]
                .iter()
                .any(|k| headers.contains_key(*k));
            if browser {
                Client::BrowserWithoutOrigin
            } else {
                Client::NonBrowser
            }
        }
    }
}

/// The access of `client` when commands need a token (`token_required`), given whether the URL's
/// `?token=` was right (`url_token_ok`).
pub fn decide(client: &Client, token_required: bool, url_token_ok: bool) -> Access {
    let by_token = || {
        if !token_required || url_token_ok {
            Access::Control
        } else {
            Access::NeedsToken
        }
    };
    match client {
        Client::Foreign { origin } => Access::ViewOnly(format!(
            "view only: commands are accepted only from the page this server serves, not from origin `{origin}`"
        )),
        Client::BrowserWithoutOrigin => Access::ViewOnly(
            "view only: a browser request without an Origin header cannot command the loop".into(),
        ),
        Client::SameOrigin {
            literal_host: false,
        } if !token_required => Access::ViewOnly(
            "view only: without a token, commands are accepted only from a page opened at an IP address or localhost (e.g. http://127.0.0.1:PORT/), not through a DNS name".into(),
        ),
        Client::SameOrigin { .. } | Client::NonBrowser => by_token(),
    }
}

/// Compares a presented token with the expected one in time that depends only on the expected
/// token's length (public: 32 hex digits), not on where they first differ.
///
/// Every byte of `expected` is compared (a missing byte of `given` compares as 0) and the
/// differences are OR-ed together; a length mismatch sets the result too. `black_box` keeps the
/// optimiser from turning the fold into an early-exit comparison.
pub fn token_eq(expected: &str, given: &str) -> bool {
    let (e, g) = (expected.as_bytes(), given.as_bytes());
    let mut diff = (e.len() ^ g.len()) as u64;
    for (i, &b) in e.iter().enumerate() {
        let c = g.get(i).copied().unwrap_or(0);
        diff |= std::hint::black_box(u64::from(b ^ c));
    }
    std::hint::black_box(diff) == 0
}

/// `(scheme, authority)` of a serialized origin `scheme://host[:port]`; `None` for `null` or
/// anything with a path, user info or an unknown scheme.
fn origin_authority(origin: &str) -> Option<(&str, &str)> {
    let (scheme, rest) = origin.split_once("://")?;
    let scheme_ok = scheme.eq_ignore_ascii_case("http") || scheme.eq_ignore_ascii_case("https");
    if !scheme_ok || rest.is_empty() || rest.contains(['/', '@', '?', '#']) {
        return None;
    }
    Some((scheme, rest))
}

/// Splits `host[:port]` (IPv6 in brackets) into the host and the port, defaulting the port to the
/// scheme's (80 for http, 443 for https).
fn split_host_port<'a>(authority: &'a str, scheme: &str) -> Option<(&'a str, u16)> {
    let default = if scheme.eq_ignore_ascii_case("https") {
        443
    } else {
        80
    };
    let (host, port) = if let Some(rest) = authority.strip_prefix('[') {
        let (h, after) = rest.split_once(']')?;
        match after.strip_prefix(':') {
            Some(p) => (h, Some(p)),
            None if after.is_empty() => (h, None),
            None => return None,
        }
    } else {
        match authority.rsplit_once(':') {
            Some((h, p)) => (h, Some(p)),
            None => (authority, None),
        }
    };
    let port = match port {
        Some(p) => p.parse().ok()?,
        None => default,
    };
    (!host.is_empty()).then_some((host, port))
}

/// True when `host_header` names the same host and port as the origin's authority `oa`.
///
/// The scheme is not compared (a TLS-terminating proxy serves the page over https and forwards
/// http); a missing port takes the origin scheme's default.
fn same_authority(scheme: &str, oa: &str, host_header: &str) -> bool {
    match (
        split_host_port(oa, scheme),
        split_host_port(host_header.trim(), scheme),
    ) {
        (Some((h1, p1)), Some((h2, p2))) => p1 == p2 && h1.eq_ignore_ascii_case(h2),
        _ => false,
    }
}

/// True when the `Host` header names an IP literal or `localhost` (or `*.localhost`, which
/// browsers resolve to loopback themselves): names a rebinding attacker cannot own.
fn is_literal_host(host_header: &str) -> bool {
    let Some((host, _)) = split_host_port(host_header.trim(), "http") else {
        return false;
    };
    let lower = host.to_ascii_lowercase();
    host.parse::<std::net::Ipv4Addr>().is_ok()
        || host.parse::<std::net::Ipv6Addr>().is_ok()
        || lower == "localhost"
        || lower.ends_with(".localhost")
}

/// True when the serialized origin `origin` (`http[s]://host[:port]`) is a page on this machine's
/// loopback: `127.0.0.0/8`, `[::1]`, `localhost` or `*.localhost` (which browsers resolve to
/// loopback themselves).
pub fn origin_is_loopback(origin: &str) -> bool {
    let Some((host, _)) = origin_authority(origin).and_then(|(s, a)| split_host_port(a, s)) else {
        return false;
    };
    let lower = host.to_ascii_lowercase();
    host.parse::<std::net::Ipv4Addr>()
        .is_ok_and(|a| a.is_loopback())
        || host
            .parse::<std::net::Ipv6Addr>()
            .is_ok_and(|a| a.is_loopback())
        || lower == "localhost"
        || lower.ends_with(".localhost")
}

/// The rule of a WebSocket server that serves no page of its own but is opened by the pages of
/// known sites (the Foxglove live server of `haptic2d run --foxglove`): a program (no `Origin`, no
/// fetch metadata) is allowed; a browser page is allowed only when its `Origin` is one of
/// `allowed` (exact, e.g. `https://app.foxglove.dev`; case-insensitive) or a loopback page
/// ([`origin_is_loopback`]); every other page, and a browser request without `Origin`, is refused
/// with the reason.
pub fn check_page_origin(headers: &HeaderMap, allowed: &[&str]) -> Result<(), String> {
    let origin = match classify(headers) {
        Client::NonBrowser => return Ok(()),
        Client::BrowserWithoutOrigin => {
            return Err("a browser request without an Origin header is refused".into())
        }
        Client::SameOrigin { .. } | Client::Foreign { .. } => headers
            .get(ORIGIN)
            .and_then(|o| o.to_str().ok())
            .unwrap_or("<not ASCII>"),
    };
    if allowed.iter().any(|a| a.eq_ignore_ascii_case(origin)) || origin_is_loopback(origin) {
        return Ok(());
    }
    Err(format!(
        "the page at origin `{}` is refused: only {} and pages on loopback may connect",
        origin.chars().take(100).collect::<String>(),
        allowed.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use axum::http::HeaderValue;

    fn headers(pairs: &[(&'static str, &'static str)]) -> HeaderMap {
        let mut h = HeaderMap::new();
        for (k, v) in pairs {
            h.insert(*k, HeaderValue::from_static(v));
        }
        h
    }

    #[test]
    fn same_origin_is_host_and_port_of_the_served_page() {
        let same = |o, h| classify(&headers(&[("origin", o), ("host", h)]));
        let lit = Client::SameOrigin { literal_host: true };
        assert_eq!(same("http://127.0.0.1:8080", "127.0.0.1:8080"), lit);
        assert_eq!(same("http://LOCALHOST:8080", "localhost:8080"), lit);
        assert_eq!(same("http://[::1]:8080", "[::1]:8080"), lit);
        assert_eq!(same("http://127.0.0.1", "127.0.0.1:80"), lit);
        assert_eq!(same("https://10.0.0.5", "10.0.0.5:443"), lit);
        assert_eq!(
            same("http://lab-pc.local:8080", "lab-pc.local:8080"),
            Client::SameOrigin {
                literal_host: false
            }
        );
        for (o, h) in [
            ("http://evil.example", "127.0.0.1:8080"),
            ("http://127.0.0.1:8081", "127.0.0.1:8080"),
            ("http://127.0.0.1", "127.0.0.1:8080"),
            ("null", "127.0.0.1:8080"),
            ("http://127.0.0.1:8080/page", "127.0.0.1:8080"),
            ("http://user@127.0.0.1:8080", "127.0.0.1:8080"),
            ("file://", "127.0.0.1:8080"),
            ("ws://127.0.0.1:8080", "127.0.0.1:8080"),
            ("http://127.0.0.1:8080", "127.0.0.1:xyz"),
        ] {
            assert!(
                matches!(same(o, h), Client::Foreign { .. }),
                "{o} vs {h}: {:?}",
                same(o, h)
            );
        }
        // No Host header: the origin cannot be matched.
        assert!(matches!(
            classify(&headers(&[("origin", "http://127.0.0.1:8080")])),
            Client::Foreign { .. }
        ));
    }

    #[test]
    fn missing_origin_is_a_program_unless_the_request_looks_like_a_browser() {
        assert_eq!(
            classify(&headers(&[("host", "127.0.0.1:8080")])),
            Client::NonBrowser
        );
        assert_eq!(
            classify(&headers(&[
                ("host", "127.0.0.1:8080"),
                ("sec-fetch-mode", "websocket")
            ])),
            Client::BrowserWithoutOrigin
        );
    }

    #[test]
    fn access_rules() {
        let foreign = Client::Foreign {
            origin: "http://evil.example".into(),
        };
        let lit = Client::SameOrigin { literal_host: true };
        let named = Client::SameOrigin {
            literal_host: false,
        };
        // A foreign page never commands, not even with the token.
        for (req, ok) in [(false, false), (true, true), (true, false)] {
            assert!(matches!(decide(&foreign, req, ok), Access::ViewOnly(_)));
            assert!(matches!(
                decide(&Client::BrowserWithoutOrigin, req, ok),
                Access::ViewOnly(_)
            ));
        }
        assert_eq!(decide(&lit, false, false), Access::Control);
        assert_eq!(decide(&lit, true, false), Access::NeedsToken);
        assert_eq!(decide(&lit, true, true), Access::Control);
        // DNS rebinding: a named host needs the token.
        assert!(matches!(decide(&named, false, false), Access::ViewOnly(_)));
        assert_eq!(decide(&named, true, true), Access::Control);
        assert_eq!(decide(&Client::NonBrowser, false, false), Access::Control);
        assert_eq!(decide(&Client::NonBrowser, true, false), Access::NeedsToken);
        assert_eq!(decide(&Client::NonBrowser, true, true), Access::Control);
        let Access::ViewOnly(why) = decide(&foreign, false, false) else {
            unreachable!()
        };
        assert!(why.contains("evil.example"), "{why}");
    }

    #[test]
    fn token_eq_accepts_only_the_exact_token() {
        let t = "0123456789abcdef0123456789abcdef";
        assert!(token_eq(t, t));
        for wrong in [
            "",
            "0",
            "0123456789abcdef0123456789abcde",    // a prefix
            "0123456789abcdef0123456789abcdeF",   // last byte differs
            "1123456789abcdef0123456789abcdef",   // first byte differs
            "0123456789abcdef0123456789abcdef0",  // longer
            "0123456789abcdef0123456789abcdef\0", // a NUL past the end
        ] {
            assert!(!token_eq(t, wrong), "{wrong:?}");
        }
        assert!(token_eq("", ""));
        assert!(!token_eq("", "x"));
    }

    #[test]
    fn page_origins_allowed_are_the_listed_sites_and_loopback_pages_only() {
        let app = ["https://app.foxglove.dev"];
        let check =
            |pairs: &[(&'static str, &'static str)]| check_page_origin(&headers(pairs), &app);
        assert!(check(&[("host", "127.0.0.1:8765")]).is_ok(), "a program");
        for ok in [
            "https://app.foxglove.dev",
            "HTTPS://APP.FOXGLOVE.DEV",
            "http://127.0.0.1:3000",
            "http://127.8.9.10",
            "http://[::1]:8080",
            "http://localhost:8080",
            "http://studio.localhost",
        ] {
            assert!(
                check(&[("origin", ok), ("host", "127.0.0.1:8765")]).is_ok(),
                "{ok}"
            );
        }
        for bad in [
            "https://evil.example",
            "https://app.foxglove.dev.evil.example",
            "http://app.foxglove.dev",
            "https://app.foxglove.dev/x",
            "http://192.168.1.5:8765",
            "http://localhost.evil.example",
            "null",
            "file://",
        ] {
            let e = check(&[("origin", bad), ("host", "127.0.0.1:8765")]).unwrap_err();
            assert!(e.contains("refused"), "{bad}: {e}");
        }
        // A page on this server's own (non-loopback) address is not a loopback page either.
        assert!(check(&[
            ("origin", "http://10.0.0.5:8765"),
            ("host", "10.0.0.5:8765")
        ])
        .is_err());
        assert!(check(&[("host", "127.0.0.1:8765"), ("sec-fetch-mode", "websocket")]).is_err());
    }
}
