//! Runs the loop with a stand-in tick and prints the timing summary.
//!
//! ```text
//! cargo run --release -p haptic2d-rt --example loop_timing -- [RATE_HZ] [SECONDS] [--rt] [--spin US]
//! ```
//!
//! The stand-in tick does a little floating-point work, checks the watchdog
//! and publishes a telemetry record that a logger thread writes to a sink, so
//! the numbers include the telemetry path. Ctrl-C stops it early.

use haptic2d_rt::signal::install_ctrlc_stop;
use haptic2d_rt::{
    run_loop, telemetry_channel, CsvLogger, CsvRecord, LoggerConfig, LoopConfig, SafetyInput,
    TickControl, Watchdog, WatchdogConfig,
};
use std::time::Duration;

#[derive(Clone, Copy, Default)]
struct Rec {
    t: f64,
    lateness_us: f64,
    x: f64,
}

impl CsvRecord for Rec {
    fn header() -> Vec<String> {
        vec!["t".into(), "lateness_us".into(), "x".into()]
    }
    fn write_row<W: std::io::Write>(&self, out: &mut csv::Writer<W>) -> csv::Result<()> {
        out.write_field(self.t.to_string())?;
        out.write_field(self.lateness_us.to_string())?;
        out.write_field(self.x.to_string())
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut positional = Vec::new();
    let mut rt = false;
    let mut spin_us = LoopConfig::default().spin_us;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--rt" => rt = true,
            "--spin" => {
                i += 1;
                spin_us = args.get(i).and_then(|s| s.parse().ok()).unwrap_or_else(|| {
                    eprintln!("--spin needs a number of microseconds");
                    std::process::exit(2)
                });
            }
            a => positional.push(a.to_string()),
        }
        i += 1;
    }
    let num = |k: usize, default: f64| -> f64 {
        positional.get(k).map_or(default, |s| {
            s.parse().unwrap_or_else(|_| {
                eprintln!("`{s}` is not a number");
                std::process::exit(2)
            })
        })
    };
    let rate_hz = num(0, 1000.0);
    let seconds = num(1, 2.0);
    if !(seconds.is_finite() && seconds >= 0.0) {
        eprintln!("SECONDS must be ≥ 0");
        std::process::exit(2);
    }
    let config = LoopConfig {
        rate_hz,
        duration: Some(Duration::from_secs_f64(seconds)),
        spin_us,
        rt,
        ..LoopConfig::default()
    };

    let stop = install_ctrlc_stop().unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    let capacity = (rate_hz * 2.0).max(1024.0) as usize;
    let (mut tx, rx, _snapshot) = telemetry_channel(capacity, Rec::default()).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    let logger = CsvLogger::spawn(rx, std::io::sink(), "sink", LoggerConfig::default())
        .unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(1)
        });
    let mut watchdog = Watchdog::new(WatchdogConfig {
        max_missed_run: None,
        ..WatchdogConfig::default()
    })
    .unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });

    let mut x = 0.0f64;
    let result = run_loop(&config, &stop, |info| {
        // Stand-in work: a short chain of dependent flops.
        for k in 0..200 {
            x = (x + info.t_s * 1e-3 + k as f64 * 1e-9).sin();
        }
        let mut tau = [x; 4];
        let safety = SafetyInput {
            deadline_missed: info.missed_deadline(),
            ..SafetyInput::nominal(info.index)
        };
        if watchdog.guard(&safety, &mut tau).is_err() {
            return TickControl::Stop;
        }
        tx.publish(Rec {
            t: info.t_s,
            lateness_us: info.lateness_ns as f64 * 1e-3,
            x: tau[0],
        });
        TickControl::Continue
    });
    drop(tx);
    let summary = match result {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2)
        }
    };
    if let Some(w) = summary.rt.as_ref().and_then(|r| r.warning()) {
        eprintln!("{w}");
    }
    println!("{summary}");
    match logger.finish() {
        Ok(report) => println!("{report}"),
        Err(e) => eprintln!("{e}"),
    }
    if let Some(f) = watchdog.fault() {
        println!("{f}");
    }
}
