//! Device I/O: the trait the haptic loop drives, and a replay device.
//!
//! A device gives four motor angles (the twin pantograph's encoders, radians,
//! after the reduction: joint angles `q11, q12, q21, q22` of MODELS §10.3) and
//! takes four joint torques (N·m). Real drivers, the simulated device and the
//! [`ReplayDevice`] all implement [`DeviceIo`].
//!
//! A 2-joint device (a 2-DOF five-bar such as a Haply 2DIY) implements [`Device2Io`] (two motor
//! angles in, two motor torques out) and enters the loop through [`Joints2`], which is a
//! [`DeviceIo`] that fills `q[0..2]`, leaves `q[2..4]` zero and drops `τ[2..4]`.
//!
//! A Cartesian point device (the Inverse3, a `PointSystem` in the loop) uses the same four slots
//! with other units: `read_encoders` gives `[x, y, 0, 0]`, the handle's plane point (m), and
//! `write_torques` takes the plane force in `τ[0..2]` (N), ignoring the rest.

use std::fmt;
use std::path::Path;

/// A device I/O failure.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum DeviceError {
    /// The device stopped answering (unplugged, powered off, timed out).
    Lost(String),
    /// A read or write failed (text: the cause).
    Io(String),
    /// A replay or recording has no more samples.
    EndOfData,
}

impl fmt::Display for DeviceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DeviceError::Lost(s) => write!(f, "device lost: {s}"),
            DeviceError::Io(s) => write!(f, "device I/O error: {s}"),
            DeviceError::EndOfData => write!(f, "end of the recorded data"),
        }
    }
}

impl std::error::Error for DeviceError {}

/// The device interface of the haptic loop. Every method is called from the
/// real-time thread, once per tick at most, and must not block longer than
/// the device's own transfer time.
pub trait DeviceIo {
    /// Reads the four joint angles `[q11, q12, q21, q22]`, radians (a point device: `[x, y, 0, 0]`,
    /// m; module docs).
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError>;

    /// Commands the four joint torques `[τ11, τ12, τ21, τ22]`, N·m (already
    /// saturated by the caller; a point device: the plane force `[f_x, f_y, ·, ·]`, N).
    fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError>;

    /// Commands zero torque on every motor. Must not fail (best effort on a
    /// lost device); called by the watchdog path and on shutdown.
    fn zero_torques(&mut self);

    /// A short human-readable name, e.g. "sim", "replay:run.csv".
    fn name(&self) -> &str;

    /// The handle's sensed orientation about the world plane's normal (rad), for a device whose
    /// joints do not carry it (an Inverse3's VerseGrip); `None` (the default) when there is none.
    /// The loop turns its changes into the slave's twist target. Read after `read_encoders`.
    fn handle_angle(&self) -> Option<f64> {
        None
    }

    /// True for a device whose motion advances one period per tick whatever the wall clock says (a
    /// simulated plant stepped in `write_torques`, a replay that plays one row per read): a late tick
    /// cannot hurt anyone there, so the loop neither measures the interval for it nor trips on
    /// stalls. Default false: a real device moves in real time, and a stall leaves its last torques
    /// applied unsupervised.
    fn paced_by_ticks(&self) -> bool {
        false
    }

    /// The device's buttons as read in the last exchange: bit `i` set = button `i` pressed (at
    /// most 8 buttons, `0..=7`). `0` (the default) for a device without buttons, and before the
    /// first reading. Read after `read_encoders`; never allocates or blocks (a field read).
    fn buttons(&self) -> u8 {
        0
    }
}

/// The device interface of a 2-joint device (a 2-DOF five-bar: motor 1, motor 2), with the same
/// contract as [`DeviceIo`]: called from the real-time thread, once per tick at most, never blocking
/// past one transfer (a device silent for its timeout returns [`DeviceError::Lost`]).
pub trait Device2Io {
    /// Reads the two motor angles `[q1, q2]` (rad, the linkage's own convention).
    fn read_joints(&mut self) -> Result<[f64; 2], DeviceError>;

    /// Commands the two motor torques `[τ1, τ2]` (N·m; the caller has saturated them; a driver
    /// clamps once more to its own limit).
    fn write_joint_torques(&mut self, tau: &[f64; 2]) -> Result<(), DeviceError>;

    /// Commands zero torque on both motors. Must not fail (best effort on a lost device).
    fn zero_torques(&mut self);

    /// A short human-readable name, e.g. "udp:127.0.0.1:9000".
    fn name(&self) -> &str;

