//! `haptic2d device SUBCOMMAND`: the bench-top commands for a device on the desk — `check`
//! (angles, pose and motor directions: [`crate::cmd_device_check`]) and `identify` (a 2DIY's
//! inertia and damping for the stability gate: [`crate::cmd_device_identify`]).

use crate::cmd_device_check::CheckArgs;
use crate::cmd_device_identify::IdentifyArgs;
use crate::haply_arg::exit_code;
use std::process::ExitCode;

/// Subcommands of `haptic2d device`.
#[derive(clap::Subcommand, Debug)]
pub enum DeviceCommand {
    /// Read the angles and the pose; with --pulse confirm the motor directions.
    Check(CheckArgs),
    /// Measure a 2DIY's inertia and damping from small torque pulses (hand released) and write
    /// them to the device file's [identified] table for the stability gate.
    Identify(IdentifyArgs),
}

/// Runs `device SUBCOMMAND`.
pub fn run(c: &DeviceCommand) -> ExitCode {
    match c {
        DeviceCommand::Check(a) => exit_code(crate::cmd_device_check::check(a)),
        DeviceCommand::Identify(a) => exit_code(crate::cmd_device_identify::identify(a)),
    }
}
