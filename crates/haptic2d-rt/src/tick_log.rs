//! CSV logging of the haptic tick's [`TickRecord`] (columns: [`TICK_COLUMNS`]).

use haptic2d::haptic::{TickRecord, TICK_COLUMNS};

use crate::logger::CsvRecord;

impl CsvRecord for TickRecord {
    fn header() -> Vec<String> {
        TICK_COLUMNS.iter().map(|s| s.to_string()).collect()
    }

    fn write_row<W: std::io::Write>(&self, out: &mut csv::Writer<W>) -> csv::Result<()> {
        for v in self.values() {
            out.write_field(v.to_string())?;
        }
        Ok(())
    }
}