    /// The handle's sensed orientation (rad), as [`DeviceIo::handle_angle`]; `None` by default.
    fn handle_angle(&self) -> Option<f64> {
        None
    }

    /// The device's buttons as read in the last exchange, as [`DeviceIo::buttons`] (bit `i` =
    /// button `i` pressed); `0` by default (no buttons).
    fn buttons(&self) -> u8 {
        0
    }
}

/// A [`Device2Io`] seen as a [`DeviceIo`]: `q = [q1, q2, 0, 0]`, `τ[2..4]` dropped. This is how a
/// 2-DOF device enters the loop of `haptic2d run`.
#[derive(Debug)]
pub struct Joints2<D>(pub D);

impl<D: Device2Io> DeviceIo for Joints2<D> {
    #[inline]
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
        let q = self.0.read_joints()?;
        Ok([q[0], q[1], 0.0, 0.0])
    }

    #[inline]
    fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
        self.0.write_joint_torques(&[tau[0], tau[1]])
    }

    fn zero_torques(&mut self) {
        self.0.zero_torques();
    }

    fn name(&self) -> &str {
        self.0.name()
    }

    fn handle_angle(&self) -> Option<f64> {
        self.0.handle_angle()
    }

    fn buttons(&self) -> u8 {
        self.0.buttons()
    }
}

/// What a [`ReplayDevice`] does after its last sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ReplayEnd {
    /// Return [`DeviceError::EndOfData`] (the loop can stop). Default.
    #[default]
    Error,
    /// Keep returning the last sample.
    Hold,
    /// Start again from the first sample.
    Loop,
}

/// The default encoder columns of a replay CSV.
pub const DEFAULT_REPLAY_COLUMNS: [&str; 4] = ["q1", "q2", "q3", "q4"];

/// The encoder columns of a tick log converted to CSV (`haptic2d log convert RUN.mcap RUN.csv`),
/// which a replay with [`DEFAULT_REPLAY_COLUMNS`] takes when the file has no `q1..q4`.
pub const LOGGED_ENCODER_COLUMNS: [&str; 4] =
    ["encoders.q1", "encoders.q2", "encoders.q3", "encoders.q4"];

/// A device that plays back recorded joint angles and discards torques.
///
/// The whole file is read at construction, so reading a sample on the RT
/// thread is an array index. Each [`read_encoders`](DeviceIo::read_encoders)
/// returns the next row.
#[derive(Debug, Clone)]
pub struct ReplayDevice {
    name: String,
    samples: Vec<[f64; 4]>,
    next: usize,
    end: ReplayEnd,
    last_torques: [f64; 4],
}

/// Largest replay read (bytes): the log cap [`MAX_LOG_BYTES`](crate::mcap::limits::MAX_LOG_BYTES),
/// 1 GiB, about 10 million rows of a tick log (17 min at 10 kHz, 2.8 h at 1 kHz), held in memory as
/// 32 bytes a row. Bounds a hostile or mistaken input (a pipe, `/dev/zero`, one endless line)
/// before it exhausts memory; lines are capped too
/// ([`MAX_CSV_LINE_BYTES`](crate::mcap::limits::MAX_CSV_LINE_BYTES)).
pub const MAX_REPLAY_BYTES: u64 = crate::mcap::limits::MAX_LOG_BYTES;

impl ReplayDevice {
    /// Loads `path`, taking the four joint angles (radians) from the columns
    /// named `columns` (e.g. [`DEFAULT_REPLAY_COLUMNS`]; with those, a file without them but with
    /// [`LOGGED_ENCODER_COLUMNS`] is read from those); other columns are ignored. Errors name the file, the column or the row.
    /// Files above [`MAX_REPLAY_BYTES`] are refused before anything is read.
    pub fn from_path(path: &Path, columns: [&str; 4], end: ReplayEnd) -> Result<Self, String> {
        let file = std::fs::File::open(path)
            .map_err(|e| format!("cannot open the replay file {}: {e}", path.display()))?;
        let len = file.metadata().map(|m| m.len()).unwrap_or(0);
        if len > MAX_REPLAY_BYTES {
            return Err(format!(
                "the replay file {} is {len} bytes, above the cap of {MAX_REPLAY_BYTES} bytes (1 GiB, about 10 million rows)\n    fix: cut the recording to the part to replay (e.g. `head -n 1000001 FILE > part.csv`)",
                path.display()
            ));
        }
        Self::from_reader(file, &path.display().to_string(), columns, end)
    }

