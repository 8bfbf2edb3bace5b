//! The per-trial table (`trials.tsv`): one tab-separated row per answered trial, in the layout
//! psychophysics tools read (a header row, then one trial per row; practice trials flagged).
//!
//! Columns: `trial block practice condition track vary reference_value comparison_value delta
//! comparison_interval response correct rt_s reversals run magnitude`. `magnitude` is the number
//! given in magnitude estimation, `-` in the other tasks (files of 15 columns, written before it
//! existed, still read). `track`, `reversals` and `run` (the
//! staircase's state after the answer: its index, reversals so far and consecutive correct answers)
//! are `-` for constant stimuli and practice; `correct` is `-` in a PSE condition (no answer is
//! correct when the comparison is another stimulus). Numbers are written in Rust's shortest round-trip form,
//! so reading a row back gives the same values bit for bit.

/// The header row.
pub const HEADER: &str = "trial\tblock\tpractice\tcondition\ttrack\tvary\treference_value\tcomparison_value\tdelta\tcomparison_interval\tresponse\tcorrect\trt_s\treversals\trun\tmagnitude";

/// The header before the `magnitude` column (still read).
const HEADER_15: &str = "trial\tblock\tpractice\tcondition\ttrack\tvary\treference_value\tcomparison_value\tdelta\tcomparison_interval\tresponse\tcorrect\trt_s\treversals\trun";

/// One answered trial.
#[derive(Clone, Debug, PartialEq)]
pub struct TrialRow {
    /// Trial number in the session, from 1.
    pub trial: u32,
    /// Block number, from 1.
    pub block: u32,
    /// Practice trial.
    pub practice: bool,
    /// Condition name.
    pub condition: String,
    /// Staircase index.
    pub track: Option<usize>,
    /// The varied parameter (`normal.kc`).
    pub vary: String,
    /// Its value in the reference.
    pub reference_value: f64,
    /// Its value in the comparison.
    pub comparison_value: f64,
    /// Comparison − base value.
    pub delta: f64,
    /// Interval (1/2) of the comparison.
    pub comparison_interval: u8,
    /// Interval (1/2) named stiffer.
    pub response: u8,
    /// The response named the comparison (the stiffer stimulus); `None` (`-`) in a PSE condition,
    /// where the comparison is another stimulus and no answer is correct (there, the response
    /// named the comparison iff `response == comparison_interval`).
    pub correct: Option<bool>,
    /// Response time (s).
    pub rt: f64,
    /// Staircase reversals after this trial.
    pub reversals: Option<u32>,
    /// Staircase consecutive-correct count after this trial.
    pub run: Option<u32>,
    /// Magnitude estimation: the number given to the comparison.
    pub magnitude: Option<f64>,
}

fn opt<T: std::fmt::Display>(v: &Option<T>) -> String {
    v.as_ref().map_or("-".into(), |x| x.to_string())
}

impl TrialRow {
    /// The row as a TSV line (with its newline).
    pub fn to_line(&self) -> String {
        format!(
            "{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\n",
            self.trial,
            self.block,
            u8::from(self.practice),
            self.condition,
            opt(&self.track),
            self.vary,
            self.reference_value,
            self.comparison_value,
            self.delta,
            self.comparison_interval,
            self.response,
            opt(&self.correct.map(u8::from)),
            self.rt,
            opt(&self.reversals),
            opt(&self.run),
            opt(&self.magnitude),
        )
    }

