//! The two ends of a parallel edge–edge overlap, each a vertex against the other polygon's edge
//! (§9.5).

use super::{Ctx, Side};
use crate::collide::VeCandidate;

impl Ctx {
    /// Edge–edge rule for edge `ea` of A and `eb` of B: the two ends of their overlap interval.
    ///
    /// In B's edge coordinate `s`, A's edge spans `[s_lo, s_hi]` (its endpoints `V_lo`, `V_hi`) and
    /// B's spans `[0, L_B]`. The low end of the overlap is `V_lo` (against `E_B`) if `s_lo ≥ 0`,
    /// else B's start vertex (against `E_A`); the high end is `V_hi` if `s_hi ≤ L_B`, else B's end
    /// vertex. With `strict`, the edges must be antiparallel within the near-parallel angle, the
    /// overlap longer than `ε_s` and both ends valid candidates, or nothing is pushed; otherwise
    /// each valid end is pushed. Returns whether two candidates were pushed.
    pub(super) fn edge_edge(
        &self,
        a: Side,
        ea: usize,
        b: Side,
        eb: usize,
        strict: bool,
        out: &mut Vec<VeCandidate>,
    ) -> bool {
        if strict && a.c.world_tangent(ea).dot(b.c.world_tangent(eb)) > -self.cos_parallel {
            return false;
        }
        let ea1 = a.c.local.next(ea);
        let eb1 = b.c.local.next(eb);
        let s0 = b.c.edge_coordinate(eb, a.c.world_vertices()[ea]);
        let s1 = b.c.edge_coordinate(eb, a.c.world_vertices()[ea1]);
        let ((v_lo, s_lo), (v_hi, s_hi)) = if s0 <= s1 {
            ((ea, s0), (ea1, s1))
        } else {
            ((ea1, s1), (ea, s0))
        };
        let lb = b.c.local.lengths()[eb];
        let overlap = s_hi.min(lb) - s_lo.max(0.0);
        if overlap < 0.0 || (strict && overlap <= self.eps_s) {
            return false;
        }
        // Each end: (true, vertex of A on E_B) or (false, vertex of B on E_A).
        let lo = if s_lo >= 0.0 {
            (true, v_lo)
        } else {
            (false, eb)
        };
        let hi = if s_hi <= lb {
            (true, v_hi)
        } else {
            (false, eb1)
        };
        let mark = out.len();
        let mut pushed = 0;
        for (a_vertex, v) in [lo, hi] {
            let ok = if a_vertex {
                self.push_if_valid(a, v, b, eb, out)
            } else {
                self.push_if_valid(b, v, a, ea, out)
            };
            pushed += ok as usize;
        }
        if strict && pushed < 2 {
            out.truncate(mark);
            return false;
        }
        pushed == 2
    }
}
