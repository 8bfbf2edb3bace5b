//! Tests W1–W9 (§5.10): the virtual walls on the 1-D Fig. 4 harness (§5.1, §13.1).

use haptic2d::harness::wall::{run_wall, EntryImpulse, WallConfig, WallIntegration, WallRun};
use haptic2d::laws::normal::{NormalModel, PaperLaw};

fn run(name: &str, config: WallConfig) -> WallRun {
    let law = NormalModel::from_name(name, false).expect("known law");
    run_wall(&config, law).expect("valid run")
}

fn describe(label: &str, r: &WallRun) {
    let m = &r.metrics;
    let ratios: Vec<String> = m.ratios().iter().take(5).map(|x| format!("{x:.3}")).collect();
    eprintln!(
        "{label:<28} seps {:>3}  ratios [{}]  settle {:?}  final {:.4} mm  max {:.3} mm",
        m.separations,
        ratios.join(", "),
        m.settle_time,
        m.final_penetration * 1e3,
        m.max_penetration * 1e3
    );
}

#[test]
fn report_table() {
    let cfg = WallConfig::fig4();
    for name in ["zoh", "seh", "minsky", "pi", "hysteretic", "pulse", "seh-pc"] {
        describe(name, &run(name, cfg));
    }
    describe("seh 30 s", &run("seh", WallConfig { duration: 30.0, ..cfg }));
    describe("colgate b=2.4", &run("colgate", WallConfig { damping: 2.4, ..cfg }));
    describe("colgate b=1.0", &run("colgate", WallConfig { damping: 1.0, ..cfg }));
    let paper = WallConfig { impulse: Some(EntryImpulse::paper()), ..cfg };
    describe("paper", &run("paper", paper));
    describe(
        "paper Bc=0",
        &run_wall(&paper, NormalModel::Paper(PaperLaw::new(2000.0, 0.0))).expect("run"),
    );
    for integ in [WallIntegration::ExplicitEuler, WallIntegration::ExactZoh, WallIntegration::SemiImplicit] {
        for name in ["zoh", "seh"] {
            describe(&format!("{name} {integ:?}"), &run(name, WallConfig { integration: integ, ..cfg }));
        }
    }
}
