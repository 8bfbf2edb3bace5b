//! The per-VE-pair record (§8.1): distance history, edge coordinate, god-object, and the slot of
//! its law states.
//!
//! The law states ([`LawState`]: a [`NormalModel`] and a [`FrictionModel`], 144 or 272 bytes) live
//! out of line in the contact set's pool, so the record that every per-sample pass walks stays
//! small (the tracked pairs that are not contacts, the majority on a pile, need no law state at
//! all).

use crate::collide::VeCandidate;
use crate::geom::Vec2;
use crate::laws::friction::{FrictionLaw, FrictionModel};
use crate::laws::normal::{ContactNormal, NormalLaw, NormalModel};

/// Sentinel of [`VeContact::law`] for an entry without law states (only tracked).
pub const NO_LAW: u32 = u32::MAX;

/// The per-contact states of the normal law and the friction model of one contact record.
///
/// Laid out friction first, then the normal law's offset and model (`repr(C)` here and in
/// [`ContactNormal`]): the common laws' fields (the reset integrator, 64 bytes; the paper law,
/// 24) then sit in the first two cache lines of the slot, which the force pass streams through
/// every sample. With the whole [`NormalModel`] (`N`, the default) a slot is 272 bytes, sized
/// for the hysteretic wall's elements; the contact set's pool stores the other laws in 144-byte
/// slots of a compact model instead (`contact/compact_law.rs`) while no record needs the wall.
///
/// `F` is the friction model's type: [`FrictionModel`] (the default) in the pool's compact and
/// whole slots; the lean slots (`contact/lean_law.rs`) hand the force pass the reset integrator
/// itself.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct LawState<N = NormalModel, F = FrictionModel> {
    /// Friction-model state (a copy of the world's prototype, taken when the record was created).
    pub friction: F,
    /// Normal-law state (a copy of the world's prototype, taken when the record was created) with
    /// the surface offset of a resolved impact ([`ContactNormal`], docs/MODELS.md §E.7).
    pub normal: ContactNormal<N>,
}

/// The state of a VE pair that is in contact (§8.2). A pair that is only tracked has no state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactState {
    /// Approaching faster than `v_c` at creation: resolved by an impulse at this sample (§7).
    Colliding,
    /// Sticking or sliding contact: forces from the normal law and the friction model.
    Continuous,
}

impl<N: NormalLaw, F: FrictionLaw> LawState<N, F> {
    /// Starts a new contact whose god-object entry point is at edge coordinate `s_entry` (m): the
    /// normal law is reset and the friction model begins there (§8.3).
    #[inline]
    pub fn begin(&mut self, s_entry: f64) {
        self.normal.reset();
        self.friction.begin(s_entry);
    }
}

/// A tracked VE pair: a candidate from the local stage, or a contact record when `state` is set.
///
/// Geometry fields are refreshed every sample; `n`, `t`, `point` are world quantities of this sample.
#[derive(Clone, Copy, Debug)]
pub struct VeContact {
    /// Identity: (vertex collider, vertex, edge collider, edge).
    pub key: VeCandidate,
    /// Body owning the vertex ("A").
    pub body_a: usize,
    /// Body owning the edge ("B").
    pub body_b: usize,
    /// `None` while only tracked; `Some(state)` for a contact record.
    pub state: Option<ContactState>,
    /// Signed-distance history (m): `d[0] = d_k`, `d[1] = d_{k−1}`, `d[2] = d_{k−2}`.
    pub d: [f64; 3],
    /// Number of valid entries in `d` (1..=3).
    pub hist: u8,
    /// This sample's local stage proposed the key from its vertex scan
    /// ([`LocalStage::from_vertex_scan`](crate::collide::LocalStage::from_vertex_scan)): the edge
    /// is its vertex's nearest edge line (or the corner rule's, within `δ_c`), so the record
    /// satisfies the depth invariant and the hand-over has nothing to check. Set by the merge.
    pub nearest_edge: bool,
    /// The last force pass listed the record among the loaded ones
    /// ([`ContactSet::loaded`](super::ContactSet::loaded): Continuous, `f_n > 0`).
    pub loaded: bool,
    /// Edge coordinate `s^B_k` (m).
    pub s: f64,
    /// Previous edge coordinate `s^B_{k−1}` (m).
    pub s_prev: f64,
    /// Edge length `L` (m).
    pub len: f64,
    /// World position of the vertex `V` (m).
    pub point: Vec2,
    /// Outward edge normal (world); the tangent is [`VeContact::t`].
    pub n: Vec2,
    /// Normal relative velocity `C0` (m/s), positive when separating.
    pub c0: f64,
    /// Tangential slip velocity `S0` (m/s).
    pub s0: f64,
    /// God-object edge coordinate `s_g` in B's frame (m), §8.3.
    pub s_g: f64,
    /// Entry point: the edge coordinate where the vertex crossed the edge line at creation (m), §8.3.
    pub s_entry: f64,
    /// Effective mass behind the contact for the braking pulse (kg).
    pub m_eff: f64,
    /// Slot of this record's [`LawState`] in the contact set's pool (see
    /// [`ContactSet::laws`](super::ContactSet::laws)); [`NO_LAW`] while only tracked.
    pub law: u32,
    /// Normal force of the last sample (N).
    pub f_n: f64,
    /// Friction force on A along `+t` of the last sample (N).
    pub f_t: f64,
    /// Tick at which this entry was first tracked.
    pub since: u64,
    /// The pair's geometry in the bodies' own frames (fixed for the life of the entry).
    pub local: LocalGeom,
    /// The crossing-corner stage's own-axis test, remembered (`contact/manager/clip.rs`): the
    /// relative angle `θ_A − θ_B` (rad) at which it was last computed, the excess (m) it found
    /// there (the overlap along the record's normal less the record's own depth), and the vertex
    /// collider's radius (m) its bound uses. NaN: not yet, or a pair with seams (never
    /// remembered).
    pub own_axis: (f64, f64, f64),
}

