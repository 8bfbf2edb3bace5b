//! Issue 38, item 2: the log readers of `haptic2d log info`, `log convert` and
//! `run --device replay:` are bounded and never panic. Seeded mutations of a small valid MCAP log
//! (bit flips, truncations, record and string lengths set to huge values) and of a small CSV tick
//! log (bit flips, truncations, NUL bytes, endless lines) go through the same reader functions
//! those commands call, in-process: every case must end in `Ok` or a clear `Err` — no panic, no
//! case slower than a second, and no single allocation larger than a small multiple of the file
//! (a counting global allocator measures it: the `mcap` crate reserved 4 GiB for a 113 KB file).
//! The regression files of the issue (../shared/repro/len-max.mcap, replay-nan-safety-exit0.mcap)
//! are rebuilt here from their descriptions (`len_max_log`, `cut_log`), not tracked as recordings.

use haptic2d_rt::io::{ReplayDevice, ReplayEnd, DEFAULT_REPLAY_COLUMNS};
use haptic2d_rt::mcap::columns::{tick_row, TICK_TABLE};
use haptic2d_rt::mcap::reader::{encoders_of, read_info, read_ticks};
use haptic2d_rt::mcap::tick_csv::read_tick_csv_from;
use haptic2d_rt::mcap::world_csv::read_world_tables;
use haptic2d_rt::mcap::{McapSetup, McapSink, WorldSample};
use std::collections::BTreeMap;
use std::panic::AssertUnwindSafe;
use std::time::{Duration, Instant};

// The counting allocator records the largest single request of each thread (haptic2d-test-support).
use haptic2d_test_support::alloc::{largest, reset_largest};

/// Largest single allocation the readers may make for a file of `len` bytes: the parsed rows are
/// a few times the text (a tick row is 16 bytes a column, ~1 KB, for a ~1 KB JSON message; vectors
/// double), never a length field's word.
fn allowed(len: usize) -> usize {
    16 * len + (1 << 20)
}

/// xorshift64*: a seeded, dependency-free generator (the cases are the same on every run).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// A small valid MCAP log: 40 ticks of box-in-walls with the world channels, chunked like a run's.
fn seed_mcap() -> Vec<u8> {
    log_of(40)
}

/// Byte offsets of every record's 8-byte length field (top level and inside chunks), and of every
/// 4-byte field that follows a record's fixed header (string and byte-array lengths).
fn length_fields(b: &[u8]) -> (Vec<usize>, Vec<usize>) {
    let (mut lens, mut strs) = (Vec::new(), Vec::new());
    fn walk(b: &[u8], mut pos: usize, end: usize, lens: &mut Vec<usize>, strs: &mut Vec<usize>) {
        while pos + 9 <= end {
            let op = b[pos];
            let len = u64::from_le_bytes(b[pos + 1..pos + 9].try_into().unwrap()) as usize;
            let body = pos + 9;
            if body + len > end {
                return;
            }
            lens.push(pos + 1);
            // Schema/Channel/Metadata/Header: a length right after the id fields.
            match op {
                0x01 | 0x0C => strs.push(body),
                0x03 => strs.push(body + 2),
                0x04 => strs.push(body + 4),
                0x06 => {
                    strs.push(body + 28);
                    let clen = u32::from_le_bytes(b[body + 28..body + 32].try_into().unwrap());
                    let recs = body + 32 + clen as usize + 8;
                    lens.push(body + 32 + clen as usize); // records length (u64)
                    walk(b, recs, body + len, lens, strs);
                }
                _ => {}
            }
            pos = body + len;
        }
    }
    walk(b, 8, b.len(), &mut lens, &mut strs);
    (lens, strs)
}

