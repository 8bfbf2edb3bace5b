//! `haptic2d study`: run on the simulated observer, SIGINT in the middle, resume, analyse; the
//! study file's errors; the observer that is not built yet is refused.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{expect_exit, haptic2d as run, text, BIN};

fn bin() -> Command {
    Command::new(BIN)
}

fn shipped() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../studies/stiffness-walls.toml")
}

fn rows(path: &Path) -> usize {
    std::fs::read_to_string(path)
        .map(|t| t.matches('\n').count().saturating_sub(1))
        .unwrap_or(0)
}

/// A study killed by SIGINT in the middle of its trials resumes from its trials.tsv and ends with
/// exactly the rows of an uninterrupted run (no trial lost or repeated); `study analyse` then fits
/// it and writes its table and plot.
#[test]
fn study_interrupted_by_sigint_resumes_with_no_trial_lost_or_repeated() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    // A longer session than the shipped one, so the signal lands mid-run.
    let long = dir.path().join("long.toml");
    let t = std::fs::read_to_string(shipped())
        .unwrap()
        .replace("repeats = 40 ", "repeats = 150 ");
    std::fs::write(&long, &t).unwrap();
    let long_s = long.to_str().unwrap();
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    let o = run(&[
        "study",
        "run",
        long_s,
        "--observer",
        "simulated",
        "--out",
        a.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let whole = std::fs::read_to_string(a.join("sub-sim01/ses-1/trials.tsv")).unwrap();
    assert_eq!(whole.matches('\n').count(), 1 + 4 + 7 * 150);

    let tsv = b.join("sub-sim01/ses-1/trials.tsv");
    let mut child = bin()
        .args(["study", "run", long_s, "--out", b.to_str().unwrap()])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while rows(&tsv) < 100 && t0.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(2));
    }
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGINT) }, 0);
    let st = child.wait().unwrap();
    let done = rows(&tsv);
    assert!(
        !st.success() && done < 4 + 7 * 150,
        "the signal came too late: {done} rows, {st:?}"
    );
    let o = run(&["study", "run", long_s, "--out", b.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("resumed from trials.tsv"), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(&tsv).unwrap(), whole);

    let o = run(&["study", "analyse", b.to_str().unwrap(), "--bootstrap", "50"]);
    assert!(o.status.success(), "{}", text(&o));
    let out = text(&o);
    assert!(
        out.contains("JND (75 % correct)") && out.contains("Weber fraction"),
        "{out}"
    );
    assert!(b.join("analysis.tsv").is_file() && b.join("psychometric.svg").is_file());
    // The per-level counts add up to the analysed (non-practice) trials.
    let levels = std::fs::read_to_string(b.join("analysis-levels.tsv")).unwrap();
    let n: u32 = levels
        .lines()
        .skip(1)
        .map(|l| l.split('\t').nth(2).unwrap().parse::<u32>().unwrap())
        .sum();
    assert_eq!(n, 7 * 150, "{levels}");
    let table = std::fs::read_to_string(b.join("analysis.tsv")).unwrap();
    assert!(
        table
            .lines()
            .nth(1)
            .unwrap()
            .starts_with("spring-1000\tnormal.kc\t1000\t1050\tweibull"),
        "{table}"
    );
}

/// `study check` accepts the shipped study and explains a broken one with the field and the fix
/// (exit 2, bad input); an observer that is not built is refused, not faked.
#[test]
fn study_check_and_run_refuse_bad_input_with_the_field_and_the_fix() {
    let _m = crate::common::module_turn(module_path!());
    let o = run(&["study", "check", shipped().to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("ok: study `stiffness-walls`"),
        "{}",
        text(&o)
    );
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        std::fs::read_to_string(shipped())
            .unwrap()
            .replace("kind = \"2afc\"", "kind = \"magnitude-estimation\""),
    )
    .unwrap();
    let o = run(&["study", "check", bad.to_str().unwrap()]);
    expect_exit(&o, 2, &["task.kind", "fix:"]);
    // `study run` refuses what it cannot run; the browser session checks its options before
    // anything starts; a participant ID that could be a name is refused.
    let study = shipped();
    let run_with = |options: &[&str]| {
        let mut args = vec!["study", "run", study.to_str().unwrap()];
        args.extend(options);
        args.extend(["--out", dir.path().to_str().unwrap()]);
        run(&args)
    };
    let o = run_with(&["--observer", "buttons"]);
    expect_exit(&o, 2, &["unknown observer", "--observer browser"]);
    let o = run_with(&["--observer", "browser", "--interval", "0"]);
    expect_exit(&o, 2, &["--interval", "fix:"]);
    let o = run_with(&["--participant", "Jane Doe"]);
    assert!(
        !o.status.success() && text(&o).contains("pseudonymous"),
        "{}",
        text(&o)
    );
}
