//! The TOML schema of a scene file (serde types). Unknown fields are errors.

use serde::Deserialize;
use std::collections::BTreeMap;

/// A whole scene file.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene name.
    pub name: Option<String>,
    /// One-line description.
    pub description: Option<String>,
    /// Rates, margins, integration.
    #[serde(default)]
    pub world: WorldSection,
    /// Impacts and the contact state machine.
    #[serde(default)]
    pub contact: ContactSection,
    /// Normal law: `model = "paper"` plus its parameters.
    #[serde(default)]
    pub normal: BTreeMap<String, toml::Value>,
    /// Friction model: `model = "reset-integrator"` plus its parameters.
    #[serde(default)]
    pub friction: BTreeMap<String, toml::Value>,
    /// Bodies.
    #[serde(default, rename = "body")]
    pub bodies: Vec<BodySection>,
    /// Grids of identical boxes (for piles).
    #[serde(default, rename = "grid")]
    pub grids: Vec<GridSection>,
    /// Applied loads.
    #[serde(default, rename = "load")]
    pub loads: Vec<LoadSection>,
    /// Device parameters overriding the spec defaults (any subset of
    /// [`DeviceParams`](crate::device::DeviceParams) fields); `None` when the file has no `[device]`
    /// table. Checked field by field when the scene is built.
    pub device: Option<toml::Table>,
}

/// `[world]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSection {
    /// Control rate (Hz); default 500 (T = 2 ms).
    pub rate: Option<f64>,
    /// Global proximity stage every N samples; default 10.
    pub proximity_every: Option<u32>,
    /// Proximity margin δ_prox (m); default 0.042.
    pub delta_prox: Option<f64>,
    /// Contact tolerance δ_c (m); default 0.002.
    pub delta_c: Option<f64>,
    /// "semi-implicit" (default) or "exact-zoh".
    pub integration: Option<String>,
    /// Passivity guard tolerance ε_E (J); off when absent.
    pub guard: Option<f64>,
    /// Damping time τ (s) of the implicit chain damper (stacks come to rest); 0 = off;
    /// default 0.0002 (`WorldParams::chain_tau`).
    pub chain_tau: Option<f64>,
    /// Gauss–Seidel sweeps of the chain damper per sample, at most (fewer once converged);
    /// default 16.
    pub chain_sweeps: Option<u32>,
    /// Work budget of the chain damper per sample, in row updates (whole sweeps, the first
    /// always runs); 0 = unbounded; default derived from the rate (`WorldParams::chain_budget`).
    pub chain_budget: Option<u64>,
    /// Accept bodies lighter than 1.5 × min_mass with a warning instead of an error.
    pub allow_light_bodies: Option<bool>,
    /// Accept bodies that start overlapping by more than `delta_c` (reported as warnings instead
    /// of errors by the CLI).
    pub allow_initial_overlap: Option<bool>,
}

/// `[contact]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSection {
    /// Resolve collisions with impulses (default true).
    pub impacts: Option<bool>,
    /// Poisson restitution e (default 0.5).
    pub restitution: Option<f64>,
    /// Collision velocity threshold v_c (m/s, default 0.02).
    pub v_c: Option<f64>,
    /// Edge-range tolerance ε_s (m, default 1e-4).
    pub eps_s: Option<f64>,
    /// Re-collision speed v_re (m/s); off when absent.
    pub recollision_speed: Option<f64>,
    /// Friction during impacts: "none" (default, frictionless impulses) or "coulomb" (issue 16).
    pub impact_friction: Option<String>,
    /// Impact friction coefficient μ (dimensionless, ≥ 0); default the friction model's μ_k.
    pub impact_mu: Option<f64>,
    /// The restitution law alone sets the rebound: impact records start their normal law at the
    /// detection depth and the struck contacts carry the impact sample's loads (default true since
    /// issue 35, docs/MODELS.md §7.6; false = §7.2 step 4 as written).
    pub impact_surface_offset: Option<bool>,
    /// Sweep budget of a large island's impact phases, 1 to 200 (default 8; docs/MODELS.md §7.7).
    pub impact_sweeps: Option<u32>,
    /// Row updates of the large islands' impact solve per sample, over all islands and phases
    /// (0 = unbounded, the default; docs/MODELS.md §7.7).
    pub impact_budget: Option<u64>,
}

/// `[[body]]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySection {
    /// Name (default `body<i>`).
    pub name: Option<String>,
    /// "dynamic" (default) or "fixed".
    pub kind: Option<String>,
    /// Mass (kg). Give `mass` or `density` for dynamic bodies.
    pub mass: Option<f64>,
    /// Areal density (kg/m²).
    pub density: Option<f64>,
    /// Moment of inertia about the centre of mass (kg·m²); computed from the shape when absent.
    pub inertia: Option<f64>,
    /// Position of the body frame origin (m).
    pub position: Option<[f64; 2]>,
    /// Orientation (rad).
    pub angle: Option<f64>,
    /// Orientation (degrees), alternative to `angle`.
    pub angle_deg: Option<f64>,
    /// Linear velocity of the centre of mass (m/s).
    pub velocity: Option<[f64; 2]>,
    /// Angular velocity (rad/s).
    pub omega: Option<f64>,
    /// Plant viscous damping on the translation (N·s/m).
    pub damping: Option<f64>,
    /// A convex polygon, counter-clockwise, in the body frame (m).
    pub polygon: Option<Vec<[f64; 2]>>,
    /// A rectangle `[width, height]` (m) centred on the body frame origin.
    #[serde(rename = "box")]
    pub rect: Option<[f64; 2]>,
    /// A union of convex polygons (m), for non-convex bodies.
    pub pieces: Option<Vec<Vec<[f64; 2]>>>,
}

/// `[[grid]]`: `count` identical boxes laid out in rows.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSection {
    /// Name prefix; bodies are named `<name><i>`.
    pub name: Option<String>,
    /// Number of boxes.
    pub count: usize,
    /// Boxes per row.
    pub columns: usize,
    /// Centre of the first box (m).
    pub origin: [f64; 2],
    /// Centre-to-centre spacing (m).
    pub spacing: [f64; 2],
    /// Box size `[width, height]` (m).
    #[serde(rename = "box")]
    pub rect: [f64; 2],
    /// Mass of each box (kg).
    pub mass: f64,
    /// Shift every other row by half a spacing (brick pattern).
    pub stagger: Option<bool>,
}

/// `[[load]]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSection {
    /// Name of the loaded body, or "*" for every dynamic body.
    pub body: String,
    /// Force (N), or acceleration (m/s²) with `per_mass = true`.
    pub force: Option<[f64; 2]>,
    /// Torque (N·m).
    pub torque: Option<f64>,
    /// "constant" (default) or "sine" (the unidirectional F(1 − cos 2πft)/2).
    pub profile: Option<String>,
    /// Frequency of the sine profile (Hz).
    pub frequency: Option<f64>,
    /// Multiply `force` by the body's mass (a body force such as gravity).
    pub per_mass: Option<bool>,
}
