//! The benchmark scenes, defined once as haptic2d scenes; the rapier2d twin of each is built from the
//! haptic2d world itself (`rapier_world.rs`), so geometry, masses, poses, velocities and loads are
//! identical by construction.

use haptic2d::scene::{builtin, Scene};

/// Time step of every comparison (s): 1 kHz, the haptic rate.
pub const DT: f64 = 0.001;

/// One benchmark case: a haptic2d scene plus the few rapier2d settings that cannot be read off it.
pub struct Case {
    /// Scene label in the table and JSON (`pile`, `box-in-walls`, `sliding`, `pyramid`).
    pub scene: &'static str,
    /// Number of dynamic bodies.
    pub n: usize,
    /// The haptic2d scene at `DT`.
    pub haptic: Scene,
    /// Coulomb friction coefficient given to every rapier2d collider (haptic2d's static μ_s).
    pub rapier_friction: f64,
    /// Restitution given to every rapier2d collider (haptic2d's Poisson e).
    pub rapier_restitution: f64,
}

/// The head of a bench scene on a floor from x = −1 m to `floor_end` (m), 0.1 m thick, under
/// gravity, with the pile's contact laws: 1 kHz, paper normal law (`Kc = 1e5 N/m`, `Bc = 40
/// N·s/m`), reset-integrator friction (μ_s = 0.5, μ_k = 0.45), impacts with restitution 0.2.
fn floor_scene_head(name: &str, description: &str, floor_end: f64) -> String {
    format!(
        r#"name = "{name}"
description = "{description}"

[world]
rate = 1000
proximity_every = 10
integration = "semi-implicit"

[contact]
impacts = true
restitution = 0.2
v_c = 0.05

[normal]
model = "paper"
kc = 1.0e5
bc = 40.0

[friction]
model = "reset-integrator"
kr = 5.0e4
mu_s = 0.5
mu_k = 0.45
beta = 20.0

[[body]]
name = "floor"
kind = "fixed"
pieces = [[[-1.0, -0.1], [{floor_end:.1}, -0.1], [{floor_end:.1}, 0.0], [-1.0, 0.0]]]

[[load]]
body = "*"
force = [0.0, -9.81]
per_mass = true
"#
    )
}

/// The sliding scene: `n` boxes of 0.05 m and 2 kg resting on a floor, launched along +x at 1–2 m/s,
/// 0.2 m apart so they never touch each other; reset-integrator friction μ_s = 0.5, μ_k = 0.45
/// (they slide for ≈ 0.25–0.45 s, then stick).
pub fn sliding_toml(n: usize) -> String {
    let mut s = floor_scene_head(
        "sliding",
        "boxes sliding on a floor with reset-integrator friction",
        8.0,
    );
    for k in 0..n {
        let v = 1.0 + k as f64 / n.max(1) as f64;
        s.push_str(&format!(
            "\n[[body]]\nname = \"slider{k}\"\nmass = 2.0\nbox = [0.05, 0.05]\nposition = [{:.3}, 0.025]\nvelocity = [{v:.3}, 0.0]\n",
            0.2 * k as f64
        ));
    }
    s
}

/// The pyramid scene: `rows` rows of 0.05 m, 2 kg boxes (row `r` from the bottom holds `rows − r`
/// boxes, 1 mm apart, each row resting on the one below: 210 boxes for 20 rows) on a floor, with the
/// pile's contact laws; it starts at rest and should stay so.
pub fn pyramid_toml(rows: usize) -> String {
    let mut s = floor_scene_head("pyramid", "a pyramid of boxes resting on the ground", 3.0);
    let pitch = 0.051; // box width + 1 mm gap
    for r in 0..rows {
        for k in 0..rows - r {
            let x = 0.5 * pitch * r as f64 + pitch * k as f64;
            let y = 0.025 + 0.05 * r as f64;
            s.push_str(&format!(
                "\n[[body]]\nname = \"b{r}_{k}\"\nmass = 2.0\nbox = [0.05, 0.05]\nposition = [{x:.4}, {y:.4}]\n"
            ));
        }
    }
    s
}

fn scene(
    name: &str,
    result: Option<Result<Scene, haptic2d::scene::SceneErrors>>,
) -> Result<Scene, String> {
    match result {
        Some(Ok(s)) => Ok(s),
        Some(Err(e)) => Err(format!("scene {name}: {e}")),
        None => Err(format!("no built-in scene {name}")),
    }
}

/// All cases: `pile` for every `n` in `pile_sizes`, `box-in-walls`, `sliding` (10 boxes), `pyramid`
/// (20 rows, 210 boxes); those whose
/// label contains none of `filter` (when non-empty) are left out.
pub fn cases(pile_sizes: &[usize], filter: &[String]) -> Result<Vec<Case>, String> {
    let keep = |label: &str| filter.is_empty() || filter.iter().any(|f| label.contains(f.as_str()));
    let rate = Some(1.0 / DT);
    let mut out = Vec::new();
    if keep("pile") {
        for &n in pile_sizes {
            let name = format!("pile:{n}");
            out.push(Case {
                scene: "pile",
                n,
                haptic: scene(&name, builtin(&name, rate))?,
                rapier_friction: 0.5,
                rapier_restitution: 0.2,
            });
        }
    }
    if keep("box-in-walls") {
        out.push(Case {
            scene: "box-in-walls",
            n: 1,
            haptic: scene("box-in-walls", builtin("box-in-walls", rate))?,
            rapier_friction: 0.0,
            rapier_restitution: 0.5,
        });
    }
    // The generated floor scenes carry the pile's laws (rapier2d: μ 0.5, e 0.2).
    let floor_case = |label: &'static str, n: usize, toml: String| -> Result<Case, String> {
        Ok(Case {
            scene: label,
            n,
            haptic: scene(label, Some(Scene::from_toml(&toml, label, rate)))?,
            rapier_friction: 0.5,
            rapier_restitution: 0.2,
        })
    };
    if keep("sliding") {
        let n = 10;
        out.push(floor_case("sliding", n, sliding_toml(n))?);
    }
    if keep("pyramid") {
        let rows = 20;
        out.push(floor_case(
            "pyramid",
            rows * (rows + 1) / 2,
            pyramid_toml(rows),
        )?);
    }
    Ok(out)
}
