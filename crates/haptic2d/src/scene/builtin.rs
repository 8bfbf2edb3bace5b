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

/// The pile scene's TOML with `n` boxes: up to 1000 boxes in rows of 25 (`scenes/pile.toml`'s
/// 1.4 m container, 40 rows for 1000); a larger pile keeps 40 rows and widens the container
/// instead, `⌈n/40⌉` columns of 0.054 m (pile:5000: 125 columns, 6.8 m). The walls are raised to
/// 0.2 m above the top row if the rows ever reach higher than 3 m (they do not for 40 rows).
///
/// Why wider, not taller (issue 17): pile:5000 as 200 rows of 25 dropped its top rows from up to
/// 11.2 m (about 14 m/s at landing), deeper than any penalty contact holds: two boxes ended up
/// inside each other (50 mm overlap), so its step times measured a broken pile.
pub fn pile_toml(n: usize) -> String {
    let text = BUILTIN[3].2;
    let columns = if n <= 1000 {
        n.clamp(1, 25)
    } else {
        n.div_ceil(40)
    };
    let rows = n.div_ceil(columns);
    let top = (0.03 + rows as f64 * 0.056 + 0.2).max(3.0);
    // Inner right wall face: the staggered rows' last box plus the same clearance as pile.toml.
    let right = if columns <= 25 {
        1.4
    } else {
        columns as f64 * 0.054 + 0.05
    };
    let outer = right + 0.1;
    let t = text
        .replace("count = 1000", &format!("count = {n}"))
        .replace("columns = 25", &format!("columns = {columns}"))
        .replace("name = \"pile\"", &format!("name = \"pile:{n}\""));
    if top == 3.0 && columns <= 25 {
        return t;
    }
    t.replace(
        "[[-0.1, -0.1], [1.5, -0.1], [1.5, 0.0], [-0.1, 0.0]]",
        &format!("[[-0.1, -0.1], [{outer}, -0.1], [{outer}, 0.0], [-0.1, 0.0]]"),
    )
    .replace(
        "[[-0.1, 0.0], [0.0, 0.0], [0.0, 3.0], [-0.1, 3.0]]",
        &format!("[[-0.1, 0.0], [0.0, 0.0], [0.0, {top}], [-0.1, {top}]]"),
    )
    .replace(
        "[[1.4, 0.0], [1.5, 0.0], [1.5, 3.0], [1.4, 3.0]]",
        &format!("[[{right}, 0.0], [{outer}, 0.0], [{outer}, {top}], [{right}, {top}]]"),
    )
}
