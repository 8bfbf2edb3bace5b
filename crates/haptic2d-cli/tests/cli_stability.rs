//! `haptic2d stability` end to end (issue 11): a verdict per axis and the poles, for the default
//! configuration and for the spec's, and the plot files.

mod common;

use common::{haptic2d, text};

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
