//! One declaration per law: its struct, its constructor and its parameter specs.
//!
//! A law's parameters used to be written three times (the struct's public fields, the
//! constructor's arguments, the [`law_params!`](crate::law_params) list); [`declare_law!`]
//! (crate::declare_law) takes them once.

/// Declares a law struct whose public fields are its parameters, followed by its private state,
/// with a constructor taking every parameter in order, and implements
/// [`Params`](crate::laws::params::Params) for it through [`law_params!`](crate::law_params).
///
/// ```ignore
/// declare_law! {
///     /// The law's doc.
///     pub struct ColgateLaw as "colgate" {
///         /// Wall stiffness `K` (N/m).
///         k: f64 [] "N/m" NonNegative "wall stiffness",
///         /// Virtual damping `B` (N·s/m).
///         b: f64 [] "N·s/m" Finite "virtual damping",
///     }
///     state {
///         /// Stored energy `½K·δ²` after the last sample (J).
///         stored: f64 = 0.0,
///     }
///     /// A wall of stiffness `k` (N/m) and virtual damping `b` (N·s/m).
///     pub fn new;
/// }
/// ```
/// A parameter entry: field (= scene-file key), type, aliases, unit, rule, meaning, as in
/// `law_params!`. A state entry: visibility, field, type and its initial value in the constructor
/// (an expression that may name the parameters). The struct derives `Clone, Copy, Debug,
/// PartialEq`. `named (CLOSURE)` instead of `as "name"` gives the name as a function of the law
/// (`dahl` / `hayward-armstrong`).
#[macro_export]
macro_rules! declare_law {
    (@struct $(#[$sm:meta])* $ty:ident, $namefn:expr;
        { $( $(#[$pm:meta])* $key:ident : $pt:ty [$($alias:literal),*] $unit:literal $rule:ident $meaning:literal ),+ $(,)? }
        { $( $(#[$fm:meta])* $fv:vis $field:ident : $ft:ty = $init:expr ),* $(,)? }
        $(#[$nm:meta])* $nv:vis $new:ident
    ) => {
        $(#[$sm])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $ty {
            $( $(#[$pm])* pub $key: $pt, )+
            $( $(#[$fm])* $fv $field: $ft, )*
        }
        impl $ty {
            $(#[$nm])*
            $nv fn $new($($key: $pt),+) -> Self {
                Self { $($key,)+ $($field: $init,)* }
            }
        }
        $crate::law_params!(@impl $ty, $namefn; $($key (self.$key) [$($alias),*] $unit $rule $meaning),+);
    };
    (
        $(#[$sm:meta])*
        pub struct $ty:ident as $name:literal { $($params:tt)+ }
        state { $($state:tt)* }
        $(#[$nm:meta])* $nv:vis fn $new:ident;
    ) => {
        $crate::declare_law!(@struct $(#[$sm])* $ty, |_s: &$ty| $name; { $($params)+ } { $($state)* } $(#[$nm])* $nv $new);
    };
    (
        $(#[$sm:meta])*
        pub struct $ty:ident named ($namefn:expr) { $($params:tt)+ }
        state { $($state:tt)* }
        $(#[$nm:meta])* $nv:vis fn $new:ident;
    ) => {
        $crate::declare_law!(@struct $(#[$sm])* $ty, $namefn; { $($params)+ } { $($state)* } $(#[$nm])* $nv $new);
    };
}