    /// Like [`from_path`](Self::from_path), from any reader; `label` names the
    /// source in error messages.
    pub fn from_reader<R: std::io::Read>(
        reader: R,
        label: &str,
        columns: [&str; 4],
        end: ReplayEnd,
    ) -> Result<Self, String> {
        Self::from_reader_capped(reader, label, columns, end, MAX_REPLAY_BYTES)
    }

    /// [`from_reader`](Self::from_reader) with the byte cap as a parameter (tests use a small one).
    fn from_reader_capped<R: std::io::Read>(
        reader: R,
        label: &str,
        columns: [&str; 4],
        end: ReplayEnd,
        cap: u64,
    ) -> Result<Self, String> {
        // The byte cap also bounds a reader with no length (a pipe, /dev/zero); the line cap one
        // endless line, and a NUL byte ends a binary file at once.
        let guard = crate::mcap::limits::TextGuard::with_caps(
            reader,
            cap,
            crate::mcap::limits::MAX_CSV_LINE_BYTES,
        );
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(guard);
        let header = rdr
            .headers()
            .map_err(|e| format!("{label}: cannot read the CSV header: {e}"))?
            .clone();
        let find = |cols: &[&str; 4]| -> Option<[usize; 4]> {
            let mut idx = [0usize; 4];
            for (k, col) in cols.iter().enumerate() {
                idx[k] = header.iter().position(|h| h == *col)?;
            }
            Some(idx)
        };
        let (idx, columns) = match find(&columns) {
            Some(i) => (i, columns),
            None if columns == DEFAULT_REPLAY_COLUMNS => match find(&LOGGED_ENCODER_COLUMNS) {
                Some(i) => (i, LOGGED_ENCODER_COLUMNS),
                None => return Err(no_columns(label, &header, &columns)),
            },
            None => return Err(no_columns(label, &header, &columns)),
        };
        let mut samples = Vec::new();
        let mut rec = csv::StringRecord::new();
        // Row numbers as a person counts them in the file: header is line 1.
        let mut line = 1usize;
        loop {
            line += 1;
            let more = rdr.read_record(&mut rec);
            if !more.map_err(|e| {
                format!("{label}: line {line}: {e}\n    fix: cut the recording to the part to replay (about 10 million rows fit the 1 GiB cap)")
            })? {
                break;
            }
            let mut q = [0.0; 4];
            for k in 0..4 {
                let field = rec.get(idx[k]).unwrap_or("");
                q[k] = field.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                    format!(
                        "{label}: line {line}, column `{}`: `{field}` is not a finite number (radians)",
                        columns[k]
                    )
                })?;
            }
            samples.push(q);
        }
        Self::from_samples(samples, end).map(|mut d| {
            d.name = format!("replay:{label}");
            d
        })
    }

    /// A replay of in-memory samples (radians). Errors if `samples` is empty.
    pub fn from_samples(samples: Vec<[f64; 4]>, end: ReplayEnd) -> Result<Self, String> {
        if samples.is_empty() {
            return Err("the replay has no samples: it needs at least one data row".into());
        }
        Ok(Self {
            name: "replay".into(),
            samples,
            next: 0,
            end,
            last_torques: [0.0; 4],
        })
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Always false: a replay has at least one sample.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// All samples, radians.
    pub fn samples(&self) -> &[[f64; 4]] {
        &self.samples
    }

    /// The torques last written (N·m), for inspection; they act on nothing.
    pub fn last_torques(&self) -> [f64; 4] {
        self.last_torques
    }
}

/// The error of a replay CSV without encoder columns: which are missing, what it has, where to get
/// them.
fn no_columns(label: &str, header: &csv::StringRecord, columns: &[&str; 4]) -> String {
    let found: Vec<&str> = header.iter().take(40).collect();
    let missing: Vec<String> = columns
        .iter()
        .filter(|c| !header.iter().any(|h| h == **c))
        .map(|c| format!("`{c}`"))
        .collect();
    format!(
        "{label}: no column {} (a replay reads the encoder angles q1,q2,q3,q4 or encoders.q1..encoders.q4, rad); columns found: {}{}\n    fix: `haptic2d log convert RUN.mcap RUN.csv` writes encoders.q1..q4 from an MCAP run log, or replay the MCAP log itself (--device replay:RUN.mcap)",
        missing.join(", "),
        found.join(", "),
        if header.len() > found.len() { ", …" } else { "" }
    )
}

