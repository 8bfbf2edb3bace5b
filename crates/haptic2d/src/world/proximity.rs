//! §0.5 step 3, the global proximity stage's schedule and the state it keeps between samples:
//! which samples run `collide/broad/` (periodic, spread, skipped or early), the proximate pairs in
//! use, the poses they were computed for, and the odometers that bound each body's motion.

use crate::body::Body;
use crate::collide::{speed_limit, BroadPhase, BroadStats, Collider, DEFAULT_DELTA_PROX};
use crate::geom::Pose;

use super::{point_motion, WorldParams};

/// The global proximity stage and its scheduling state.
#[derive(Clone, Debug)]
pub(super) struct Proximity {
    broad: BroadPhase,
    /// The proximate collider pairs in use (those of the last published update).
    pub(super) pairs: Vec<(u32, u32)>,
    /// The global stage may have written `pairs` since the local stage last read them (set by
    /// [`run`](Self::run), cleared once the local stage has read them).
    pub(super) pairs_written: bool,
    /// Largest vertex distance from the centre of mass, per body (m).
    pub(super) radius: Vec<f64>,
    /// Running bound on how far any point of each body has moved (m): `|Δp| + |Δθ|·ρ` between
    /// the poses of consecutive samples, however they changed (integration or a pose set from
    /// outside). The local stage skips separated pairs whose gap this cannot have closed.
    odometer: Vec<f64>,
    /// Poses at the last odometer reading (after [`read_odometers`](Self::read_odometers): the
    /// bodies' poses now).
    pub(super) odometer_poses: Vec<Pose>,
    /// Per body, the poses its pairs in the proximity set in use were decided for: those of the
    /// update that published the set, or of the body's last partial update.
    global_poses: Vec<Pose>,
    /// Body poses of the spread global update in progress (its snapshot).
    job_poses: Vec<Pose>,
    /// Number of whole global updates run early because many bodies had moved far.
    pub(super) early_updates: u64,
    /// Number of partial global updates (some bodies had moved far), and the bodies they updated.
    pub(super) partial_updates: u64,
    pub(super) partial_bodies: u64,
    /// Per body: whether it moved past the margin in this sample, and its motion since its
    /// global pose (m), as [`moved_past_margin`](Self::moved_past_margin) wrote them.
    moved: Vec<bool>,
    motion: Vec<f64>,
    /// Periodic global updates skipped because the published set was still exact, and whether
    /// the last periodic one was.
    pub(super) skipped_updates: u64,
    skipped_last_period: bool,
}

impl Proximity {
    /// The stage for `bodies` and `colliders` with margin `params.delta_prox` (the default margin
    /// if that one is invalid; scene validation reports it).
    pub(super) fn new(bodies: &[Body], colliders: &[Collider], params: &WorldParams) -> Self {
        let colliders_len = colliders.len().max(4);
        let mut radius = vec![0.0f64; bodies.len()];
        for c in colliders {
            radius[c.body] = radius[c.body].max(c.local.radius());
        }
        let poses: Vec<Pose> = bodies.iter().map(|b| b.pose).collect();
        Self {
            broad: BroadPhase::with_capacity(params.delta_prox, 8 * colliders_len).unwrap_or_else(
                |_| {
                    BroadPhase::with_capacity(DEFAULT_DELTA_PROX, 8 * colliders_len)
                        .expect("the default margin is valid")
                },
            ),
            // Room for a typical contact load, so the first contacts do not allocate on the hot path.
            pairs: Vec::with_capacity(8 * colliders_len),
            pairs_written: true,
            radius,
            odometer: vec![0.0; bodies.len()],
            odometer_poses: poses.clone(),
            job_poses: poses.clone(),
            global_poses: poses,
            early_updates: 0,
            partial_updates: 0,
            partial_bodies: 0,
            moved: vec![false; bodies.len()],
            motion: vec![0.0; bodies.len()],
            skipped_updates: 0,
            skipped_last_period: false,
        }
    }

    /// The margin in use `δ_prox` (m).
    pub(super) fn delta_prox(&self) -> f64 {
        self.broad.delta_prox()
    }

    /// Work counters of the last published update.
    pub(super) fn stats(&self) -> BroadStats {
        self.broad.stats()
    }

