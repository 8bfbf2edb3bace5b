//! Issue 10: the fuzz harness's CLI part — a handful of spawned `haptic2d` processes with hostile
//! arguments (numbers NaN, ±inf, 1e300, −0, huge counts; bad files such as /dev/zero), each with a
//! timeout: no panic, no abort (death by a signal), no hang, and an exit status from the documented
//! table. The arguments come from a fixed-seed generator, so every run spawns the same processes.

use std::time::Duration;

const NUMBERS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "1e300",
    "-1e300",
    "-0",
    "0",
    "1e-300",
    "-1",
    "1e9",
    "1e12",
    "18446744073709551616",
    "0.05",
    "1000",
];
const SCENES: &[&str] = &[
    "box-in-walls",
    "peg-in-hole",
    "pile:0",
    "pile:-1",
    "pile:100000000000",
    "pile:18446744073709551616",
    "pile:nan",
    "/dev/zero",
    "/dev/null",
    "/",
];
const DOCUMENTED: &[i32] = &[0, 1, 2, 3, 4, 5, 6, 130];

/// A tiny fixed-seed generator (SplitMix64).
struct Rng(u64);
impl Rng {
    fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        xs[((z ^ (z >> 31)) % xs.len() as u64) as usize]
    }
}

/// Runs `args` with a 60 s deadline; returns the exit code, panicking on a signal, a panic or a hang.
fn run(args: &[String]) -> i32 {
    let (code, out) = crate::common::ends_within(args, Duration::from_secs(60));
    assert!(!out.contains("panicked"), "{args:?} panicked:\n{out}");
    assert!(
        DOCUMENTED.contains(&code),
        "{args:?}: undocumented exit {code}:\n{out}"
    );
    if code != 0 {
        assert!(
            !out.trim().is_empty(),
            "{args:?}: exit {code} with no message"
        );
    }
    code
}

#[test]
fn hostile_cli_arguments_never_panic_abort_or_hang() {
    let _m = crate::common::module_turn(module_path!());
    let mut rng = Rng(0x4841_5054_4943_3244);
    let mut cases: Vec<Vec<String>> = Vec::new();
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    // Fixed cases from the issue.
    cases.push(s(&["check", "/dev/zero"]));
    let words = |line: &str| {
        line.split_whitespace()
            .map(String::from)
            .collect::<Vec<_>>()
    };
    cases.push(words("run --headless --no-rt --rate 1e9 --duration 0.1"));
    cases.push(words("run --headless --no-rt --duration 1e300"));
    cases.push(words(
        "run --headless --no-rt --duration 0.1 --device-file /dev/zero",
    ));
    cases.push(s(&["simulate", "box-in-walls", "--duration", "1e300"]));
    cases.push(s(&["check", "pile:100000000000"]));
    // Generated cases: short `simulate`s and `check`s (a `run` costs real time, so only a few).
    for k in 0..14 {
        let scene = rng.pick(SCENES);
        let case = match k % 7 {
            0 => s(&["check", scene]),
            1..=4 => s(&[
                "simulate",
                rng.pick(&["box-in-walls", "peg-in-hole", "pile:10"]),
                "--duration",
                rng.pick(&["nan", "inf", "-1", "0", "1e-300", "1e300", "0.05", "1e9"]),
                "--rate",
                rng.pick(NUMBERS),
                "--every",
                rng.pick(&["0", "1", "18446744073709551615", "-1", "nan"]),
            ]),
            5 => s(&["simulate", scene, "--duration", "0.05"]),
            _ => s(&[
                "run",
                "--headless",
                "--no-rt",
                "--duration",
                rng.pick(&["nan", "inf", "-1", "0", "1e300", "0.05"]),
                "--rate",
                rng.pick(&["nan", "inf", "-1", "0", "1e300", "1e9", "500", "1000"]),
                "--spin-us",
                rng.pick(&["nan", "-1", "1e300", "10"]),
            ]),
        };
        cases.push(case);
    }
    let mut by_code = std::collections::BTreeMap::<i32, usize>::new();
    for c in &cases {
        *by_code.entry(run(c)).or_default() += 1;
    }
    println!(
        "cli fuzz: {} processes, exit codes {by_code:?}",
        cases.len()
    );
    assert!(
        by_code.get(&2).copied().unwrap_or(0) >= 6,
        "the fixed hostile cases are rejected"
    );
}
