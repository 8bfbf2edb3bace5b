//! Reading a CSV tick log (`haptic2d run --log FILE.csv`, or `log convert` of an MCAP log) back, for
//! `haptic2d log info FILE.csv` and `log convert FILE.csv OUT.mcap`: the table column of each CSV
//! column ([`TICK_TABLE`]) and every row's cells. Bounded like every log reader ([`limits`]): at
//! most 1 GiB, lines of at most 1 MiB, no NUL byte.
//!
//! [`limits`]: crate::mcap::limits

use crate::mcap::columns::{column_index, parse_cell, Val, TICK_TABLE};
use crate::mcap::limits::{open_log_file, TextGuard, MAX_LOG_BYTES};
use std::io::Read;
use std::path::Path;

/// A CSV tick log: the [`TICK_TABLE`] index of each CSV column, and the rows (one cell a column).
pub type TickCsv = (Vec<usize>, Vec<Vec<Val>>);

/// Reads the CSV tick log at `path` (errors name the file, the line and the column). A regular
/// file above [`MAX_LOG_BYTES`] is refused before it is read.
pub fn read_tick_csv(path: &Path) -> Result<TickCsv, String> {
    let (file, meta, label) = open_log_file(path, "CSV log")?;
    if meta.is_file() && meta.len() > MAX_LOG_BYTES {
        return Err(format!(
            "the CSV log {label} is {} bytes, above the cap of {MAX_LOG_BYTES} bytes (1 GiB)\n    fix: cut the recording into parts",
            meta.len()
        ));
    }
    read_tick_csv_from(file, &label)
}

/// [`read_tick_csv`] from any reader (`label` names it in errors), through a [`TextGuard`].
pub fn read_tick_csv_from<R: Read>(reader: R, label: &str) -> Result<TickCsv, String> {
    let mut rdr = csv::ReaderBuilder::new().from_reader(TextGuard::new(reader));
    let header = rdr
        .headers()
        .map_err(|e| format!("{label}: cannot read the CSV header: {e}"))?
        .clone();
    let mut cols = Vec::with_capacity(header.len());
    for h in header.iter() {
        let k = column_index(h.trim()).ok_or_else(|| {
            format!(
                "{label}: column `{h}` is not a tick-log column\n    fix: `log convert` converts tick logs of `haptic2d run --log` (columns: docs/LOGS.md); a world CSV of `simulate` converts by re-running `simulate --out FILE.mcap`"
            )
        })?;
        if cols.contains(&k) {
            return Err(format!("{label}: column `{h}` appears twice"));
        }
        cols.push(k);
    }
    let mut rows = Vec::new();
    let mut rec = csv::StringRecord::new();
    let mut line = 1usize;
    loop {
        line += 1;
        if !rdr
            .read_record(&mut rec)
            .map_err(|e| format!("{label}: line {line}: {e}"))?
        {
            break;
        }
        if rec.len() != cols.len() {
            return Err(format!(
                "{label}: line {line} has {} fields, the header {}",
                rec.len(),
                cols.len()
            ));
        }
        let mut row = Vec::with_capacity(cols.len());
        for (&k, field) in cols.iter().zip(rec.iter()) {
            row.push(
                parse_cell(&TICK_TABLE[k], field)
                    .map_err(|e| format!("{label}: line {line}: {e}"))?,
            );
        }
        rows.push(row);
    }
    Ok((cols, rows))
}