    /// The odometers: a running bound on how far any point of each body has moved (m), read
    /// by the global stage to skip GJK where the motion cannot have changed its result.
    pub(super) fn read_odometers(&mut self, bodies: &[Body]) {
        for ((odo, last), (b, &r)) in self
            .odometer
            .iter_mut()
            .zip(self.odometer_poses.iter_mut())
            .zip(bodies.iter().zip(&self.radius))
        {
            *odo += point_motion(last, &b.pose, r);
            *last = b.pose;
        }
    }

    /// §0.5 step 3, the global proximity stage (`collide/broad/`), scheduled by sample `tick`:
    ///
    /// - every `N_g`-th sample without spreading: the whole stage now (or none, when the set in
    ///   use is still exact: `skip_update`);
    /// - every `N_g`-th sample with spreading: publish the update begun `N_g` samples ago (the
    ///   whole stage now if none is in progress: the first sample, or after an early whole
    ///   update abandoned it) and begin the next one for the current poses;
    /// - with spreading, every sample that did not begin an update: advance the update in
    ///   progress by its share, so that it ends by the next `N_g`-th sample;
    /// - then, unless the whole stage ran now: the bodies that may have outrun the margin since
    ///   their global poses (`moved_past_margin`), and with them those past [`BATCH`] of it,
    ///   get their pairs decided again at the current poses (the partial update,
    ///   `collide/broad/partial.rs`); when more than
    ///   1/[`WHOLE_FRACTION`] of the dynamic bodies did, the whole stage runs instead (early,
    ///   and with spreading a new spread update begins).
    ///
    /// The global poses (`global_poses`) are per body: those of the update that published the
    /// set in use, or of the body's last partial update, so `moved_past_margin` measures each
    /// body's motion since its pairs were decided, whatever the delay.
    pub(super) fn run(
        &mut self,
        tick: u64,
        params: &WorldParams,
        bodies: &[Body],
        colliders: &[Collider],
    ) {
        let n_g = params.proximity_every.max(1) as u64;
        let phase = tick % n_g;
        let spread = params.proximity_spread && n_g > 1;
        if phase == 0 && self.periodic(params, bodies, colliders, spread) {
            return;
        }
        let moved = self.moved_past_margin(bodies, params);
        if moved.bodies > 0 && moved.bodies * WHOLE_FRACTION > moved.dynamic {
            self.whole(bodies, colliders);
            if spread {
                self.begin(bodies, colliders);
            }
            self.early_updates += 1;
            return;
        }
        if moved.bodies > 0 {
            self.broad
                .update_bodies(colliders, &self.moved, &self.motion, &mut self.pairs);
            self.pairs_written = true;
            for ((g, b), _) in self
                .global_poses
                .iter_mut()
                .zip(bodies)
                .zip(&self.moved)
                .filter(|(_, &m)| m)
            {
                *g = b.pose;
            }
            self.partial_updates += 1;
            self.partial_bodies += moved.bodies as u64;
        }
        if spread && phase != 0 {
            // The sample that began an update has done its share (`begin`, and publishing).
            self.broad.advance((n_g - phase) as usize);
        }
    }

    /// The `N_g`-th sample's part of [`run`](Self::run): publish the spread update in progress,
    /// skip, or run the whole stage; begin the next spread update. Returns whether the whole
    /// stage ran now (the set in use is then that of the poses now).
    fn periodic(
        &mut self,
        params: &WorldParams,
        bodies: &[Body],
        colliders: &[Collider],
        spread: bool,
    ) -> bool {
        let mut published = false;
        if spread && self.broad.in_progress() {
            self.broad.publish(&mut self.pairs);
            self.pairs_written = true;
            std::mem::swap(&mut self.global_poses, &mut self.job_poses);
            published = true;
        }
        // A periodic update whose result the colliders cannot have changed since the published
        // one is skipped (`BroadPhase::still_exact`, `skip_update`): the set in use is what it
        // would compute, or the published set with pairs of moved bodies decided again by
        // partial updates since, each of them as good for the margin rule.
        // `global_poses` keep their poses, which only makes the check for moved bodies stricter
        // than it needs to be.
        if params.proximity_skip && self.broad.skip_update(colliders) {
            self.skipped_updates += 1;
            self.skipped_last_period = true;
            return false;
        }
        // After a skip, the set in use is what the update of the last period would have
        // published now, so a spread update just begins, as after a publication.
        let after_skip = std::mem::take(&mut self.skipped_last_period) && spread;
        let whole = !published && !after_skip;
        if whole {
            self.whole(bodies, colliders);
        }
        if spread {
            self.begin(bodies, colliders);
        }
        whole
    }

