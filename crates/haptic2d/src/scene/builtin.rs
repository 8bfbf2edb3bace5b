//! Built-in scenes, embedded from the repository's `scenes/` folder.

use super::{Scene, SceneErrors};

/// `(name, description, TOML text)` of every built-in scene.
pub const BUILTIN: &[(&str, &str, &str)] = &[
    (
        "box-in-walls",
        "Fig. 4: a rectangle pushed by a constant 2 N force into the wall of an enclosure",
        include_str!("../../../../scenes/box-in-walls.toml"),
    ),
    (
        "box-in-walls-tilt",
        "Fig. 4, tilted: the rectangle starts at 10°, one corner hits first",
        include_str!("../../../../scenes/box-in-walls-tilt.toml"),
    ),
    (
        "peg-in-hole",
        "Fig. 7: a peg in a tight channel pushed by a unidirectional sinusoid, reset-integrator friction",
        include_str!("../../../../scenes/peg-in-hole.toml"),
    ),
    (
        "pile",
        "1000 boxes falling into a container under gravity (scaling)",
        include_str!("../../../../scenes/pile.toml"),
    ),
];

/// Names of the built-in scenes.
pub fn builtin_names() -> impl Iterator<Item = &'static str> {
    BUILTIN.iter().map(|b| b.0)
}

/// Loads a built-in scene by name, with an optional rate override (Hz). `None` if no such scene.
///
/// `pile:N` gives the pile with `N` boxes (e.g. `pile:100`).
pub fn builtin(name: &str, rate: Option<f64>) -> Option<Result<Scene, SceneErrors>> {
    if let Some(n) = name.strip_prefix("pile:") {
        let n: usize = n.parse().ok().filter(|&n| n > 0)?;
        return Some(Scene::from_toml(&pile_toml(n), name, rate));
    }
    let (_, _, text) = BUILTIN.iter().find(|b| b.0 == name)?;
    Some(Scene::from_toml(text, &format!("built-in:{name}"), rate))
}

/// The pile scene's TOML with `n` boxes (at most 25 per row). The container's walls (3 m in
/// `scenes/pile.toml`, above the 40 rows of 1000 boxes) are raised to 0.2 m above the top row when
/// the rows reach higher (0.03 m + 0.056 m a row): pile:5000's 200 rows start up to 11.2 m high,
/// and with 3 m walls the upper rows fell out of the container.
pub fn pile_toml(n: usize) -> String {
    let text = BUILTIN[3].2;
    let columns = n.clamp(1, 25);
    let rows = n.div_ceil(columns);
    let top = 0.03 + rows as f64 * 0.056 + 0.2;
    let mut t = text
        .replace("count = 1000", &format!("count = {n}"))
        .replace("columns = 25", &format!("columns = {columns}"))
        .replace("name = \"pile\"", &format!("name = \"pile:{n}\""));
    if top > 3.0 {
        t = t
            .replace(
                "[0.0, 3.0], [-0.1, 3.0]",
                &format!("[0.0, {top}], [-0.1, {top}]"),
            )
            .replace(
                "[1.5, 3.0], [1.4, 3.0]",
                &format!("[1.5, {top}], [1.4, {top}]"),
            );
    }
    t
}
