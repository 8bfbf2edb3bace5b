//! CSV logging of the haptic tick's [`TickRecord`] (columns: [`TICK_COLUMNS`]).

use haptic2d::haptic::{TickRecord, TICK_COLUMNS};

use crate::float_text::push_f64;
use crate::logger::CsvRecord;

impl CsvRecord for TickRecord {
    fn header() -> Vec<String> {
        TICK_COLUMNS.iter().map(|s| s.to_string()).collect()
    }

    /// Each value as `{}` writes it ([`push_f64`]: the same characters, without a `String` a
    /// field or `core::fmt`).
    fn write_row<W: std::io::Write>(&self, out: &mut csv::Writer<W>) -> csv::Result<()> {
        let mut text = String::with_capacity(32);
        for v in self.values() {
            text.clear();
            push_f64(&mut text, v);
            out.write_field(&text)?;
        }
        Ok(())
    }
}
