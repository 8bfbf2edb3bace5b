//! `haptic2d reproduce [all|fig4|fig5|fig7|fig8] [--out DIR] [--controller-file FILE.toml]`: the
//! paper's figures as data, plots, metrics and a report (see the `haptic2d-lab` crate).

use crate::exit::Failure;
use std::path::Path;

/// Runs the selected figure(s), writes `DIR/<figure>/` and `DIR/REPORT.md`, prints a summary. Every
/// case's verdict is in its `metrics.json` (`pass`) and in the report; with `strict`, the command also
/// fails (after writing everything) if any case does not pass. With `controller_file`, that
/// controller carries the claims of the device-in-the-loop figures (Figs. 5–6 and 8–11) instead of
/// the default; Figs. 4 and 7 do not use a controller.
///
/// An unknown figure, an `--out` that cannot be a folder or a bad controller file is bad input
/// (exit 2), checked before anything runs; a failure while running or writing, and `--strict` with a
/// failing case, exit 1.
pub fn run(
    figure: &str,
    out: &Path,
    strict: bool,
    controller_file: Option<&Path>,
) -> Result<(), Failure> {
    let names = haptic2d_lab::figures::figure_names();
    if figure != "all" && !names.contains(&figure) {
        return Err(format!(
            "unknown figure `{figure}`; valid: all, {}\n    fix: e.g. haptic2d reproduce fig4 (Figs. 5–6 are `fig5`, Figs. 8–11 `fig8`)",
            names.join(", ")
        )
        .into());
    }
    if out.as_os_str().is_empty() || (out.exists() && !out.is_dir()) {
        return Err(format!(
            "--out: `{}` is not a folder (it must name a folder to create or reuse)",
            out.display()
        )
        .into());
    }
    let controller = match controller_file {
        Some(p) => Some(crate::controller_file::resolve("four-channel", Some(p))?),
        None => None,
    };
    let controller = controller.map(|(kind, label)| (label, kind));
    let s = haptic2d_lab::reproduce_with(figure, out, true, controller).map_err(Failure::error)?;
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
        Err(Failure::error(
            "some cases do not pass (--strict); see the report",
        ))
    } else {
        println!("some cases do not reproduce the paper's claim: see the report (--strict makes this an error)");
        Ok(())
    }
}
