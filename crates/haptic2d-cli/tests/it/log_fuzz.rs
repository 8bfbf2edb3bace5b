//! Issue 38, item 2, end to end: mutated logs through the real `haptic2d log info`, `log convert`
//! and `run --device replay:` — every one ends with exit 0, 2 (a clear `error:` line) or 3 (the
//! replayed angles tripped the safety latch), never a panic (101), an abort (134) or a hang. The
//! bulk of the fuzzing runs in-process in haptic2d-rt's tests/it/log_fuzz.rs (1 200 MCAP and 1 200
//! CSV cases); this runs a few dozen through the binary, which adds the commands' own code.

use crate::common::{run, run_ok};
use std::time::Duration;

/// xorshift64*: seeded, the same cases on every run.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) % n.max(1) as u64) as usize
    }
}

/// Offsets of the top-level records' length fields.
fn record_lengths(b: &[u8]) -> Vec<usize> {
    let mut out = Vec::new();
    let mut pos = 8;
    while pos + 9 <= b.len() {
        out.push(pos + 1);
        let len = u64::from_le_bytes(b[pos + 1..pos + 9].try_into().unwrap()) as usize;
        pos += 9 + len;
    }
    out
}

fn mutate(seed: &[u8], rng: &mut Rng, lens: &[usize]) -> Vec<u8> {
    let mut b = seed.to_vec();
    match rng.below(3) {
        0 => {
            for _ in 0..1 + rng.below(16) {
                let i = rng.below(b.len());
                b[i] ^= 1 << rng.below(8);
            }
        }
        1 => b.truncate(rng.below(b.len())),
        _ => {
            let at = lens[rng.below(lens.len())];
            let v = [u64::MAX, u64::from(u32::MAX), 1 << 33][rng.below(3)];
            b[at..at + 8].copy_from_slice(&v.to_le_bytes());
        }
    }
    b
}

/// Runs `args` with a 30 s limit and asserts it ended as documented: exit 0, 2 (with an `error:`
/// line) or 3, no panic, no signal, no hang. Its exit code.
#[track_caller]
fn ends_as_documented(args: &[&str]) -> i32 {
    let (code, out) = crate::common::ends_within(args, Duration::from_secs(30));
    assert!(!out.contains("panicked"), "{args:?}:\n{out}");
    assert!([0, 2, 3].contains(&code), "{args:?}: exit {code}\n{out}");
    if code == 2 {
        assert!(out.contains("error: "), "{args:?}: no error line\n{out}");
    }
    code
}

/// `run --headless --no-rt --device REPLAY --duration 1`.
fn replay_run(replay: &str) -> Vec<&str> {
    vec![
        "run",
        "--headless",
        "--no-rt",
        "--device",
        replay,
        "--duration",
        "1",
    ]
}

#[test]
fn mutated_logs_through_log_info_log_convert_and_replay_end_with_a_documented_code() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let seed_path = dir.path().join("seed.mcap");
    run_ok(
        "run --headless --no-rt --duration 0.05 --log {}",
        &[&seed_path],
    );
    let seed = std::fs::read(&seed_path).unwrap();
    let lens = record_lengths(&seed);
    let mut rng = Rng(0x10F_F022);
    let mut codes = std::collections::BTreeMap::new();
    for i in 0..12 {
        let m = dir.path().join(format!("m{i}.mcap"));
        std::fs::write(&m, mutate(&seed, &mut rng, &lens)).unwrap();
        let m = m.to_str().unwrap();
        let out_csv = dir.path().join(format!("m{i}.csv"));
        let replay = format!("replay:{m}");
        for args in [
            vec!["log", "info", m],
            vec!["log", "convert", m, out_csv.to_str().unwrap()],
            replay_run(&replay),
        ] {
            let code = ends_as_documented(&args);
            let cmd = if args[0] == "run" {
                "run replay:"
            } else {
                args[1]
            };
            *codes.entry(format!("{cmd} → {code}")).or_insert(0) += 1;
        }
    }
    eprintln!("{codes:?}");
    // The CSV tick log of the same kind, mutated, through `log info` and `replay:`.
    let csv = dir.path().join("seed.csv");
    assert!(run("log convert {} {}", &[&seed_path, &csv])
        .status
        .success());
    let text_seed = std::fs::read(&csv).unwrap();
    for i in 0..8 {
        let mut b = text_seed.clone();
        let j = rng.below(b.len());
        match i % 4 {
            0 => b[j] ^= 1 << rng.below(8),
            1 => b.truncate(j),
            2 => b.insert(j, 0),
            _ => b.splice(j..j, vec![b'7'; (1 << 20) + 1]).for_each(drop),
        }
        let p = dir.path().join(format!("c{i}.csv"));
        std::fs::write(&p, b).unwrap();
        let replay = format!("replay:{}", p.display());
        for args in [
            vec!["log", "info", p.to_str().unwrap()],
            replay_run(&replay),
        ] {
            ends_as_documented(&args);
        }
    }
}