impl DeviceIo for ReplayDevice {
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
        if self.next >= self.samples.len() {
            match self.end {
                ReplayEnd::Error => return Err(DeviceError::EndOfData),
                ReplayEnd::Hold => return Ok(self.samples[self.samples.len() - 1]),
                ReplayEnd::Loop => self.next = 0,
            }
        }
        let q = self.samples[self.next];
        self.next += 1;
        Ok(q)
    }

    fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
        self.last_torques = *tau;
        Ok(())
    }

    fn zero_torques(&mut self) {
        self.last_torques = [0.0; 4];
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn paced_by_ticks(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod buttons_tests {
    use super::*;

    /// A 2-joint device whose buttons a test sets.
    struct Pressed(u8);

    impl Device2Io for Pressed {
        fn read_joints(&mut self) -> Result<[f64; 2], DeviceError> {
            Ok([0.0; 2])
        }
        fn write_joint_torques(&mut self, _: &[f64; 2]) -> Result<(), DeviceError> {
            Ok(())
        }
        fn zero_torques(&mut self) {}
        fn name(&self) -> &str {
            "pressed"
        }
        fn buttons(&self) -> u8 {
            self.0
        }
    }

    #[test]
    fn a_device_without_buttons_reports_none_and_joints2_forwards_a_2_joint_devices_buttons() {
        let replay = ReplayDevice::from_samples(vec![[0.0; 4]], ReplayEnd::Hold).unwrap();
        assert_eq!(replay.buttons(), 0);
        let d = Joints2(Pressed(0b101));
        assert_eq!(DeviceIo::buttons(&d), 0b101);
    }
}

#[cfg(test)]
mod replay_cap_tests {
    use super::*;

    const COLS: [&str; 4] = DEFAULT_REPLAY_COLUMNS;

    fn header() -> String {
        format!("{}\n", COLS.join(","))
    }

    #[test]
    fn replay_of_an_endless_line_stops_at_the_byte_cap() {
        // A header, then one line that never ends (what `/dev/zero` or a stuck pipe looks like).
        let head = header();
        let r = std::io::Read::chain(head.as_bytes(), std::io::repeat(b'1'));
        let e = ReplayDevice::from_reader_capped(r, "endless", COLS, ReplayEnd::Error, 4096)
            .expect_err("an endless line is refused");
        assert!(e.contains("above the cap of 4096 bytes"), "{e}");
    }

    #[test]
    fn replay_of_too_many_rows_stops_at_the_byte_cap() {
        let mut text = header();
        while text.len() < 10_000 {
            text.push_str("0,0,0,0\n");
        }
        let e =
            ReplayDevice::from_reader_capped(text.as_bytes(), "long", COLS, ReplayEnd::Error, 4096)
                .expect_err("a file above the cap is refused");
        assert!(e.contains("above the cap"), "{e}");
        // The same rows under the cap load.
        let d = ReplayDevice::from_reader_capped(
            text.as_bytes(),
            "long",
            COLS,
            ReplayEnd::Error,
            1 << 20,
        )
        .expect("under the cap");
        assert_eq!(d.name(), "replay:long");
    }

    #[test]
    fn replay_reads_the_encoder_columns_log_convert_writes() {
        let text = "t,encoders.q1,encoders.q2,encoders.q3,encoders.q4\n0,0.1,0.2,0.3,0.4\n";
        let d = ReplayDevice::from_reader(text.as_bytes(), "conv", COLS, ReplayEnd::Error)
            .expect("encoders.q1..q4 are read");
        assert_eq!(d.samples(), &[[0.1, 0.2, 0.3, 0.4]]);
    }

    #[test]
    fn replay_without_encoder_columns_names_what_it_needs_and_where_to_get_it() {
        let e = ReplayDevice::from_reader(&b"t,x\n0,1\n"[..], "run.csv", COLS, ReplayEnd::Error)
            .expect_err("no encoders");
        assert!(e.contains("columns found: t, x"), "{e}");
        assert!(e.contains("log convert RUN.mcap RUN.csv"), "{e}");
        assert!(
            !e.contains("column option"),
            "names no option that does not exist: {e}"
        );
    }

    #[test]
    fn replay_of_binary_data_is_refused_at_its_first_nul_byte() {
        let r = std::io::Read::chain(&b"q1,q2,q3,q4\n"[..], std::io::repeat(0));
        let e = ReplayDevice::from_reader(r, "zero", COLS, ReplayEnd::Error).unwrap_err();
        assert!(e.contains("NUL byte"), "{e}");
    }
}
