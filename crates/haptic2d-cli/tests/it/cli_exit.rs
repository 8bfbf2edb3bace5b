//! Issue 10, items 4–6: every option and scene number bounded with a clear message, and the
//! documented exit codes (`haptic2d --help`, docs/SCENES.md): 0 clean, 1 runtime failure, 2 bad
//! input, 3 safety stop, 4 lost device (unit-tested in `cmd_run`), 5 energy excess under `--strict`,
//! 6 divergence, 130 interrupted (tests/it/cli_signals.rs).

use crate::common::{haptic2d, run, text};
use std::process::Output;

fn code(o: &Output) -> i32 {
    o.status
        .code()
        .unwrap_or_else(|| panic!("killed by a signal: {}", text(o)))
}

/// Asserts exit status `want`, no panic, and that the output contains `needle`.
fn assert_exit(args: &[&str], want: i32, needle: &str) -> String {
    let o = haptic2d(args);
    let out = text(&o);
    assert_eq!(code(&o), want, "{args:?}:\n{out}");
    assert!(!out.contains("panicked"), "{args:?}:\n{out}");
    assert!(
        out.contains(needle),
        "{args:?}: missing `{needle}` in:\n{out}"
    );
    out
}

fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> String {
    let p = dir.path().join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

const BOX_IN_WALLS: &str = include_str!("../../../../scenes/box-in-walls.toml");

#[test]
fn help_lists_the_exit_codes() {
    let _m = crate::common::module_turn(module_path!());
    let out = assert_exit(&["--help"], 0, "Exit codes:");
    for c in ["0 ", "1 ", "2 ", "3 ", "4 ", "5 ", "6 ", "130 "] {
        assert!(
            out.contains(&format!("\n  {c}")),
            "code {c} missing:\n{out}"
        );
    }
}

#[test]
fn a_clean_simulate_exits_0() {
    let _m = crate::common::module_turn(module_path!());
    assert_exit(
        &["simulate", "box-in-walls", "--duration", "0.5"],
        0,
        "samples",
    );
}

#[test]
fn bad_scene_exits_2_naming_the_field() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let r1 = write(
        &dir,
        "r1.toml",
        &BOX_IN_WALLS.replace("angle_deg = 0.0", "angle_deg = 0.0\nvelocity = [nan, 0.0]"),
    );
    assert_exit(&["check", &r1], 2, "\"box\".velocity[0]: is NaN");
    assert_exit(&["simulate", &r1], 2, "velocity[0]");
}

#[test]
fn check_dev_zero_is_a_bounded_read_and_a_clear_error() {
    let _m = crate::common::module_turn(module_path!());
    assert_exit(&["check", "/dev/zero"], 2, "larger than the documented cap");
}

#[test]
fn run_rate_above_cap_is_rejected_before_allocating_the_ring() {
    let _m = crate::common::module_turn(module_path!());
    // Today's `--rate 1e9` sized a 624 GB telemetry ring.
    let _turn = crate::common::turn(); // one real-time loop at a time
    assert_exit(
        &"run --headless --no-rt --rate 1e9 --duration 1"
            .split(' ')
            .collect::<Vec<_>>(),
        2,
        "--rate must be a positive number of Hz up to 1e5",
    );
}

#[test]
fn run_duration_1e300_is_a_clear_error_not_a_panic() {
    let _turn = crate::common::loop_turn(module_path!()); // one real-time loop at a time
    assert_exit(
        &["run", "--headless", "--no-rt", "--duration", "1e300"],
        2,
        "--duration must be a positive number of seconds up to 1e7",
    );
}

#[test]
fn simulate_duration_1e300_is_a_clear_error() {
    let _m = crate::common::module_turn(module_path!());
    assert_exit(
        &["simulate", "box-in-walls", "--duration", "1e300"],
        2,
        "above the documented cap",
    );
    assert_exit(
        &[
            "simulate",
            "box-in-walls",
            "--rate",
            "1e12",
            "--duration",
            "1",
        ],
        2,
        "--rate must be a positive number of Hz up to 1e5",
    );
}

