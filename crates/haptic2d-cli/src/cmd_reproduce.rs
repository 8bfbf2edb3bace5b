//! `haptic2d reproduce [all|fig4|fig5|fig7|fig8] [--out DIR]`: the paper's figures as data, plots,
//! metrics and a report (see the `haptic2d-lab` crate).

use std::path::Path;

/// Runs the selected figure(s), writes `DIR/<figure>/` and `DIR/REPORT.md`, prints a summary. Every
/// case's verdict is in its `metrics.json` (`pass`) and in the report; with `strict`, the command also
/// fails (after writing everything) if any case does not pass.
pub fn run(figure: &str, out: &Path, strict: bool) -> Result<(), String> {
    let s = haptic2d_lab::reproduce(figure, out, true)?;
    for f in &s.figures {
        let extra = if f.comparisons > 0 {
            format!(", +{} comparison runs", f.comparisons)
        } else {
            String::new()
        };
        println!(
            "{}: {}/{} cases pass{extra} ({:.2} s)",
            f.name, f.passed, f.total, f.seconds
        );
        for c in &f.failing {
            println!("  FAIL {c} (details in {}/metrics.json)", f.name);
        }
    }
    println!("report: {}", s.report.display());
    println!("total: {:.2} s", s.seconds);
    if s.all_pass() {
        // The claim cases of Figs. 5–11 are the paper's architecture (the four-channel controller,
        // with its released-stable default gains); comparison runs are not counted.
        println!("every case reproduces the paper's claim");
        Ok(())
    } else if strict {
        Err("some cases do not pass (--strict); see the report".to_string())
    } else {
        println!("some cases do not reproduce the paper's claim: see the report (--strict makes this an error)");
        Ok(())
    }
}