/// Body-frame geometry of a VE pair: the vertex in A's frame, the edge's start, normal and tangent
/// in B's frame. World quantities follow from the two body poses each sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalGeom {
    /// Vertex `V` in A's centre-of-mass frame (m).
    pub v: Vec2,
    /// Edge start `E0` in B's centre-of-mass frame (m).
    pub e0: Vec2,
    /// Outward edge normal in B's frame (the tangent is `(−n_y, n_x)`, see [`VeContact::t`]).
    pub n: Vec2,
}

impl VeContact {
    /// Edge tangent (world): `t = (−n_y, n_x)`, exactly the rotated polygon tangent, since a
    /// polygon's normals are `n = (t_y, −t_x)` (`geom/polygon.rs`) and rotating both by the same
    /// `(cos, sin)` keeps that relation exactly (each component is the same two products added in
    /// the other order, or negated; only the sign of an exact zero can differ).
    #[inline]
    pub fn t(&self) -> Vec2 {
        Vec2::new(-self.n.y, self.n.x)
    }
    /// True for a contact record (Colliding or Continuous).
    #[inline]
    pub fn is_contact(&self) -> bool {
        self.state.is_some()
    }
    /// True if the vertex lies within the edge range `[−ε_s, L + ε_s]`.
    #[inline]
    pub fn in_range(&self, eps_s: f64) -> bool {
        self.s >= -eps_s && self.s <= self.len + eps_s
    }
    /// World position of the god-object (m): the point `E0 + s_g·t` on the edge.
    #[inline]
    pub fn god_object(&self) -> Vec2 {
        // point = E0 + s·t + d·n, so E0 = point − s·t − d·n.
        self.point - self.t() * self.s - self.n * self.d[0] + self.t() * self.s_g
    }
}

/// A Continuous record whose normal law pushed in the last sample (`f_n > 0`), as the force pass
/// lists them for later passes (the chain damper): 48 bytes instead of the whole record. The
/// keys are listed apart ([`Loaded::keys`]), rewritten only when they change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadedContact {
    /// Body owning the vertex ("A").
    pub body_a: u32,
    /// Body owning the edge ("B").
    pub body_b: u32,
    /// World position of the vertex (m).
    pub point: Vec2,
    /// Outward edge normal (world).
    pub n: Vec2,
    /// Normal force of the sample (N, > 0).
    pub f_n: f64,
}

/// The loaded records of the last sample ([`ContactSet::loaded`](super::ContactSet::loaded)), in
/// key order: what the chain damper reads of them.
#[derive(Clone, Copy, Debug)]
pub struct Loaded<'a> {
    /// The records' geometry and normal forces.
    pub contacts: &'a [LoadedContact],
    /// Their keys (parallel to `contacts`).
    pub keys: &'a [VeCandidate],
    /// A number that changes whenever `keys` do (1, 2, …; it may also change when they do not):
    /// equal numbers mean the same keys in the same order, so a reader can keep what it built
    /// for the last sample's list without comparing them.
    pub generation: u64,
}

/// One transition of the contact state machine, for the trace that tests assert on (§8.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContactEvent {
    /// Sample index `k`.
    pub tick: u64,
    /// Pair identity.
    pub key: VeCandidate,
    /// What happened.
    pub kind: EventKind,
}

/// Kinds of contact-state transitions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventKind {
    /// A record was created in this state (Colliding, or Continuous for an invalid impact).
    Created(ContactState),
    /// Created as Colliding by the simultaneity window (§8.2 rule 2).
    CreatedSimultaneous,
    /// A Colliding record was resolved by the impact solver and became Continuous.
    Resolved,
    /// The record was deleted (separation or out of the edge range).
    Released,
    /// A Continuous record was promoted back to Colliding (§8.2 rule 5, option).
    Recollision,
}

#[cfg(test)]
mod tests {
    use crate::geom::{ConvexPolygon, Rot, Vec2};
    use rand::{Rng, SeedableRng};

    /// `VeContact::t` derives the world tangent from the world normal: for random convex
    /// polygons and angles (and the axis-aligned box at 0 rad), the rotated tangent is exactly
    /// `(−n_y, n_x)` of the rotated normal.
    #[test]
    fn world_tangent_is_the_rotated_normal_turned_exactly() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        for _ in 0..500 {
            let n = rng.random_range(3..9);
            let r = rng.random_range(1e-3..2.0);
            let phase = rng.random_range(0.0..6.3);
            let vertices = (0..n)
                .map(|i| {
                    let a = phase
                        + std::f64::consts::TAU * (i as f64 + rng.random_range(-0.3..0.3))
                            / n as f64;
                    Vec2::new(r * a.cos() + 0.3, r * a.sin() - 0.7)
                })
                .collect();
            let Ok(p) = ConvexPolygon::new(vertices) else {
                continue;
            };
            let p = if n == 4 {
                ConvexPolygon::rectangle(r, 0.5 * r).unwrap()
            } else {
                p
            };
            for k in 0..20 {
                let rot = Rot::new(if k == 0 {
                    0.0
                } else {
                    rng.random_range(-50.0..50.0)
                });
                for (t, nl) in p.tangents().iter().zip(p.normals()) {
                    let (tw, nw) = (rot.apply(*t), rot.apply(*nl));
                    assert_eq!((tw.x, tw.y), (-nw.y, nw.x));
                }
            }
        }
    }
}