#[test]
fn pile_count_above_cap_exits_2() {
    let _m = crate::common::module_turn(module_path!());
    assert_exit(
        &["check", "pile:100000000000"],
        2,
        "above the documented cap",
    );
}

#[test]
fn overlapping_bodies_are_an_error_in_check_unless_accepted() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    // The box's face 5 mm inside the left wall (face at x = 0; half width 0.02 m).
    let text = BOX_IN_WALLS.replace("position = [0.04, 0.0]", "position = [0.015, 0.0]");
    let p = write(&dir, "overlap.toml", &text);
    let out = assert_exit(
        &["check", &p],
        2,
        "bodies \"walls\" and \"box\" overlap by 5.000 mm",
    );
    assert!(out.contains("allow_initial_overlap"), "{out}");
    assert_exit(
        &["check", &p, "--allow-overlap"],
        0,
        "warning: bodies \"walls\" and \"box\" overlap by 5.000 mm",
    );
    let keyed = write(
        &dir,
        "overlap-ok.toml",
        &text.replace("[world]", "[world]\nallow_initial_overlap = true"),
    );
    assert_exit(&["simulate", &keyed, "--duration", "0.1"], 0, "samples");
    assert_exit(
        &["simulate", &p, "--duration", "0.1"],
        2,
        "overlap by 5.000 mm",
    );
}

