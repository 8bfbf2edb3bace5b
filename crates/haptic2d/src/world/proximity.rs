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
    /// Body poses the proximity set in use was computed for.
    global_poses: Vec<Pose>,
    /// Body poses of the spread global update in progress (its snapshot).
    job_poses: Vec<Pose>,
    /// Number of global updates run early because a body had moved far.
    pub(super) early_updates: u64,
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
    /// - early (a body may have outrun the margin since the poses of the set in use): the whole
    ///   stage now, for the current poses; with spreading on, a new spread update starts too;
    /// - every `N_g`-th sample without spreading: the whole stage now;
    /// - every `N_g`-th sample with spreading: publish the update begun `N_g` samples ago (the
    ///   whole stage now if none is in progress: the first sample, or after an early update was
    ///   abandoned) and begin the next one for the current poses;
    /// - with spreading, every sample that did not begin an update: advance the update in
    ///   progress by its share, so that it ends by the next `N_g`-th sample.
    ///
    /// The poses of the set in use (`global_poses`) are those of the update that produced it, so
    /// `moved_past_margin` measures the motion since then whatever the delay.
    pub(super) fn run(
        &mut self,
        tick: u64,
        params: &WorldParams,
        bodies: &[Body],
        colliders: &[Collider],
    ) {
        let n_g = params.proximity_every.max(1) as u64;
        let phase = tick % n_g;
        let periodic = phase == 0;
        let early = !periodic && self.moved_past_margin(bodies, params);
        let spread = params.proximity_spread && n_g > 1;
        let mut published = false;
        if periodic && spread && self.broad.in_progress() {
            self.broad.publish(&mut self.pairs);
            self.pairs_written = true;
            std::mem::swap(&mut self.global_poses, &mut self.job_poses);
            published = true;
        }
        if !(periodic || early) {
            // The sample that began an update has done its share (`begin`, and publishing).
            if spread {
                self.broad.advance((n_g - phase) as usize);
            }
            return;
        }
        // A periodic update whose result the colliders cannot have changed since the published
        // one is skipped (`BroadPhase::still_exact`, `skip_update`): the set in use is what it
        // would compute.
        // `global_poses` keep the poses of the published update, which only makes the early
        // update's check stricter than it needs to be.
        if periodic && params.proximity_skip && self.broad.skip_update(colliders) {
            self.skipped_updates += 1;
            self.skipped_last_period = true;
            return;
        }
        // After a skip, the set in use is what the update of the last period would have
        // published now, so a spread update just begins, as after a publication.
        let after_skip = std::mem::take(&mut self.skipped_last_period) && periodic && spread;
        if !published && !after_skip {
            self.broad
                .update_with_motion(colliders, &self.odometer, &mut self.pairs);
            self.pairs_written = true;
            for (g, b) in self.global_poses.iter_mut().zip(bodies) {
                *g = b.pose;
            }
            self.early_updates += early as u64;
        }
        if spread {
            self.broad.begin_with_motion(colliders, &self.odometer);
            for (g, b) in self.job_poses.iter_mut().zip(bodies) {
                *g = b.pose;
            }
        }
    }

    /// Whether a body may have moved, by the end of this sample, more than `(δ_prox − δ_c)/2`
    /// since the last global update, so that the proximity set may miss a pair.
    ///
    /// A pair left out at the update was at least `δ_prox` apart (§9.1); its distance shrinks by
    /// at most the sum of the two bodies' point motions, each at most `D_i = |Δp_i| + |Δθ_i|·ρ_i`
    /// since the update (`ρ_i` the body's vertex radius). While every `D_i ≤ (δ_prox − δ_c)/2` the
    /// pair is still more than `δ_c` apart, so it has no VE candidate yet. This sample adds about
    /// `m_i = (|v_i| + |ω_i|·ρ_i)·T` (the velocity now; the integration changes it by `T·a`), so
    /// the stage is re-run when `D_i + m_i > (δ_prox − δ_c)/2` for some body. Slow worlds (a
    /// pile) never trigger it; a body faster than `(δ_prox − δ_c)/(2·T)` re-runs it every sample
    /// and is beyond the guarantee ([`World::speed_warnings`](super::World::speed_warnings)).
    /// Costs one pass over the bodies.
    fn moved_past_margin(&self, bodies: &[Body], params: &WorldParams) -> bool {
        let limit = speed_limit(self.broad.delta_prox(), params.delta_c);
        let dt = params.dt;
        bodies
            .iter()
            .zip(&self.global_poses)
            .zip(&self.radius)
            .any(|((b, g), &r)| {
                b.is_dynamic() && {
                    let d = point_motion(g, &b.pose, r);
                    let m = (b.vel.length() + b.omega.abs() * r) * dt;
                    d + m > limit
                }
            })
    }
}
