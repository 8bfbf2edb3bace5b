//! End-to-end tests of the `haptic2d` binary: what a new user types.

use crate::common::{haptic2d, run_ok, text};

#[test]
fn simulate_twice_gives_byte_identical_csv() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.csv");
    let b = dir.path().join("b.csv");
    for p in [&a, &b] {
        run_ok("simulate box-in-walls-tilt --duration 1.5 --out {}", &[&p]);
    }
    let (x, y) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert!(x.len() > 1000);
    assert_eq!(x, y, "two runs of the same scene differ");
}

#[test]
fn simulate_writes_the_documented_columns() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("b.csv");
    run_ok(
        "simulate box-in-walls --duration 1 --every 10 --out {}",
        &[&p],
    );
    let csv = std::fs::read_to_string(&p).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t,energy.kinetic,energy.stored,work.applied,contacts,overlap,box.x,box.y,box.theta,box.vx,box.vy,box.omega"
    );
    // 1 s at 500 Hz, every 10th sample, plus the initial row.
    assert_eq!(lines.count(), 51);
}

/// The CSV's overlap column is the world's largest overlap of two bodies at each written sample
/// (`World::max_overlap`, computed here in the test's own world, stepped alongside), from the
/// t = 0 row on: `simulate` takes it from its run summary, sampled after the same step, instead
/// of running the separating-axis tests a second time.
#[test]
fn the_csv_overlap_column_is_the_worlds_overlap_at_each_written_sample() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("pile.csv");
    run_ok("simulate pile:20 --duration 0.6 --every 7 --out {}", &[&p]);
    let csv = std::fs::read_to_string(&p).unwrap();
    let column: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(5).unwrap().parse().unwrap())
        .collect();
    let mut world = haptic2d::scene::builtin("pile:20", None)
        .unwrap()
        .unwrap()
        .world;
    world.prime();
    let mut want = vec![world.max_overlap().depth];
    let ticks = (0.6 / world.params.dt).round() as u64;
    for k in 1..=ticks {
        assert!(world.step().is_none(), "diverged at {k}");
        if k % 7 == 0 {
            want.push(world.max_overlap().depth);
        }
    }
    assert_eq!(column.len(), want.len());
    assert!(want.iter().any(|&d| d > 0.0), "the pile never overlaps");
    for (i, (got, want)) in column.iter().zip(&want).enumerate() {
        assert_eq!(
            got.to_bits(),
            want.to_bits(),
            "row {i}: {got} against {want}"
        );
    }
}

#[test]
fn scenes_lists_the_builtins() {
    let _m = crate::common::module_turn(module_path!());
    let o = haptic2d(&["scenes"]);
    assert!(o.status.success());
    let t = text(&o);
    for name in ["box-in-walls", "peg-in-hole", "pile"] {
        assert!(t.contains(name), "{t}");
    }
}

#[test]
fn check_explains_a_bad_scene_and_fails() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.toml");
    std::fs::write(
        &p,
        "[[body]]\nname = \"b\"\nmass = 1.0\npolygon = [[0.0, 0.0], [0.0, 0.1], [0.1, 0.0]]\n",
    )
    .unwrap();
    let o = haptic2d(&["check", p.to_str().unwrap()]);
    assert!(!o.status.success());
    let t = text(&o);
    assert!(
        t.contains("bad.toml")
            && t.contains("body[0] \"b\".polygon")
            && t.contains("clockwise")
            && t.contains("fix:"),
        "{t}"
    );
}

#[test]
fn unknown_scene_and_bad_options_fail_cleanly() {
    let _m = crate::common::module_turn(module_path!());
    let o = haptic2d(&["simulate", "no-such-scene"]);
    assert!(!o.status.success());
    assert!(text(&o).contains("built-in scenes"), "{}", text(&o));
    let o = haptic2d(&["simulate", "box-in-walls", "--duration", "-1"]);
    assert!(!o.status.success());
    assert!(text(&o).contains("--duration"));
    let o = haptic2d(&["simulate", "box-in-walls", "--bogus"]);
    assert!(!o.status.success());
    assert!(!text(&o).contains("panicked"));
}

/// docs/SCENES.md quotes what `check` prints for bodies that start overlapping; the quote is the
/// binary's own output for the scene it describes (walls and a box overlapping by 5 mm, in
/// `my.toml`), so it cannot go stale.
#[test]
fn scenes_md_quotes_what_check_prints_for_overlapping_bodies() {
    let _m = crate::common::module_turn(module_path!());
    let doc = std::fs::read_to_string(crate::common::root().join("docs/SCENES.md")).unwrap();
    let section = doc
        .split_once("## Bodies that start overlapping")
        .expect("SCENES.md has the section")
        .1;
    let quoted = section
        .split("```")
        .nth(1)
        .expect("the section quotes the output")
        .trim_start_matches('\n')
        .trim_end();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("my.toml"),
        "[[body]]\nname = \"walls\"\nkind = \"fixed\"\nbox = [1.0, 0.1]\nposition = [0.0, -0.05]\n\n\
         [[body]]\nname = \"box\"\nbox = [0.1, 0.1]\nmass = 1.0\nposition = [0.0, 0.045]\n",
    )
    .unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_haptic2d"))
        .args(["check", "my.toml"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.starts_with(quoted),
        "SCENES.md quotes:\n{quoted}\ncheck prints:\n{stderr}"
    );
}

/// Issue 35: `simulate` says when the sweep budget of large impact islands (MODELS §7.7) acted, so
/// a user sees that restitution in a landing pile was cut; a scene without large islands says
/// nothing about it.
#[test]
fn simulate_reports_the_impact_sweep_budget_when_a_large_island_hits_it() {
    let _m = crate::common::module_turn(module_path!());
    let o = haptic2d(&["simulate", "pile:100", "--duration", "0.3"]);
    assert!(o.status.success(), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    let line = out
        .lines()
        .find(|l| l.starts_with("large impact islands: "))
        .unwrap_or_else(|| panic!("no budget line in\n{out}"));
    let number = |after: &str| -> u64 {
        let i = line
            .find(after)
            .unwrap_or_else(|| panic!("{after}? {line}"));
        line[..i]
            .rsplit(|c: char| !c.is_ascii_digit())
            .find(|w| !w.is_empty())
            .and_then(|w| w.parse().ok())
            .unwrap_or_else(|| panic!("{line}"))
    };
    // 100 boxes landing together form islands of more than 24 rows, and 8 sweeps do not
    // converge them.
    assert!(number(" solved") > 0, "{line}");
    assert!(number(" solver phases stopped") > 0, "{line}");
    let o = haptic2d(&["simulate", "box-in-walls", "--duration", "0.5"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        !String::from_utf8_lossy(&o.stdout).contains("large impact islands"),
        "{}",
        text(&o)
    );
}