/// One mutant of `seed`: the kind of mutation and the bytes.
fn mutate(seed: &[u8], rng: &mut Rng, lens: &[usize], strs: &[usize]) -> (&'static str, Vec<u8>) {
    let mut b = seed.to_vec();
    match rng.below(6) {
        0 => {
            for _ in 0..1 + rng.below(8) {
                let i = rng.below(b.len());
                b[i] ^= 1 << rng.below(8);
            }
            ("bit flips", b)
        }
        1 => {
            b.truncate(rng.below(b.len()));
            ("truncation", b)
        }
        2 | 3 => {
            let at = lens[rng.below(lens.len())];
            let v: u64 = match rng.below(5) {
                0 => u64::MAX,
                1 => u64::from(u32::MAX),
                2 => 1 << 40,
                3 => rng.next(),
                _ => {
                    u64::from_le_bytes(b[at..at + 8].try_into().unwrap()) + 1 + rng.below(64) as u64
                }
            };
            b[at..at + 8].copy_from_slice(&v.to_le_bytes());
            ("record length", b)
        }
        4 => {
            let at = strs[rng.below(strs.len())];
            let v: u32 = [u32::MAX, u32::MAX / 2, 1 << 24, rng.next() as u32][rng.below(4)];
            b[at..at + 4].copy_from_slice(&v.to_le_bytes());
            ("string length", b)
        }
        _ => {
            // Random bytes over a random span (a record body overwritten).
            let i = rng.below(b.len());
            let n = (1 + rng.below(64)).min(b.len() - i);
            for k in 0..n {
                b[i + k] = rng.next() as u8;
            }
            ("random span", b)
        }
    }
}

/// Runs `f` on one case: panics caught and counted, time and the largest allocation checked.
struct Tally {
    cases: usize,
    ok: usize,
    errors: usize,
    panics: Vec<String>,
    slow: Vec<String>,
    big: Vec<String>,
}

impl Tally {
    fn new() -> Self {
        Self {
            cases: 0,
            ok: 0,
            errors: 0,
            panics: Vec::new(),
            slow: Vec::new(),
            big: Vec::new(),
        }
    }

    fn case(&mut self, what: &str, len: usize, f: impl FnOnce() -> Result<(), String>) {
        self.cases += 1;
        reset_largest();
        let t = Instant::now();
        let r = std::panic::catch_unwind(AssertUnwindSafe(f));
        let dt = t.elapsed();
        let largest = largest();
        match r {
            Ok(Ok(())) => self.ok += 1,
            Ok(Err(e)) => {
                self.errors += 1;
                assert!(!e.trim().is_empty(), "{what}: an empty error message");
            }
            Err(_) => self.panics.push(what.to_string()),
        }
        if dt > Duration::from_secs(1) {
            self.slow.push(format!("{what}: {dt:?}"));
        }
        if largest > allowed(len) {
            self.big
                .push(format!("{what}: {largest} bytes for a {len}-byte file"));
        }
    }

    fn assert_clean(&self, name: &str) {
        eprintln!(
            "{name}: {} cases, {} read, {} refused with an error, {} panics, {} slow, {} oversized allocations",
            self.cases,
            self.ok,
            self.errors,
            self.panics.len(),
            self.slow.len(),
            self.big.len()
        );
        assert!(
            self.panics.is_empty(),
            "{name}: panics in {:?}",
            self.panics
        );
        assert!(self.slow.is_empty(), "{name}: slow cases {:?}", self.slow);
        assert!(
            self.big.is_empty(),
            "{name}: oversized allocations {:?}",
            self.big
        );
    }
}

/// What `log info`, `log convert` (ticks and world tables) and `run --device replay:` read.
fn read_all_ways(bytes: &[u8]) -> Result<(), String> {
    read_info(bytes, "m")?;
    read_ticks(bytes, "m")?;
    read_world_tables(bytes, "m")?;
    encoders_of(bytes, "m")?;
    Ok(())
}

#[test]
fn fuzzed_mcap_logs_are_read_or_refused_never_a_panic_a_hang_or_a_huge_allocation() {
    // The panic hook would print every caught panic: keep the output to the tally.
    let seed = seed_mcap();
    read_all_ways(&seed).expect("the seed log reads");
    let (lens, strs) = length_fields(&seed);
    assert!(
        lens.len() > 50 && strs.len() > 10,
        "{} {}",
        lens.len(),
        strs.len()
    );
    let mut rng = Rng(0x5EED_0038);
    let mut tally = Tally::new();
    let mut kinds: BTreeMap<&str, usize> = BTreeMap::new();
    for i in 0..1200 {
        let (kind, m) = mutate(&seed, &mut rng, &lens, &strs);
        *kinds.entry(kind).or_default() += 1;
        tally.case(&format!("mcap case {i} ({kind})"), m.len(), || {
            read_all_ways(&m)
        });
    }
    eprintln!("mutations: {kinds:?}");
    tally.assert_clean("MCAP");
    // Most mutants are still partly readable: the test reaches past the first record.
    assert!(
        tally.errors > 100 && tally.ok > 100,
        "{} ok, {} errors",
        tally.ok,
        tally.errors
    );
}

