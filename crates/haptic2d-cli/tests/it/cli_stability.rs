//! `haptic2d stability` end to end (issue 11): a verdict per axis and the poles, for the default
//! configuration and for the spec's, and the plot files.

use crate::common::{haptic2d, run, run_ok, text};

fn stability(args: &[&str], out: &std::path::Path) -> String {
    let mut a = vec!["stability"];
    a.extend_from_slice(args);
    a.extend_from_slice(&["--out", out.to_str().unwrap()]);
    let o = haptic2d(&a);
    assert!(o.status.success(), "{}", text(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn stability_prints_a_verdict_and_poles_per_axis_for_the_default() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let s = stability(&[], dir.path());
    println!("{s}");
    for axis in ["axis x", "axis y", "axis theta"] {
        assert!(s.contains(axis), "{s}");
    }
    assert_eq!(s.matches("verdict: stable").count(), 3, "{s}");
    assert_eq!(s.matches("right-most poles").count(), 6, "{s}");
    assert_eq!(s.matches("sampled growth").count(), 6, "{s}");
    assert!(dir.path().join("poles-four-channel.svg").is_file());
    assert!(dir.path().join("poles-four-channel.png").is_file());
}

#[test]
fn stability_shows_the_spec_configuration_unstable_released() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let s = stability(
        &[
            "peg-in-hole",
            "--controller",
            "four-channel-spec",
            "--scale",
            "2",
        ],
        dir.path(),
    );
    println!("{s}");
    assert!(s.contains("UNSTABLE with the hand released"), "{s}");
    assert_eq!(s.matches("verdict:").count(), 3, "{s}");
}

#[test]
fn stability_rejects_bad_options_with_a_message() {
    let _m = crate::common::module_turn(module_path!());
    for (args, needle) in [
        (
            vec!["stability", "--controller", "nope"],
            "four-channel-spec",
        ),
        (vec!["stability", "--rate", "-5"], "--rate"),
        (vec!["stability", "--delay", "3"], "--delay"),
    ] {
        let o = haptic2d(&args);
        assert!(!o.status.success());
        assert!(text(&o).contains(needle), "{}", text(&o));
    }
}

/// `--controller-file`: the shipped paper file is the §11.1 table (unstable released on the peg at
/// scale 2, like `--controller four-channel-spec`), the default file gives the default's verdicts, and
/// the plot is named after the file.
#[test]
fn stability_reads_a_controller_file() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let root = crate::common::root();
    let paper = root.join("controllers/paper-4ch.toml");
    let s = stability(
        &[
            "peg-in-hole",
            "--controller-file",
            paper.to_str().unwrap(),
            "--scale",
            "2",
        ],
        dir.path(),
    );
    assert!(s.contains("UNSTABLE with the hand released"), "{s}");
    assert!(s.contains("controller paper-4ch at"), "{s}");
    assert!(dir.path().join("poles-paper-4ch.svg").is_file());
    let default = root.join("controllers/default.toml");
    let s = stability(
        &["--controller-file", default.to_str().unwrap()],
        dir.path(),
    );
    assert_eq!(s.matches("verdict: stable").count(), 3, "{s}");
}

/// A bad controller file is refused with the file, the field and the fix; unknown keys are refused.
#[test]
fn stability_refuses_a_bad_controller_file_naming_the_field() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    for (body, needles) in [
        (
            "architecture = \"four-channel\"\nc5 = [1.0, 1.0]\n",
            vec!["c5", "expected 3 values", "fix:"],
        ),
        (
            "architecture = \"four-channel\"\nd_m = [1.0, -1.0, 0.0]\n",
            vec!["d_m[1]", ">= 0", "fix:"],
        ),
        (
            "architecture = \"four-channel\"\nc7 = [0, 0, 0]\n",
            vec!["c7", "unknown key", "c5", "fix:"],
        ),
        (
            "architecture = \"coupling\"\nk_m = [1, 1, 1]\n",
            vec!["k_m", "unknown key for a coupling", "fix:"],
        ),
        ("c5 = [0, 0, 0]\n", vec!["architecture", "missing", "fix:"]),
        (
            "architecture = \"four-chanel\"\n",
            vec!["architecture", "unknown architecture", "fix:"],
        ),
    ] {
        let f = dir.path().join("bad.toml");
        std::fs::write(&f, body).unwrap();
        let o = run(
            "stability --controller-file {} --out {}",
            &[&f, &dir.path()],
        );
        assert!(!o.status.success(), "{body}");
        let t = text(&o);
        assert!(t.contains("bad.toml"), "{t}");
        for n in needles {
            assert!(t.contains(n), "{n} in {t}");
        }
    }
    let o = haptic2d(&["stability", "--controller-file", "/nonexistent/c.toml"]);
    assert!(!o.status.success());
    assert!(
        text(&o).contains("controllers/paper-4ch.toml"),
        "{}",
        text(&o)
    );
}

/// `run` and `reproduce` take `--controller-file` too: `run` names the controller on its start line
/// and runs; `reproduce fig8` carries the claims with the file's controller, labelled by the file.
#[test]
fn run_and_reproduce_accept_a_controller_file() {
    let _turn = crate::common::loop_turn(module_path!()); // one real-time loop at a time
    let dir = tempfile::tempdir().unwrap();
    let root = crate::common::root();
    let soft = root.join("controllers/coupling-soft.toml");
    let o = run(
        "run --headless --no-rt --duration 0.2 --controller-file {}",
        &[&soft],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("controller coupling"), "{}", text(&o));
    let out = dir.path().join("repro");
    run_ok(
        "reproduce fig8 --out {} --controller-file {}",
        &[&out, &soft],
    );
    let report = std::fs::read_to_string(out.join("fig8/report.md")).unwrap();
    assert!(
        report.contains("| coupling-soft/classical | yes |"),
        "{report}"
    );
    let o = haptic2d(&["run", "--controller-file", "/nonexistent.toml"]);
    assert!(!o.status.success());
    assert!(text(&o).contains("controller file"), "{}", text(&o));
}
