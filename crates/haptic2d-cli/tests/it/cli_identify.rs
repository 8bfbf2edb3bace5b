//! `haptic2d device identify` against `haptic2d emulate haply` (the stock firmware's behaviour, real
//! time, over a pseudo-terminal), issue 34 item 6: the inertia and damping of the emulated 2DIY
//! (`Plant2`: `I_j` = 2e-5 kg·m², `m_e` = 0.03 kg, `b` = 2e-4 N·m·s/rad; `M = I_j·1 + m_e·JᵀJ` at the
//! rest pose), written to the device file and used by the stability gate; reversed directions
//! refused with the field to flip; a handle that is not still at the rest pose refused before any
//! torque. The deterministic accuracy test (an inertia the code never saw, 1.7× the defaults, within
//! 10 %) is `haptic2d-devices/tests/identify_emulator.rs`; here the sample times are the host's wall
//! clock on a shared machine, so the bound is 15 %.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::{
    assert_has, assert_lacks, cmd, emulate_haply, expect_exit, interrupt as stop, joint1_reversed,
    motor1_flipped, run, shipped_text, text, write_in,
};

use haptic2d_devices::haply::{HaplyDeviceFile, HaplyKind};

/// The shipped gen 3 file with `edit` applied, in `dir`, and a reply timeout of 1000 periods: on a
/// machine at load average 13 the emulator was once silent for 100 ms. A late reply only stretches
/// a sample interval, which the fit takes from the host's clock.
fn device_file(dir: &Path, name: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let text = shipped_text("haply-2diy-gen3.toml")
        .replace("timeout_periods = 20 ", "timeout_periods = 1000 ");
    write_in(dir, name, &edit(text))
}

/// `haptic2d emulate haply --device-file FILE ARGS… --duration 30` and its pty path.
fn emulate(file: &Path, args: &[&str]) -> (crate::common::Killed, String) {
    emulate_haply(file, &[args, &["--duration", "30"]].concat())
}

/// The hand of the emulator for a released handle: no hand, no hand damping.
const RELEASED: [&str; 4] = ["--hand", "free", "--hand-damping", "0"];

/// `device identify --device-file FILE EXTRA…` against an emulator of `board` started with
/// `emu_args` (stopped after).
fn identify(board: &Path, emu_args: &[&str], file: &Path, extra: &[&str]) -> Output {
    let (emu, pty) = emulate(board, emu_args);
    let device = format!("haply:{pty}");
    let o = cmd(
        "device identify --device {} --release-delay 0 --device-file {}",
        &[&device, &file],
    )
    .args(extra)
    .output()
    .unwrap();
    stop(emu);
    o
}

/// A released handle (no hand, no hand damping): the identified joint inertias and the lumped model
/// are the emulated linkage's; `--write` stores them and `stability` says it uses them.
#[test]
fn device_identify_writes_the_emulated_inertia_and_the_gate_uses_it() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let file = device_file(dir.path(), "gen3.toml", |t| t);
    let o = identify(&file, &RELEASED, &file, &["--write"]);
    let out = expect_exit(&o, 0, &["wrote [identified]"]);
    let f = HaplyDeviceFile::from_path(&file).unwrap();
    let id = f.identified.clone().expect("an [identified] table");
    assert!(id.command.contains("device identify") && id.date.ends_with('Z'));
    let HaplyKind::TwoDiy { linkage, .. } = &f.kind else {
        panic!()
    };
    let q = f.rest_joint_angles();
    let j = linkage.state([q[0], q[1]]).unwrap().j;
    let jtj = |a: usize, b: usize| j[0][a] * j[0][b] + j[1][a] * j[1][b];
    let (i_j, m_e, b) = (2e-5, 0.03, 2e-4);
    for k in 0..2 {
        let want = i_j + m_e * jtj(k, k);
        let err = (id.inertia[k] - want) / want;
        assert!(
            err.abs() < 0.15,
            "joint {k}: {:e} vs {want:e}\n{out}",
            id.inertia[k]
        );
        assert!(
            (id.damping[k] - b).abs() < 0.5 * b,
            "joint {k} damping {:e}\n{out}",
            id.damping[k]
        );
    }
    assert!(((id.end_mass - m_e) / m_e).abs() < 0.15, "{out}");
    // The stability gate's numbers come from the table now.
    let o = run("stability --controller coupling --device-file {}", &[&file]);
    let s = text(&o);
    assert!(
        s.contains("device dynamics:") && s.contains(&format!("identified {}", id.date)),
        "{s}"
    );
    // Without the table it says the numbers are estimates.
    let plain = device_file(dir.path(), "plain.toml", |t| t);
    let o = run(
        "stability --controller coupling --device-file {}",
        &[&plain],
    );
    assert_has(&text(&o), &["built-in estimates, not measured"]);
}

/// A reversed motor (the host's file says CW, the board's motor turns CCW) and a motor and encoder
/// reversed together (every angle still grows) are both told from the fitted response; nothing is
/// identified and the fix names the field (exit 2).
#[test]
fn device_identify_detects_a_reversed_motor_and_a_reversed_motor_and_encoder() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let good = device_file(dir.path(), "gen3.toml", |t| t);
    let flipped = device_file(dir.path(), "flipped.toml", motor1_flipped);
    let o = identify(&good, &RELEASED, &flipped, &["--write"]);
    expect_exit(
        &o,
        2,
        &[
            "fix: motor[0] turns its link clockwise",
            "nothing identified",
        ],
    );
    assert!(HaplyDeviceFile::from_path(&flipped)
        .unwrap()
        .identified
        .is_none());
    // The board has motor 1's motor and encoder both reversed against the host's file.
    let board = device_file(dir.path(), "board.toml", joint1_reversed);
    let o = identify(&board, &RELEASED, &good, &[]);
    expect_exit(&o, 2, &["motor[0]'s motor AND encoder are both reversed"]);
}

/// The stock firmware reports the offsets wherever the handle is, so the host checks what it can:
/// the handle must be still at the rest pose at zero torque. A hand pushing it (0.02 N along +y,
/// creeping about 1 cm/s against the hand's damping) is refused before any torque, exit 2.
#[test]
fn device_identify_refuses_a_handle_that_is_not_still_at_the_rest_pose() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let file = device_file(dir.path(), "gen3.toml", |t| t);
    let o = identify(&file, &["--hand", "constant:0,0.02,0"], &file, &["--write"]);
    let out = expect_exit(&o, 2, &["rest pose", "fix:"]);
    assert_lacks(&out, &["identified at"]);
    assert!(HaplyDeviceFile::from_path(&file)
        .unwrap()
        .identified
        .is_none());
}

/// Bad options exit 2 before the device is opened: a pulse above the cap, --write on a built-in file.
#[test]
fn device_identify_refuses_bad_options_with_exit_2() {
    let _m = crate::common::module_turn(module_path!());
    for (args, says) in [
        ("--torque 0.1", "--torque 0.1"),
        ("--write", "--write needs --device-file"),
    ] {
        let o = run(
            &format!("device identify --device haply:/nonexistent {args}"),
            &[],
        );
        expect_exit(&o, 2, &[says]);
    }
}