/// A small CSV tick log with the encoder columns a replay reads.
fn seed_csv() -> String {
    let names: Vec<&str> = TICK_TABLE
        .iter()
        .map(|c| c.name)
        .filter(|n| !n.starts_with("encoders."))
        .collect();
    let mut s = format!("q1,q2,q3,q4,{}\n", names[..8].join(","));
    for i in 0..60 {
        s.push_str(&format!("{},2.9,0.2,3.0", 0.1 + i as f64 * 1e-4));
        for k in 0..8 {
            s.push_str(&format!(",{}", i * 8 + k));
        }
        s.push('\n');
    }
    s
}

#[test]
fn fuzzed_csv_logs_are_read_or_refused_never_a_panic_a_hang_or_a_huge_allocation() {
    let seed = seed_csv();
    let tick_seed = {
        // `log info` / `log convert` read tick columns only: the same rows without q1..q4.
        let mut lines = seed.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').skip(4).collect();
        let mut t = head.join(",") + "\n";
        for l in lines {
            t += &(l.split(',').skip(4).collect::<Vec<_>>().join(",") + "\n");
        }
        t
    };
    ReplayDevice::from_reader(
        seed.as_bytes(),
        "s",
        DEFAULT_REPLAY_COLUMNS,
        ReplayEnd::Error,
    )
    .expect("the seed replays");
    read_tick_csv_from(tick_seed.as_bytes(), "s").expect("the seed tick log reads");
    let mut rng = Rng(0xC5F_0038);
    let mut tally = Tally::new();
    for i in 0..600 {
        for (name, text) in [
            ("replay", seed.as_bytes()),
            ("tick log", tick_seed.as_bytes()),
        ] {
            let mut b = text.to_vec();
            let kind = match rng.below(5) {
                0 => {
                    for _ in 0..1 + rng.below(8) {
                        let j = rng.below(b.len());
                        b[j] ^= 1 << rng.below(8);
                    }
                    "bit flips"
                }
                1 => {
                    b.truncate(rng.below(b.len()));
                    "truncation"
                }
                2 => {
                    let j = rng.below(b.len());
                    b.insert(j, 0);
                    "NUL byte"
                }
                3 => {
                    let j = rng.below(b.len());
                    let junk = vec![b'9'; (1 << 20) + 10];
                    b.splice(j..j, junk);
                    "endless line"
                }
                _ => {
                    let j = rng.below(b.len());
                    b.splice(j..j, b"1e999,-,nan,\"\n,,,".iter().copied());
                    "odd cells"
                }
            };
            let what = format!("csv case {i} {name} ({kind})");
            let len = b.len();
            if name == "replay" {
                tally.case(&what, len, || {
                    ReplayDevice::from_reader(&b[..], "r", DEFAULT_REPLAY_COLUMNS, ReplayEnd::Error)
                        .map(|_| ())
                });
            } else {
                tally.case(&what, len, || read_tick_csv_from(&b[..], "t").map(|_| ()));
            }
        }
    }
    tally.assert_clean("CSV");
}

/// The top-level records of an MCAP file after its magic: (byte offset, opcode, declared length),
/// up to the first whose length runs past the end. Written from the MCAP specification
/// (<https://mcap.dev/spec>: opcode u8, length u64 LE, body), apart from the reader under test.
fn top_level(b: &[u8]) -> Vec<(usize, u8, u64)> {
    let mut out = Vec::new();
    let mut pos = 8;
    while pos + 9 <= b.len() {
        let len = u64::from_le_bytes(b[pos + 1..pos + 9].try_into().unwrap());
        out.push((pos, b[pos], len));
        match usize::try_from(len)
            .ok()
            .and_then(|l| (pos + 9).checked_add(l))
        {
            Some(next) if next <= b.len() => pos = next,
            _ => break,
        }
    }
    out
}

