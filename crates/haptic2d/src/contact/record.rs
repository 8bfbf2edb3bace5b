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
///
/// **Layout** (`repr(C)`: 256 bytes, 8-byte aligned, so the four 64-byte groups below are cache
/// lines only where the vector's buffer happens to be line-aligned; issue 42 item 1,
/// docs/perf-s33-layout.md). The fields are ordered by the passes of a settled sample that read
/// them: lines 0 and 1 hold what both the merge-and-measure pass (`manager/sync.rs`) and the
/// force pass read, line 2 what only the force pass reads with the crossing-corner stage's
/// remembered own-axis test (`manager/clip.rs`, which reads lines 0 and 2), line 3 what only the
/// merge reads (the key and the body-frame geometry): each of the two heavy passes reads three
/// lines of four. The tick and the entry point, read only where a record is created, fill line 2.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct VeContact {
    // Line 0 (bytes 0..64): every pass.
    /// `None` while only tracked; `Some(state)` for a contact record.
    pub state: Option<ContactState>,
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
    /// Slot of this record's [`LawState`] in the contact set's pool (see
    /// [`ContactSet::laws`](super::ContactSet::laws)); [`NO_LAW`] while only tracked.
    pub law: u32,
    /// Body owning the vertex ("A").
    pub body_a: usize,
    /// Body owning the edge ("B").
    pub body_b: usize,
    /// Normal relative velocity `C0` (m/s), positive when separating.
    pub c0: f64,
    /// Tangential slip velocity `S0` (m/s).
    pub s0: f64,
    /// Signed-distance history (m): `d[0] = d_k`, `d[1] = d_{k−1}`, `d[2] = d_{k−2}`.
    pub d: [f64; 3],
    // Line 1 (bytes 64..128): the merge and the force pass.
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
    /// Normal force of the last sample (N).
    pub f_n: f64,
    // Line 2 (bytes 128..192): the force pass and the crossing-corner stage.
    /// Effective mass behind the contact for the braking pulse (kg).
    pub m_eff: f64,
    /// Friction force on A along `+t` of the last sample (N).
    pub f_t: f64,
    /// God-object edge coordinate `s_g` in B's frame (m), §8.3.
    pub s_g: f64,
    /// The crossing-corner stage's own-axis test, remembered (`contact/manager/clip.rs`): the
    /// relative angle `θ_A − θ_B` (rad) at which it was last computed, the excess (m) it found
    /// there (the overlap along the record's normal less the record's own depth), and the vertex
    /// collider's radius (m) its bound uses. NaN: not yet, or a pair with seams (never
    /// remembered).
    pub own_axis: (f64, f64, f64),
    /// Entry point: the edge coordinate where the vertex crossed the edge line at creation (m), §8.3.
    pub s_entry: f64,
    /// Tick at which this entry was first tracked.
    pub since: u64,
    // Line 3 (bytes 192..256): the merge.
    /// Identity: (vertex collider, vertex, edge collider, edge).
    pub key: VeCandidate,
    /// The pair's geometry in the bodies' own frames (fixed for the life of the entry).
    pub local: LocalGeom,
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
    use super::VeContact;
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

    /// The cache lines (64 bytes) a field at `offset` spans in a record.
    fn lines<T>(offset: usize, _field: fn(&VeContact) -> &T) -> std::ops::RangeInclusive<usize> {
        offset / 64..=(offset + std::mem::size_of::<T>() - 1) / 64
    }

    /// The lines of a field of `VeContact`, by name.
    macro_rules! lines_of {
        ($field:ident) => {
            lines(std::mem::offset_of!(VeContact, $field), |e| &e.$field)
        };
    }

    /// A record is four whole cache lines, and the fields each pass of a settled sample reads
    /// sit in the lines its layout documents: the merge-and-measure pass (`manager/sync.rs`,
    /// `measure` and the merge's tests) in lines 0, 1 and 3; the force pass
    /// (`manager/forces.rs`; the key aside, read only when the loaded list changes) in lines
    /// 0–2; the crossing-corner stage's remembered test (`manager/clip.rs`) in lines 0 and 2.
    #[test]
    fn a_record_is_four_cache_lines_with_each_pass_fields_in_its_lines() {
        assert_eq!(std::mem::size_of::<VeContact>(), 256);
        assert_eq!(std::mem::align_of::<VeContact>(), 8);
        let sync = [
            lines_of!(key),
            lines_of!(body_a),
            lines_of!(body_b),
            lines_of!(state),
            lines_of!(d),
            lines_of!(hist),
            lines_of!(nearest_edge),
            lines_of!(s),
            lines_of!(s_prev),
            lines_of!(len),
            lines_of!(point),
            lines_of!(n),
            lines_of!(c0),
            lines_of!(s0),
            lines_of!(local),
        ];
        let forces = [
            lines_of!(state),
            lines_of!(law),
            lines_of!(d),
            lines_of!(hist),
            lines_of!(c0),
            lines_of!(s0),
            lines_of!(m_eff),
            lines_of!(f_n),
            lines_of!(f_t),
            lines_of!(s),
            lines_of!(s_prev),
            lines_of!(s_g),
            lines_of!(len),
            lines_of!(loaded),
            lines_of!(body_a),
            lines_of!(body_b),
            lines_of!(point),
            lines_of!(n),
        ];
        let clip = [
            lines_of!(state),
            lines_of!(body_a),
            lines_of!(body_b),
            lines_of!(own_axis),
        ];
        let passes: [(&str, &[_], &[usize]); 3] = [
            ("merge", &sync, &[0, 1, 3]),
            ("forces", &forces, &[0, 1, 2]),
            ("clip", &clip, &[0, 2]),
        ];
        for (pass, fields, allowed) in passes {
            for (i, l) in fields.iter().enumerate() {
                assert!(
                    l.clone().all(|line| allowed.contains(&line)),
                    "{pass}: field {i} in lines {l:?}"
                );
            }
        }
    }
}
