//! `transport-bench`: the world link's message over our UDP link and over zenoh, on loopback at
//! 1 kHz, ping and echo in two processes (docs/PERFORMANCE.md "The world link: our UDP against
//! zenoh on loopback"; issue 41 item 1).
//!
//! ```text
//! transport-bench [--n N] [TRANSPORT ...]     TRANSPORT: udp zenoh-tcp zenoh-udp zenoh-tcp-lowlatency
//!                                             (default: all, N = 10000 messages = 10 s each)
//! transport-bench echo TRANSPORT ENDPOINT N   the echo role, started by the first form
//! ```
//!
//! This crate is outside the workspace (the root Cargo.toml's `exclude`): CI and
//! `cargo test --workspace` never build it, so zenoh's ~260 crates are not a cost of the project.

mod echo;
mod message;
mod ping;
mod report;
mod slots;
mod summary;
mod transport;
mod udp;
mod zenoh_link;

use transport::Transport;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let Err(e) = run(&args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run(args: &[String]) -> Result<(), String> {
    if args.first().map(String::as_str) == Some("echo") {
        let [_, t, endpoint, n] = args else {
            return Err("usage: transport-bench echo TRANSPORT ENDPOINT N".into());
        };
        let n = n.parse().map_err(|e| format!("N = {n:?}: {e}"))?;
        return transport::echo(Transport::parse(t)?, endpoint, n);
    }
    let mut n: u32 = 10_000;
    let mut chosen = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--n" {
            let v = it.next().ok_or("--n needs a number of messages")?;
            n = v.parse().map_err(|e| format!("--n {v:?}: {e}"))?;
        } else {
            chosen.push(Transport::parse(a)?);
        }
    }
    if chosen.is_empty() {
        chosen = transport::ALL.to_vec();
    }
    println!("{}", report::machine());
    for t in chosen {
        println!("{}", transport::measure(t, n)?);
        println!("load average after {}: {}\n", t.name(), report::load());
    }
    Ok(())
}