    /// Parses a TSV line (without its newline); the error names the column.
    pub fn parse(line: &str) -> Result<TrialRow, String> {
        let f: Vec<&str> = line.split('\t').collect();
        if f.len() != 15 && f.len() != 16 {
            return Err(format!("{} columns, expected 16", f.len()));
        }
        fn num<T: std::str::FromStr>(s: &str, col: &str) -> Result<T, String> {
            s.parse()
                .map_err(|_| format!("column `{col}`: `{s}` is not a valid number"))
        }
        fn opt_num<T: std::str::FromStr>(s: &str, col: &str) -> Result<Option<T>, String> {
            if s == "-" {
                Ok(None)
            } else {
                num(s, col).map(Some)
            }
        }
        let flag = |s: &str, col: &str| match s {
            "0" => Ok(false),
            "1" => Ok(true),
            _ => Err(format!("column `{col}`: `{s}` is not 0 or 1")),
        };
        Ok(TrialRow {
            trial: num(f[0], "trial")?,
            block: num(f[1], "block")?,
            practice: flag(f[2], "practice")?,
            condition: f[3].to_string(),
            track: opt_num(f[4], "track")?,
            vary: f[5].to_string(),
            reference_value: num(f[6], "reference_value")?,
            comparison_value: num(f[7], "comparison_value")?,
            delta: num(f[8], "delta")?,
            comparison_interval: num(f[9], "comparison_interval")?,
            response: num(f[10], "response")?,
            correct: if f[11] == "-" {
                None
            } else {
                Some(flag(f[11], "correct")?)
            },
            rt: num(f[12], "rt_s")?,
            reversals: opt_num(f[13], "reversals")?,
            run: opt_num(f[14], "run")?,
            magnitude: match f.get(15) {
                Some(m) => opt_num(m, "magnitude")?,
                None => None,
            },
        })
    }
}

impl TrialRow {
    /// The response named the comparison stimulus (in either design).
    pub fn comparison_chosen(&self) -> bool {
        self.response == self.comparison_interval
    }
}

/// Reads the rows of a `trials.tsv` text. Only complete lines (ending in a newline) count: a last
/// line cut short by a crash is not a trial. Returns the rows and the byte length of the complete
/// part (where appending resumes).
pub fn read(text: &str) -> Result<(Vec<TrialRow>, usize), String> {
    let complete = text.rfind('\n').map_or(0, |i| i + 1);
    let mut lines = text[..complete].lines();
    match lines.next() {
        None => return Ok((Vec::new(), 0)),
        Some(h) if h == HEADER || h == HEADER_15 => {}
        Some(h) => return Err(format!("line 1 is not the trials.tsv header (got `{h}`)")),
    }
    let mut rows = Vec::new();
    for (i, l) in lines.enumerate() {
        rows.push(TrialRow::parse(l).map_err(|e| format!("line {}: {e}", i + 2))?);
    }
    Ok((rows, complete))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_round_trips_bit_for_bit_and_a_cut_line_is_not_a_trial() {
        let r = TrialRow {
            trial: 3,
            block: 1,
            practice: false,
            condition: "spring".into(),
            track: Some(1),
            vary: "normal.kc".into(),
            reference_value: 1000.0,
            comparison_value: 1000.0 + 0.1 + 0.2,
            delta: 0.1 + 0.2,
            comparison_interval: 2,
            response: 1,
            correct: Some(false),
            rt: 4.123456789012345,
            reversals: Some(2),
            run: Some(0),
            magnitude: None,
        };
        let line = r.to_line();
        assert_eq!(TrialRow::parse(line.trim_end_matches('\n')).unwrap(), r);
        let text = format!("{HEADER}\n{line}{}", &line[..10]);
        let (rows, len) = read(&text).unwrap();
        assert_eq!(rows, vec![r]);
        assert_eq!(len, HEADER.len() + 1 + line.len());
    }

    /// A magnitude round-trips bit for bit, and a file written before the `magnitude` column
    /// (15 columns) is still read, its rows without a magnitude.
    #[test]
    fn a_magnitude_round_trips_and_a_fifteen_column_file_is_still_read() {
        let line =
            "1\t1\t0\tc\t-\tnormal.kc\t1000\t1200\t200\t2\t0\t-\t4.5\t-\t-\t131.7890123456789\n";
        let (rows, _) = read(&format!("{HEADER}\n{line}")).unwrap();
        assert_eq!(rows[0].magnitude, Some(131.7890123456789));
        assert_eq!(rows[0].to_line(), line);
        let old = "1\t1\t0\tc\t-\tnormal.kc\t1000\t1200\t200\t2\t1\t1\t4.5\t-\t-\n";
        let (rows, _) = read(&format!("{HEADER_15}\n{old}")).unwrap();
        assert_eq!((rows[0].magnitude, rows[0].correct), (None, Some(true)));
    }
}