    /// The whole stage now, for the current poses (abandons a spread update in progress).
    fn whole(&mut self, bodies: &[Body], colliders: &[Collider]) {
        self.broad
            .update_with_motion(colliders, &self.odometer, &mut self.pairs);
        self.pairs_written = true;
        for (g, b) in self.global_poses.iter_mut().zip(bodies) {
            *g = b.pose;
        }
    }

    /// Begins a spread update for the current poses.
    fn begin(&mut self, bodies: &[Body], colliders: &[Collider]) {
        self.broad.begin_with_motion(colliders, &self.odometer);
        for (g, b) in self.job_poses.iter_mut().zip(bodies) {
            *g = b.pose;
        }
    }

    /// Marks the bodies to update (`moved`): when some body may have moved, by the end of this
    /// sample, more than `(δ_prox − δ_c)/2` since its global pose, so that the proximity set may
    /// miss one of its pairs, every body that may have moved more than [`BATCH`] of that; none
    /// otherwise. Writes each body's motion since its global pose (`motion`, m).
    /// Returns how many bodies to update, how many of them moved past, and how many bodies are
    /// dynamic.
    ///
    /// A pair left out at the update that last decided it stays more than `δ_c` apart while
    /// neither body has moved more than `(δ_prox − δ_c)/2` since its global pose
    /// (`collide/broad/partial.rs`; for a whole update: it was at least `δ_prox` apart, §9.1, and
    /// its distance shrinks by at most the two bodies' point motions). Body `i`'s motion since
    /// its global pose is at most `D_i = |Δp_i| + |Δθ_i|·ρ_i` (`ρ_i` the body's vertex radius);
    /// this sample adds about `m_i = (|v_i| + |ω_i|·ρ_i)·T` (the velocity now; the integration
    /// changes it by `T·a`), so body `i` moved past when `D_i + m_i > (δ_prox − δ_c)/2`. Slow
    /// worlds (a pile at rest) never mark one; a body faster than `(δ_prox − δ_c)/(2·T)` is marked
    /// every sample and is beyond the guarantee
    /// ([`World::speed_warnings`](super::World::speed_warnings)). Costs one pass over the bodies.
    fn moved_past_margin(&mut self, bodies: &[Body], params: &WorldParams) -> Moved {
        let limit = speed_limit(self.broad.delta_prox(), params.delta_c);
        let dt = params.dt;
        let mut count = Moved::default();
        for ((b, g), ((&r, moved), motion)) in bodies.iter().zip(&self.global_poses).zip(
            self.radius
                .iter()
                .zip(self.moved.iter_mut())
                .zip(self.motion.iter_mut()),
        ) {
            let d = point_motion(g, &b.pose, r);
            *motion = d;
            let reach = d + (b.vel.length() + b.omega.abs() * r) * dt;
            *moved = b.is_dynamic() && reach > BATCH * limit;
            count.bodies += *moved as usize;
            count.past += (*moved && reach > limit) as usize;
            count.dynamic += b.is_dynamic() as usize;
        }
        if count.past == 0 {
            count.bodies = 0;
        }
        count
    }
}

/// Counts of [`Proximity::moved_past_margin`].
#[derive(Clone, Copy, Debug, Default)]
struct Moved {
    /// Bodies marked to update (0 when none moved past the margin).
    bodies: usize,
    /// Marked bodies that moved past the margin itself.
    past: usize,
    /// Dynamic bodies.
    dynamic: usize,
}

/// When some body moved past the margin, the bodies that moved more than this fraction of it
/// get their pairs decided again too: fewer samples then change the set (each change costs
/// the local stage a merge of its pairs), and deciding a body's pairs early is always safe.
const BATCH: f64 = 0.5;

/// When more than one in this many dynamic bodies are to be updated in a sample, the whole stage
/// runs instead of the partial update: on pile:1000's landing, 8 gave the fewest instructions of
/// the values measured (2 and 8; docs/archive/PERFORMANCE-NOTEBOOK.md, "Issue 42, session 31").
const WHOLE_FRACTION: usize = 8;
