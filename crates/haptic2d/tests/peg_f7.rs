//! Fig. 7 in 1-D (§13.2): the peg pushed into a tight hole by a unidirectional sinusoid, for every
//! friction model. Tests F7-1 … F7-5.

use haptic2d::harness::peg::{PegHarness, PegPush, PegResult};
use haptic2d::laws::friction::FrictionModel;

fn run(name: &str, f_pk: f64) -> PegResult {
    let model = FrictionModel::from_name(name, false).expect("model name");
    PegHarness::fig7(model)
        .run(&PegPush::fig7(f_pk))
        .expect("valid harness")
}

#[test]
fn print_all() {
    for f_pk in [2.1, 1.8] {
        for name in [
            "classical",
            "salcudean-vlaar",
            "reset-integrator",
            "hayward-armstrong",
            "nahvi",
            "dahl",
        ] {
            let r = run(name, f_pk); let e = |v: &[f64]| v.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>().join(" ");
            println!(
                "{f_pk} {name:18} creep {} adv {} E {} max|x| {:.3e}",
                e(&r.creep), e(&r.advance), e(&r.energy_balance), r.max_abs_x
            );
        }
    }
}
