//! Issue 39, item 7: every main command's `--help` (and each emulator's, `emulate haply|inverse3`)
//! ends with working examples and fits in 100 columns. (`cli_tests::every_example_parses` in main.rs parses each example with the real
//! parser; here each example printed in the help is run with `--help` appended, which clap refuses
//! when an option before it is unknown or its value does not parse.)

use crate::common::{haptic2d, text};

/// The longest help line allowed (characters).
const MAX_COLUMNS: usize = 100;

/// `haptic2d WORDS… --help`, which must succeed with no line wider than [`MAX_COLUMNS`]: the help.
#[track_caller]
fn narrow_help(words: &[&str]) -> String {
    let o = haptic2d(&[words, &["--help"]].concat());
    let help = text(&o);
    let cmd = words.join(" ");
    assert!(o.status.success(), "{cmd} --help:\n{help}");
    for line in help.lines() {
        let n = line.chars().count();
        assert!(
            n <= MAX_COLUMNS,
            "{cmd} --help: line of {n} columns: {line}"
        );
    }
    help
}

#[test]
fn every_command_help_has_examples_that_parse() {
    let _m = crate::common::module_turn(module_path!());
    let screens: [&[&str]; 9] = [
        &["run"],
        &["simulate"],
        &["emulate"],
        &["emulate", "haply"],
        &["emulate", "inverse3"],
        &["log"],
        &["reproduce"],
        &["stability"],
        &["study"],
    ];
    for words in screens {
        let cmd = words.join(" ");
        let help = narrow_help(words);
        let (_, examples) = help
            .split_once("\nExamples:\n")
            .unwrap_or_else(|| panic!("{cmd} --help has no Examples: block:\n{help}"));
        let lines: Vec<&str> = examples
            .lines()
            .map(str::trim)
            .filter(|l| l.starts_with("haptic2d "))
            .collect();
        assert!(
            (3..=5).contains(&lines.len()),
            "{cmd}: {} examples in:\n{examples}",
            lines.len()
        );
        for line in lines {
            let mut args: Vec<&str> = line.split_whitespace().skip(1).collect();
            assert_eq!(args[..words.len()], words[..], "{line}");
            args.push("--help");
            let o = haptic2d(&args);
            assert!(o.status.success(), "{line} --help:\n{}", text(&o));
        }
    }
}

/// The check above can fail: an unknown option before `--help` is refused, also one that belongs
/// to the other emulator.
#[test]
fn an_unknown_option_before_help_is_refused() {
    let _m = crate::common::module_turn(module_path!());
    let o = haptic2d(&["run", "--headles", "--help"]);
    assert!(!o.status.success(), "{}", text(&o));
    let o = haptic2d(&["emulate", "haply", "--bind", "127.0.0.1:0", "--help"]);
    assert!(!o.status.success(), "{}", text(&o));
}

/// Issue 39 item 7: `emulate` names its two emulators; an unknown one is refused (exit 2) with
/// the subcommands listed.
#[test]
fn emulate_without_a_known_emulator_lists_haply_and_inverse3() {
    let _m = crate::common::module_turn(module_path!());
    for args in [&["emulate"][..], &["emulate", "foo"]] {
        let o = haptic2d(args);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {t}");
        assert!(
            t.contains("haply") && t.contains("inverse3"),
            "{args:?}: {t}"
        );
    }
}

/// Every other help screen fits in the same width (the top level carries the exit codes).
#[test]
fn every_other_help_fits_in_100_columns() {
    let _m = crate::common::module_turn(module_path!());
    let screens: [&[&str]; 8] = [
        &[],
        &["check"],
        &["sweep"],
        &["scenes"],
        &["devices"],
        &["device", "check"],
        &["log", "info"],
        &["log", "convert"],
    ];
    for words in screens {
        narrow_help(words);
    }
}
