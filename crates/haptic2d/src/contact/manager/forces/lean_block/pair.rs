//! Two `f64` lanes with the IEEE operations of the block force pass (`lean_block.rs`): SSE2
//! `f64x2` on x86-64 (the baseline target: every x86-64 processor has SSE2), two plain `f64`s
//! elsewhere. Each operation is the scalar one lane by lane, with the same bits:
//! `+ − × ÷` and negation are IEEE's; [`Pair::max0`] is `f64::max(x, 0.0)` as Rust compiles it
//! for x86-64 (`maxsd x, 0`: `x` if `x > 0`, else `+0.0`, so NaN and `−0.0` give `+0.0`, as
//! `f64::max` must or may); the comparisons are the ordered ones (false with a NaN).

use std::ops::{Add, Div, Mul, Neg, Sub};

/// Two lanes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pair(imp::V);

/// Which lanes of a comparison hold (all ones or all zeros in each lane's 64 bits).
#[derive(Clone, Copy, Debug)]
pub(super) struct Mask(imp::M);

#[cfg(target_arch = "x86_64")]
// SAFETY (every `unsafe` block of this module): the intrinsics need SSE2, which every x86-64
// target has enabled (it is part of the architecture's baseline), so they are always available;
// none of them touches memory.
mod imp {
    use std::arch::x86_64::*;
    pub(super) type V = __m128d;
    pub(super) type M = __m128d;

