//! The replay device reads encoder angles back from a CSV and discards torques.

use haptic2d_rt::io::DEFAULT_REPLAY_COLUMNS;
use haptic2d_rt::{DeviceError, DeviceIo, ReplayDevice, ReplayEnd};
use std::io::Write;

const CSV: &str = "t,q1,q2,q3,q4,extra\n\
0.000,0.1,0.2,0.3,0.4,x\n\
0.001,1.5,-2.5,3.25,-4e-3,y\n\
0.002,0,0,0,1e2,z\n";

#[test]
fn replay_reads_back_a_csv_file_row_by_row() {
    let mut f = tempfile::NamedTempFile::new().unwrap();
    f.write_all(CSV.as_bytes()).unwrap();
    let mut dev =
        ReplayDevice::from_path(f.path(), DEFAULT_REPLAY_COLUMNS, ReplayEnd::Error).unwrap();
    assert_eq!(dev.len(), 3);
    assert!(dev.name().starts_with("replay:"));
    assert_eq!(dev.read_encoders().unwrap(), [0.1, 0.2, 0.3, 0.4]);
    assert_eq!(dev.read_encoders().unwrap(), [1.5, -2.5, 3.25, -4e-3]);
    assert_eq!(dev.read_encoders().unwrap(), [0.0, 0.0, 0.0, 100.0]);
    assert_eq!(dev.read_encoders(), Err(DeviceError::EndOfData));
    // Torques go nowhere, but the last ones are kept for inspection.
    dev.write_torques(&[1.0, 2.0, 3.0, 4.0]).unwrap();
    assert_eq!(dev.last_torques(), [1.0, 2.0, 3.0, 4.0]);
    dev.zero_torques();
    assert_eq!(dev.last_torques(), [0.0; 4]);
}

#[test]
fn replay_uses_configured_columns_in_the_given_order() {
    let src = "q22,q21,q12,q11\n4,3,2,1\n";
    let mut dev = ReplayDevice::from_reader(
        src.as_bytes(),
        "mem",
        ["q11", "q12", "q21", "q22"],
        ReplayEnd::Error,
    )
    .unwrap();
    assert_eq!(dev.read_encoders().unwrap(), [1.0, 2.0, 3.0, 4.0]);
}

#[test]
fn replay_end_modes_hold_and_loop() {
    let samples = vec![[1.0; 4], [2.0; 4]];
    let mut hold = ReplayDevice::from_samples(samples.clone(), ReplayEnd::Hold).unwrap();
    let got: Vec<f64> = (0..4).map(|_| hold.read_encoders().unwrap()[0]).collect();
    assert_eq!(got, [1.0, 2.0, 2.0, 2.0]);
    let mut lp = ReplayDevice::from_samples(samples, ReplayEnd::Loop).unwrap();
    let got: Vec<f64> = (0..5).map(|_| lp.read_encoders().unwrap()[0]).collect();
    assert_eq!(got, [1.0, 2.0, 1.0, 2.0, 1.0]);
}

/// The error of reading `csv` (named `name`) with the default columns.
fn refusal(csv: &str, name: &str) -> String {
    ReplayDevice::from_reader(
        csv.as_bytes(),
        name,
        DEFAULT_REPLAY_COLUMNS,
        ReplayEnd::Error,
    )
    .unwrap_err()
}

#[test]
fn missing_column_error_names_the_column_and_lists_the_found_ones() {
    let e = refusal("t,q1,q2,q3\n0,1,2,3\n", "rec.csv");
    assert!(
        e.contains("rec.csv") && e.contains("`q4`") && e.contains("t, q1, q2, q3"),
        "{e}"
    );
}

#[test]
fn bad_number_error_names_the_line_and_column() {
    let e = refusal("q1,q2,q3,q4\n0,0,0,0\n0,abc,0,0\n", "rec.csv");
    assert!(
        e.contains("line 3") && e.contains("`q2`") && e.contains("abc"),
        "{e}"
    );
    let e = refusal("q1,q2,q3,q4\nNaN,0,0,0\n", "rec.csv");
    assert!(e.contains("not a finite number"), "{e}");
}

#[test]
fn empty_replay_and_missing_file_are_clear_errors() {
    let e = refusal("q1,q2,q3,q4\n", "empty.csv");
    assert!(e.contains("no samples"), "{e}");
    let e = ReplayDevice::from_path(
        std::path::Path::new("/nonexistent/rec.csv"),
        DEFAULT_REPLAY_COLUMNS,
        ReplayEnd::Error,
    )
    .unwrap_err();
    assert!(e.contains("/nonexistent/rec.csv"), "{e}");
}
