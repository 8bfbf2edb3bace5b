//! The read-outs of an impact solver's last solve, written once for both solvers.

/// Implements for the impact solver `$ty`, whose last solve had `self.n` rows (or contacts),
/// `len`, `is_empty` and, per `name => field`, a method `name` returning the first `n` entries of
/// the buffer `field` (each entry's doc comment says what it holds, with its unit).
macro_rules! last_solve_views {
    ($ty:ident, $rows:literal; $($(#[$m:meta])* $name:ident => $field:ident),+ $(,)?) => {
        impl $ty {
            #[doc = concat!("Number of ", $rows, " of the last solve.")]
            pub fn len(&self) -> usize {
                self.n
            }

            #[doc = concat!("True if the last solve had no ", $rows, ".")]
            pub fn is_empty(&self) -> bool {
                self.n == 0
            }

            $(
                $(#[$m])*
                pub fn $name(&self) -> &[f64] {
                    &self.$field[..self.n]
                }
            )+
        }
    };
}
pub(crate) use last_solve_views;