/// A log of `ticks` samples of box-in-walls at 1 kHz: tick rows with made-up encoder angles, and
/// the world (scene updates at 100 Hz).
fn log_of(ticks: u64) -> Vec<u8> {
    let mut world = haptic2d::scene::builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap()
        .world;
    world.prime();
    let mut scene = BTreeMap::new();
    scene.insert("scene_name".to_string(), "box-in-walls".to_string());
    let mut setup = McapSetup::for_world(&world, scene, true);
    setup.scene_update_hz = 100.0;
    let mut out = Vec::new();
    let mut sink = McapSink::new(std::io::Cursor::new(&mut out), setup).unwrap();
    let mut sample = WorldSample::default();
    for i in 0..ticks {
        world.step();
        sample.capture(&world);
        let q = [0.1 + i as f64 * 1e-4, 2.9, 0.2, 3.0];
        let row = tick_row(i, 1_000_000 * i, 0, &q, &Default::default());
        sink.write_tick_row(i, 1_000_000 * i, &row).unwrap();
        sink.write_world(i, 1_000_000 * i, &sample).unwrap();
    }
    sink.finish(&[]).unwrap();
    out
}

/// `../shared/repro/len-max.mcap`, rebuilt from its description (a whole log whose Header
/// record, at byte 8, declares a length of 2⁶⁴ − 1) instead of tracked as a recording.
fn len_max_log() -> Vec<u8> {
    let mut b = seed_mcap();
    assert_eq!(b[8], 0x01, "a log starts with its Header record");
    b[9..17].copy_from_slice(&u64::MAX.to_le_bytes());
    b
}

/// `../shared/repro/replay-nan-safety-exit0.mcap`, rebuilt from its description: a run log whose
/// Header's opcode is flipped to an unknown one (0xb6, as in the repro: a reader skips it), cut
/// halfway into its second Chunk record. Returns the bytes and that chunk's offset.
fn cut_log() -> (Vec<u8>, usize) {
    let mut b = log_of(3000);
    let chunks: Vec<_> = top_level(&b).into_iter().filter(|r| r.1 == 0x06).collect();
    assert!(chunks.len() >= 2, "one chunk only: {:?}", top_level(&b));
    let (at, _, len) = chunks[1];
    b[8] = 0xb6;
    b.truncate(at + 9 + len as usize / 2);
    (b, at)
}

#[test]
fn record_length_of_2_pow_64_minus_1_is_a_clear_error_not_a_panic() {
    // ../shared/repro/len-max.mcap (rebuilt by `len_max_log`): the Header's length field is 2⁶⁴ − 1; `log info`, `log
    // convert` and `replay:` panicked inside the mcap crate (exit 101).
    let b = len_max_log();
    reset_largest();
    for r in [
        read_info(&b, "len-max.mcap").map(|_| ()),
        read_ticks(&b, "len-max.mcap").map(|_| ()),
        read_world_tables(&b, "len-max.mcap").map(|_| ()),
        encoders_of(&b, "len-max.mcap").map(|_| ()),
    ] {
        let e = r.unwrap_err();
        assert!(
            e.contains("byte 8: a Header record (opcode 0x01) declares a length of 18446744073709551615 bytes"),
            "{e}"
        );
    }
    assert!(largest() < 1 << 20);
}

#[test]
fn a_log_cut_inside_a_chunk_replays_its_whole_ticks_before_the_cut() {
    // ../shared/repro/replay-nan-safety-exit0.mcap (rebuilt by `cut_log`): a run log cut inside its second chunk (and its
    // Header's opcode flipped to an unknown one, which a reader skips). The ticks before the cut
    // are read; the file is reported as cut, not complete.
    let (b, chunk_at) = cut_log();
    let info = read_info(&b, "cut.mcap").unwrap();
    assert!(!info.complete);
    let cut = info.damage.as_deref().unwrap();
    assert!(
        cut.contains(&format!(
            "the file ends inside a Chunk record at byte {chunk_at}"
        )),
        "{cut}"
    );
    let q = encoders_of(&b, "cut.mcap").unwrap();
    assert!(q.len() > 10, "{} ticks", q.len());
    assert!(q.iter().flatten().all(|v| v.is_finite()));
}

#[test]
fn the_reader_agrees_with_the_mcap_crate_on_every_message_of_a_valid_log() {
    let seed = seed_mcap();
    let mut ours = Vec::new();
    haptic2d_rt::mcap::reader::scan(&seed, "seed", |topic, t, data| {
        ours.push((topic.to_string(), t, data.to_vec()));
        Ok(())
    })
    .unwrap();
    let theirs: Vec<(String, u64, Vec<u8>)> = mcap::MessageStream::new(&seed)
        .unwrap()
        .map(|m| {
            let m = m.unwrap();
            (m.channel.topic.clone(), m.log_time, m.data.to_vec())
        })
        .collect();
    assert_eq!(ours.len(), theirs.len());
    assert!(ours == theirs, "the two readers differ");
}