#[test]
fn energy_excess_is_a_warning_and_exit_5_with_strict() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    // The pure-stiffness ZOH wall under exact-ZOH integration gains energy at every bounce (§5.10).
    let zoh = BOX_IN_WALLS
        .replace(
            "integration = \"semi-implicit\"",
            "integration = \"exact-zoh\"",
        )
        .replace("impacts = true", "impacts = false");
    let zoh = zoh
        .lines()
        .map(|l| {
            if l.starts_with("model = \"paper\"") {
                "model = \"zoh\"".to_string()
            } else if l.starts_with("kc = ") {
                "k = 1000.0".to_string()
            } else if l.starts_with("bc = ") {
                String::new()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let p = write(&dir, "zoh.toml", &zoh);
    let out = assert_exit(
        &["simulate", &p, "--duration", "5"],
        0,
        "warning: the world generated energy",
    );
    assert!(out.contains("--strict"), "{out}");
    assert_exit(
        &["simulate", &p, "--duration", "5", "--strict"],
        5,
        "generated energy",
    );
    // A passive scene passes --strict.
    assert_exit(
        &["simulate", "box-in-walls", "--duration", "2", "--strict"],
        0,
        "samples",
    );
}

#[test]
fn divergence_is_detected_before_the_row_is_written_and_exits_6() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    // 1e6 m/s² on a free body: the speed passes the divergence bound (1e6 m/s) after 1 s.
    let scene = r#"
[world]
rate = 1000
[[body]]
name = "rocket"
mass = 1.0
box = [0.04, 0.04]
[[load]]
body = "rocket"
force = [1.0e6, 0.0]
per_mass = true
"#;
    let p = write(&dir, "rocket.toml", scene);
    let csv = dir.path().join("rocket.csv");
    let out = assert_exit(
        &[
            "simulate",
            &p,
            "--duration",
            "3",
            "--out",
            csv.to_str().unwrap(),
        ],
        6,
        "the simulation diverged at t = 1.0010 s",
    );
    assert!(out.contains("\"rocket\": vx = "), "{out}");
    let rows = std::fs::read_to_string(&csv).unwrap();
    assert!(rows.ends_with('\n'), "whole rows only");
    let last = rows.lines().last().unwrap();
    let vx: f64 = last.split(',').nth(8).unwrap().parse().unwrap();
    assert!(
        vx.abs() <= 1e6,
        "no row beyond the bound was written: {last}"
    );
    // One row per sample up to the one before divergence, plus the header and t = 0.
    assert_eq!(
        rows.lines().count(),
        1 + 1 + 1000,
        "{}",
        rows.lines().count()
    );
}

#[test]
fn a_safety_stop_in_run_exits_3() {
    let _turn = crate::common::loop_turn(module_path!()); // one real-time loop at a time
    let dir = tempfile::tempdir().unwrap();
    // Encoder angles of zero are no pose of the device: the closure monitor trips on tick 0.
    let replay = write(&dir, "zero.csv", "q1,q2,q3,q4\n0,0,0,0\n0,0,0,0\n");
    assert_exit(
        &[
            "run",
            "--headless",
            "--no-rt",
            "--device",
            &format!("replay:{replay}"),
            "--duration",
            "1",
        ],
        3,
        "safety stop at tick 0",
    );
}

#[test]
fn clap_usage_errors_exit_2() {
    let _m = crate::common::module_turn(module_path!());
    assert_exit(&["simulate", "box-in-walls", "--bogus"], 2, "--bogus");
}

/// The regression logs of issue 38 (kept with the reader's tests in haptic2d-rt).
/// The two hostile logs of `../shared/repro/`, rebuilt from their descriptions out of a log this
/// binary records (`run --log`, 1.5 s) instead of tracked as recordings: `len-max.mcap`, the log
/// with its Header record (byte 8) declaring a length of 2⁶⁴ − 1; and
/// `replay-nan-safety-exit0.mcap`, the log with its Header's opcode flipped to an unknown one
/// (0xb6, skipped by a reader) and cut halfway into its second Chunk record. Returns their paths.
fn hostile_logs(dir: &tempfile::TempDir) -> (String, String) {
    let rec = dir.path().join("rec.mcap");
    let o = run("run --headless --no-rt --duration 1.5 --log {}", &[&rec]);
    // Any whole log will do: a run a loaded machine stalls (a safety stop, exit 3) still leaves
    // one, ending on a whole tick.
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let log = std::fs::read(&rec).unwrap();
    assert_eq!(log[8], 0x01, "a log starts with its Header record");
    // Top-level records after the magic (MCAP spec: opcode u8, length u64 LE, body).
    let mut chunks = Vec::new();
    let mut pos = 8;
    while pos + 9 <= log.len() {
        let len = u64::from_le_bytes(log[pos + 1..pos + 9].try_into().unwrap()) as usize;
        if log[pos] == 0x06 {
            chunks.push((pos, len));
        }
        pos += 9 + len;
    }
    assert!(chunks.len() >= 2, "one chunk only in a 1.5 s run log");
    let mut len_max = log.clone();
    len_max[9..17].copy_from_slice(&u64::MAX.to_le_bytes());
    let (at, len) = chunks[1];
    let mut cut = log[..at + 9 + len / 2].to_vec();
    cut[8] = 0xb6;
    let path = |name: &str, bytes: &[u8]| {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        p.to_str().unwrap().to_string()
    };
    (path("cut.mcap", &cut), path("len-max.mcap", &len_max))
}

/// Issue 38 item 3 and issue 39 items 5 and 7: every command into every ending, with its code and
/// the message that says why. (Exit 4 is unit-tested in `cmd_run`; 141 is in tests/it/cli_pipe.rs;
/// 130 in tests/it/cli_signals.rs and tests/it/mcap_log.rs.)
#[test]
fn every_command_ends_with_its_documented_exit_code_and_message() {
    let _turn = crate::common::loop_turn(module_path!()); // one real-time loop at a time
    let dir = tempfile::tempdir().unwrap();
    let zero_replay = write(&dir, "zero.csv", "q1,q2,q3,q4\n0,0,0,0\n0,0,0,0\n");
    let out_file = write(&dir, "a-file", "not a folder");
    let (cut, len_max) = hostile_logs(&dir);
    let csv_out = dir.path().join("out.csv");
    let csv_out = csv_out.to_str().unwrap();
    let replay_cut = format!("replay:{cut}");
    let replay_len_max = format!("replay:{len_max}");
    let replay_zero = format!("replay:{zero_replay}");
    let run = |extra: &[&'static str]| -> Vec<String> {
        let mut v: Vec<String> = ["run", "--headless", "--no-rt"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let own = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<String>>();
    #[allow(unused_mut)]
    let mut table: Vec<(Vec<String>, i32, &str)> = vec![
        // 0: ran to the end.
        (
            own(&["simulate", "box-in-walls", "--duration", "0.2"]),
            0,
            "samples",
        ),
        (run(&["--duration", "0.2"]), 0, "on time"),
        (own(&["log", "info", &cut]), 0, "NOT finished"),
        // A replay that reaches its end: "the replay ended", and no safety stop (issue 39 item 5).
        (
            own(&["run", "--headless", "--no-rt", "--device", &replay_cut]),
            0,
            "stopped: the replay ended",
        ),
        // 1: a runtime failure.
        (
            own(&[
                "simulate",
                "box-in-walls",
                "--duration",
                "0.1",
                "--out",
                "/nonexistent-dir/x.csv",
            ]),
            1,
            "cannot write",
        ),
        // 2: bad input, nothing ran.
        (own(&["reproduce", "fig6"]), 2, "unknown figure `fig6`"),
        (
            own(&["reproduce", "fig4", "--out", &out_file]),
            2,
            "is not a folder",
        ),
        (
            own(&["stability", "--rate", "-5"]),
            2,
            "--rate must be a positive number",
        ),
        (
            own(&["stability", "--delay", "7"]),
            2,
            "--delay must be 0 or 1",
        ),
        (
            own(&["stability", "--controller", "nope"]),
            2,
            "--controller",
        ),
        (own(&["sweep", "ripples"]), 2, "unknown sweep `ripples`"),
        (own(&["sweep", "walls", "--points", "1"]), 2, "points"),
        (
            own(&["sweep", "walls", "--out", &out_file]),
            2,
            "is not a folder",
        ),
        (
            run(&["--hand", "constant:1e300,0,0"]),
            2,
            "beyond the simulated hand's bound",
        ),
        (
            run(&["--foxglove", "0.0.0.0:0", "--duration", "0.1"]),
            2,
            "--foxglove-allow-remote",
        ),
        (
            own(&["log", "info", &len_max]),
            2,
            "declares a length of 18446744073709551615 bytes",
        ),
        (
            own(&["log", "convert", &len_max, csv_out]),
            2,
            "declares a length of 18446744073709551615 bytes",
        ),
        (
            own(&["run", "--headless", "--no-rt", "--device", &replay_len_max]),
            2,
            "declares a length of 18446744073709551615 bytes",
        ),
        (own(&["log", "info", "/dev/zero.mcap"]), 2, "cannot read"),
        // 3: a safety stop (a replay whose recorded angles are no pose of the device).
        (
            own(&[
                "run",
                "--headless",
                "--no-rt",
                "--device",
                &replay_zero,
                "--duration",
                "1",
            ]),
            3,
            "safety stop at tick 0",
        ),
    ];
    #[cfg(not(feature = "inverse3"))]
    {
        table.push((run(&["--device", "inverse3"]), 2, "--features inverse3"));
        table.push((own(&["emulate", "inverse3"]), 2, "--features inverse3"));
    }
    let mut failures = Vec::new();
    for (args, want, needle) in &table {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = haptic2d(&a);
        let out = text(&o);
        let got = o.status.code();
        let mut bad = got != Some(*want) || !out.contains(needle) || out.contains("panicked");
        // A replay that ended is not a safety stop.
        if args.iter().any(|s| s == &replay_cut) {
            bad |= out.contains("safety stop");
        }
        if bad {
            failures.push(format!(
                "{a:?}: exit {got:?} (want {want}), missing `{needle}`?\n{out}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n---\n"));
}

#[test]
fn dev_zero_as_a_log_is_refused_at_once() {
    let _turn = crate::common::loop_turn(module_path!()); // one real-time loop at a time
    let t0 = std::time::Instant::now();
    // As a CSV log (no .mcap extension): its first byte is a NUL.
    assert_exit(&["log", "info", "/dev/zero"], 2, "NUL byte");
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("zero.mcap");
    std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
    // As an MCAP log: its first 8 bytes are not the magic.
    assert_exit(
        &["log", "info", link.to_str().unwrap()],
        2,
        "not an MCAP file",
    );
    assert_exit(
        &[
            "run",
            "--headless",
            "--no-rt",
            "--device",
            &format!("replay:{}", link.display()),
        ],
        2,
        "not an MCAP file",
    );
    assert!(
        t0.elapsed() < std::time::Duration::from_secs(20),
        "{:?}",
        t0.elapsed()
    );
}