    #[inline(always)]
    pub(super) fn new(x: f64, y: f64) -> V {
        unsafe { _mm_setr_pd(x, y) }
    }
    #[inline(always)]
    pub(super) fn lanes(v: V) -> [f64; 2] {
        unsafe { [_mm_cvtsd_f64(v), _mm_cvtsd_f64(_mm_unpackhi_pd(v, v))] }
    }
    #[inline(always)]
    pub(super) fn splat(x: f64) -> V {
        unsafe { _mm_set1_pd(x) }
    }
    #[inline(always)]
    pub(super) fn add(a: V, b: V) -> V {
        unsafe { _mm_add_pd(a, b) }
    }
    #[inline(always)]
    pub(super) fn sub(a: V, b: V) -> V {
        unsafe { _mm_sub_pd(a, b) }
    }
    #[inline(always)]
    pub(super) fn mul(a: V, b: V) -> V {
        unsafe { _mm_mul_pd(a, b) }
    }
    #[inline(always)]
    pub(super) fn div(a: V, b: V) -> V {
        unsafe { _mm_div_pd(a, b) }
    }
    #[inline(always)]
    pub(super) fn neg(a: V) -> V {
        unsafe { _mm_xor_pd(a, _mm_set1_pd(-0.0)) }
    }
    #[inline(always)]
    pub(super) fn max0(a: V) -> V {
        unsafe { _mm_max_pd(a, _mm_setzero_pd()) }
    }
    #[inline(always)]
    pub(super) fn gt(a: V, b: V) -> M {
        unsafe { _mm_cmpgt_pd(a, b) }
    }
    #[inline(always)]
    pub(super) fn lt(a: V, b: V) -> M {
        unsafe { _mm_cmplt_pd(a, b) }
    }
    #[inline(always)]
    pub(super) fn ge(a: V, b: V) -> M {
        unsafe { _mm_cmpge_pd(a, b) }
    }
    #[inline(always)]
    pub(super) fn le(a: V, b: V) -> M {
        unsafe { _mm_cmple_pd(a, b) }
    }
    #[inline(always)]
    pub(super) fn and(a: M, b: M) -> M {
        unsafe { _mm_and_pd(a, b) }
    }
    #[inline(always)]
    pub(super) fn or(a: M, b: M) -> M {
        unsafe { _mm_or_pd(a, b) }
    }
    #[inline(always)]
    pub(super) fn select(m: M, a: V, b: V) -> V {
        unsafe { _mm_or_pd(_mm_and_pd(m, a), _mm_andnot_pd(m, b)) }
    }
    #[inline(always)]
    pub(super) fn keep(m: M, a: V) -> V {
        unsafe { _mm_and_pd(m, a) }
    }
    #[inline(always)]
    pub(super) fn clear(m: M, a: V) -> V {
        unsafe { _mm_andnot_pd(m, a) }
    }
    #[inline(always)]
    pub(super) fn bits(m: M) -> [bool; 2] {
        let b = unsafe { _mm_movemask_pd(m) };
        [b & 1 != 0, b & 2 != 0]
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod imp {
    pub(super) type V = [f64; 2];
    pub(super) type M = [bool; 2];

    #[inline(always)]
    fn map(a: V, b: V, f: impl Fn(f64, f64) -> f64) -> V {
        [f(a[0], b[0]), f(a[1], b[1])]
    }
    #[inline(always)]
    fn test(a: V, b: V, f: impl Fn(f64, f64) -> bool) -> M {
        [f(a[0], b[0]), f(a[1], b[1])]
    }
    pub(super) fn new(x: f64, y: f64) -> V {
        [x, y]
    }
    pub(super) fn lanes(v: V) -> [f64; 2] {
        v
    }
    pub(super) fn splat(x: f64) -> V {
        [x; 2]
    }
    pub(super) fn add(a: V, b: V) -> V {
        map(a, b, |x, y| x + y)
    }
    pub(super) fn sub(a: V, b: V) -> V {
        map(a, b, |x, y| x - y)
    }
    pub(super) fn mul(a: V, b: V) -> V {
        map(a, b, |x, y| x * y)
    }
    pub(super) fn div(a: V, b: V) -> V {
        map(a, b, |x, y| x / y)
    }
    pub(super) fn neg(a: V) -> V {
        [-a[0], -a[1]]
    }
    pub(super) fn max0(a: V) -> V {
        [a[0].max(0.0), a[1].max(0.0)]
    }
    pub(super) fn gt(a: V, b: V) -> M {
        test(a, b, |x, y| x > y)
    }
    pub(super) fn lt(a: V, b: V) -> M {
        test(a, b, |x, y| x < y)
    }
    pub(super) fn ge(a: V, b: V) -> M {
        test(a, b, |x, y| x >= y)
    }
    pub(super) fn le(a: V, b: V) -> M {
        test(a, b, |x, y| x <= y)
    }
    pub(super) fn and(a: M, b: M) -> M {
        [a[0] && b[0], a[1] && b[1]]
    }
    pub(super) fn or(a: M, b: M) -> M {
        [a[0] || b[0], a[1] || b[1]]
    }
    pub(super) fn select(m: M, a: V, b: V) -> V {
        [
            if m[0] { a[0] } else { b[0] },
            if m[1] { a[1] } else { b[1] },
        ]
    }
    pub(super) fn keep(m: M, a: V) -> V {
        select(m, a, [0.0; 2])
    }
    pub(super) fn clear(m: M, a: V) -> V {
        select(m, [0.0; 2], a)
    }
    pub(super) fn bits(m: M) -> [bool; 2] {
        m
    }
}

impl Pair {
    /// `x` in the first lane, `y` in the second.
    #[inline(always)]
    pub(super) fn new(x: f64, y: f64) -> Self {
        Self(imp::new(x, y))
    }
    /// The two lanes.
    #[inline(always)]
    pub(super) fn lanes(self) -> [f64; 2] {
        imp::lanes(self.0)
    }
    /// `x` in both lanes.
    #[inline(always)]
    pub(super) fn splat(x: f64) -> Self {
        Self(imp::splat(x))
    }
    /// `f64::max(x, 0.0)` in each lane (module docs).
    #[inline(always)]
    pub(super) fn max0(self) -> Self {
        Self(imp::max0(self.0))
    }
    /// `self > o` in each lane.
    #[inline(always)]
    pub(super) fn gt(self, o: Self) -> Mask {
        Mask(imp::gt(self.0, o.0))
    }
    /// `self < o` in each lane.
    #[inline(always)]
    pub(super) fn lt(self, o: Self) -> Mask {
        Mask(imp::lt(self.0, o.0))
    }
    /// `self >= o` in each lane.
    #[inline(always)]
    pub(super) fn ge(self, o: Self) -> Mask {
        Mask(imp::ge(self.0, o.0))
    }
    /// `self <= o` in each lane.
    #[inline(always)]
    pub(super) fn le(self, o: Self) -> Mask {
        Mask(imp::le(self.0, o.0))
    }
}

impl Mask {
    /// Both conditions.
    #[inline(always)]
    pub(super) fn and(self, o: Self) -> Self {
        Self(imp::and(self.0, o.0))
    }
    /// Either condition.
    #[inline(always)]
    pub(super) fn or(self, o: Self) -> Self {
        Self(imp::or(self.0, o.0))
    }
    /// `a` where the mask holds, else `b` (bit for bit).
    #[inline(always)]
    pub(super) fn select(self, a: Pair, b: Pair) -> Pair {
        Pair(imp::select(self.0, a.0, b.0))
    }
    /// `a` where the mask holds, else `+0.0` (`select(a, 0.0)` in one operation).
    #[inline(always)]
    pub(super) fn keep(self, a: Pair) -> Pair {
        Pair(imp::keep(self.0, a.0))
    }
    /// `+0.0` where the mask holds, else `a` (`select(0.0, a)` in one operation).
    #[inline(always)]
    pub(super) fn clear(self, a: Pair) -> Pair {
        Pair(imp::clear(self.0, a.0))
    }
    /// Whether either lane holds.
    #[inline(always)]
    pub(super) fn any(self) -> bool {
        let [a, b] = self.bits();
        a || b
    }
    /// The mask's lanes.
    #[inline(always)]
    pub(super) fn bits(self) -> [bool; 2] {
        imp::bits(self.0)
    }
}

/// Implements a binary operator on [`Pair`] lane by lane with `imp`'s function.
macro_rules! lanewise {
    ($($tr:ident $m:ident),*) => {$(
        impl $tr for Pair {
            type Output = Pair;
            #[inline(always)]
            fn $m(self, o: Pair) -> Pair {
                Pair(imp::$m(self.0, o.0))
            }
        }
    )*};
}
lanewise!(Add add, Sub sub, Mul mul, Div div);

impl Neg for Pair {
    type Output = Pair;
    #[inline(always)]
    fn neg(self) -> Pair {
        Pair(imp::neg(self.0))
    }
}
