//! Helpers shared by the modules of this binary: scenes from text, scene errors, the 2-DOF rig.

use haptic2d::contact::{ContactState, EventKind};
use haptic2d::device::pantograph2::Pantograph2;
use haptic2d::haptic::planar2::{Planar2Config, Planar2System};
use haptic2d::haptic::ControllerKind;
use haptic2d::scene::{builtin, Scene, SceneErrors};
use haptic2d::world::World;

/// A fixed wall filling x ∈ [−0.1, 0] m, y ∈ [−0.2, 0.2] m (scene TOML).
pub const WALL_TOML: &str = "[[body]]\nname = \"wall\"\nkind = \"fixed\"\npolygon = [[-0.1, -0.2], [0.0, -0.2], [0.0, 0.2], [-0.1, 0.2]]\n";

/// [`WALL_TOML`] and a 0.04 m × 0.02 m box of 0.5 kg, whose `position` (and any other field)
/// follows (scene TOML).
pub const WALL_AND_BOX_TOML: &str = "[[body]]\nname = \"wall\"\nkind = \"fixed\"\npolygon = [[-0.1, -0.2], [0.0, -0.2], [0.0, 0.2], [-0.1, 0.2]]\n[[body]]\nname = \"box\"\nmass = 0.5\nbox = [0.04, 0.02]\n";

/// A fixed floor 40 m long with its top at y = 0 (scene TOML).
pub const FLOOR_TOML: &str = "[[body]]\nname = \"floor\"\nkind = \"fixed\"\npolygon = [[-20.0, -0.1], [20.0, -0.1], [20.0, 0.0], [-20.0, 0.0]]";

/// The paper's normal law (MODELS §5: per corner, `kc` = 1e5 N/m, `bc` = 40 N·s/m) as a scene's
/// `[normal]` table.
pub const PAPER_NORMAL_TOML: &str = "[normal]\nmodel = \"paper\"\nkc = 1.0e5\nbc = 40.0";

/// The world of the scene `text` (`name` in messages), primed (its contacts found) as a run does
/// before its first step.
pub fn primed_world(text: &str, name: &str) -> World {
    let mut w = Scene::from_toml(text, name, None)
        .unwrap_or_else(|e| panic!("{name} is a valid scene: {e}"))
        .world;
    w.prime();
    w
}

/// The errors of the scene `text` (file name `test.toml`), which must be refused.
pub fn scene_errors(text: &str) -> SceneErrors {
    match Scene::from_toml(text, "test.toml", None) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    }
}

/// Asserts that some error of the refused scene `text` is on a field containing `field`, its
/// message contains `what`, and it gives a fix.
pub fn assert_scene_error(text: &str, field: &str, what: &str) {
    let e = scene_errors(text);
    let shown = e.to_string();
    assert!(
        e.errors
            .iter()
            .any(|x| x.field.contains(field) && x.message.contains(what) && !x.fix.is_empty()),
        "no error on `{field}` containing `{what}`:\n{shown}"
    );
}

/// True if the last step of `w` resolved a colliding contact.
pub fn impacted(w: &World) -> bool {
    w.contacts().events().iter().any(|e| {
        matches!(
            e.kind,
            EventKind::Created(ContactState::Colliding) | EventKind::CreatedSimultaneous
        )
    })
}

/// The 2DIY gen 3 five-bar (d = 0.038, l1 = 0.07, l2 = 0.09 m).
pub fn gen3_linkage() -> Pantograph2 {
    Pantograph2::new(0.038, 0.07, 0.09).unwrap()
}

/// The built-in box-in-walls world at 1 kHz.
pub fn box_in_walls() -> World {
    builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap()
        .world
}

/// A 2-DOF system on box-in-walls and the gen 3 five-bar (torque limit 0.123 N·m), the coupling
/// controller, a ramp of `ramp_time` s, and `edit` applied to its configuration.
pub fn planar2_system(ramp_time: f64, edit: impl FnOnce(&mut Planar2Config)) -> Planar2System {
    let mut c = Planar2Config::new(gen3_linkage(), 0.123);
    c.controller = ControllerKind::from_name("coupling").unwrap();
    c.safety.ramp_time = ramp_time;
    edit(&mut c);
    Planar2System::new(box_in_walls(), c).unwrap()
}
