//! Law parameters, declared once.
//!
//! Every normal law and friction model lists its parameters as [`ParamSpec`]s — scene-file key,
//! aliases, unit, rule, meaning — through [`law_params!`](crate::law_params). From that one list come:
//! `set_param` (key lookup, aliases, the set-time rules of switches and counts), the key list in
//! messages, the per-parameter range checks of `validate`, and the tables of docs/MODELS.md Part I
//! ([`markdown_tables`], checked against the document by a test). Checks that tie two parameters
//! together (`mu_s ≥ mu_k`) stay written out in the law's `validate`.

use std::fmt::Write as _;

/// What values a parameter accepts. Checked by [`validate`] (ranges) and by [`set`] (switches and
/// counts, which have no value to hold otherwise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rule {
    /// Any finite number.
    Finite,
    /// Finite and ≥ 0.
    NonNegative,
    /// Finite and > 0.
    Positive,
    /// ≥ 0, or +∞ (no bound).
    NonNegativeOrInfinite,
    /// Strictly between 0 and 1.
    OpenUnit,
    /// 0 (off) or 1 (on).
    Switch,
    /// A whole number ≥ 1.
    Count,
}

impl Rule {
    /// The rule in words, as messages and the MODELS tables print it.
    pub fn describe(self) -> &'static str {
        match self {
            Rule::Finite => "finite",
            Rule::NonNegative => "finite and ≥ 0",
            Rule::Positive => "finite and > 0",
            Rule::NonNegativeOrInfinite => "≥ 0 (or infinite)",
            Rule::OpenUnit => "strictly between 0 and 1",
            Rule::Switch => "0 or 1",
            Rule::Count => "a whole number ≥ 1",
        }
    }

    /// Whether `v` satisfies the rule.
    pub fn admits(self, v: f64) -> bool {
        match self {
            Rule::Finite => v.is_finite(),
            Rule::NonNegative => v.is_finite() && v >= 0.0,
            Rule::Positive => v.is_finite() && v > 0.0,
            Rule::NonNegativeOrInfinite => !v.is_nan() && v >= 0.0,
            Rule::OpenUnit => v.is_finite() && v > 0.0 && v < 1.0,
            Rule::Switch => v == 0.0 || v == 1.0,
            Rule::Count => v >= 1.0 && v.fract() == 0.0 && v <= u32::MAX as f64,
        }
    }
}

/// One parameter of a law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamSpec {
    /// The scene-file key (`[normal]`/`[friction]` tables, `set_param`, the display).
    pub key: &'static str,
    /// Other accepted spellings of the key.
    pub aliases: &'static [&'static str],
    /// SI unit as printed ("N/m", "N·s/m"); empty for a pure number.
    pub unit: &'static str,
    /// Accepted values.
    pub rule: Rule,
    /// What it is, in a few words.
    pub meaning: &'static str,
}

/// A law whose parameters are declared with [`law_params!`](crate::law_params).
pub trait Params {
    /// The law's name in messages (`paper`, `reset-integrator`, …).
    fn law_name(&self) -> &'static str;
    /// Its parameters, in the documented order.
    fn specs(&self) -> &'static [ParamSpec];
    /// The current value of the parameter `key` (a canonical key of [`Params::specs`]).
    fn get(&self, key: &str) -> f64;
    /// Stores `value` (already checked by [`set`]) under the canonical key `key`.
    fn put(&mut self, key: &str, value: f64);
}

/// The keys of `specs`, comma-separated, for messages ("kc, bc").
pub fn key_list(specs: &[ParamSpec]) -> String {
    specs.iter().map(|s| s.key).collect::<Vec<_>>().join(", ")
}

/// The spec that `key` names (canonical key or alias).
pub fn find(specs: &'static [ParamSpec], key: &str) -> Option<&'static ParamSpec> {
    specs
        .iter()
        .find(|s| s.key == key || s.aliases.contains(&key))
}

/// Sets the parameter `key` of `law` to `value`. An unknown key is an error listing the valid
/// ones; a switch or count that is not one is an error naming the rule. Ranges are checked by
/// [`validate`], so a scene can set parameters in any order.
pub fn set<L: Params + ?Sized>(law: &mut L, key: &str, value: f64) -> Result<(), String> {
    let Some(spec) = find(law.specs(), key) else {
        return Err(format!(
            "{}: unknown parameter `{key}`; valid parameters: {}",
            law.law_name(),
            key_list(law.specs())
        ));
    };
    if matches!(spec.rule, Rule::Switch | Rule::Count) && !spec.rule.admits(value) {
        return Err(format!(
            "{}: parameter `{}` must be {}, got {value}",
            law.law_name(),
            spec.key,
            spec.rule.describe()
        ));
    }
    law.put(spec.key, value);
    Ok(())
}

/// Checks every declared parameter of `law` against its rule; the error names the first bad one,
/// its rule and unit.
pub fn validate<L: Params + ?Sized>(law: &L) -> Result<(), String> {
    for spec in law.specs() {
        let v = law.get(spec.key);
        if !spec.rule.admits(v) {
            let unit = if spec.unit.is_empty() {
                String::new()
            } else {
                format!(" ({})", spec.unit)
            };
            return Err(format!(
                "{}: parameter `{}`{unit} must be {}, got {v}",
                law.law_name(),
                spec.key,
                spec.rule.describe()
            ));
        }
    }
    Ok(())
}

/// A value that a law stores for a parameter: `f64`, a switch (`bool`) or a count (`u32`).
pub trait ParamValue: Copy {
    /// As the `f64` that [`Params::get`] returns.
    fn to_param(self) -> f64;
    /// From a value that passed the parameter's [`Rule`].
    fn from_param(v: f64) -> Self;
}

impl ParamValue for f64 {
    fn to_param(self) -> f64 {
        self
    }
    fn from_param(v: f64) -> Self {
        v
    }
}

impl ParamValue for bool {
    fn to_param(self) -> f64 {
        if self {
            1.0
        } else {
            0.0
        }
    }
    fn from_param(v: f64) -> Self {
        v == 1.0
    }
}

impl ParamValue for u32 {
    fn to_param(self) -> f64 {
        self as f64
    }
    fn from_param(v: f64) -> Self {
        v as u32
    }
}

/// Declares a law's parameters once and implements [`Params`] for it.
///
/// ```ignore
/// law_params! { PaperLaw, "paper";
///     kc (self.kc) ["k"] "N/m" NonNegative "contact stiffness Kc",
///     bc (self.bc) ["b"] "N·s/m" NonNegative "contact damping Bc",
/// }
/// ```
/// Each entry: key, the place it is stored (any place expression on `self`), aliases, unit, rule,
/// meaning. A `name_fn` form takes an expression for laws whose name depends on the value
/// (`dahl` / `hayward-armstrong`).
#[macro_export]
macro_rules! law_params {
    (@place $s:ident, self . $($rest:tt)+) => { $s.$($rest)+ };
    (@impl $ty:ty, $name:expr; $($key:ident ($($place:tt)+) [$($alias:literal),*] $unit:literal $rule:ident $meaning:literal),+) => {
        impl $ty {
            /// This law's parameters (declared once; docs/MODELS.md Part I is generated from them).
            pub const SPECS: &'static [$crate::laws::params::ParamSpec] = &[
                $($crate::laws::params::ParamSpec {
                    key: stringify!($key),
                    aliases: &[$($alias),*],
                    unit: $unit,
                    rule: $crate::laws::params::Rule::$rule,
                    meaning: $meaning,
                }),+
            ];
        }
        impl $crate::laws::params::Params for $ty {
            fn law_name(&self) -> &'static str {
                let f: fn(&$ty) -> &'static str = $name;
                f(self)
            }
            fn specs(&self) -> &'static [$crate::laws::params::ParamSpec] {
                Self::SPECS
            }
            #[allow(unused_variables)]
            fn get(&self, key: &str) -> f64 {
                use $crate::laws::params::ParamValue as _;
                let s = self;
                $(if key == stringify!($key) {
                    return $crate::law_params!(@place s, $($place)+).to_param();
                })+
                f64::NAN
            }
            fn put(&mut self, key: &str, value: f64) {
                use $crate::laws::params::ParamValue;
                let s = self;
                $(if key == stringify!($key) {
                    let place = &mut $crate::law_params!(@place s, $($place)+);
                    *place = ParamValue::from_param(value);
                    return;
                })+
            }
        }
    };
    ($ty:ty, $name:expr; $($key:ident ($($place:tt)+) [$($alias:literal),*] $unit:literal $rule:ident $meaning:literal),+ $(,)?) => {
        $crate::law_params!(@impl $ty, |_s: &$ty| $name; $($key ($($place)+) [$($alias),*] $unit $rule $meaning),+);
    };
}

/// A row of a MODELS Part I table: the law's names, one line on what it is, its parameters and a
/// per-contact default instance.
pub struct TableRow {
    /// The names that select it (`seh` / `seh-pc`).
    pub names: &'static [&'static str],
    /// What it is, with its § reference.
    pub summary: &'static str,
    /// The per-contact default (its parameter values are the table's defaults).
    pub law: Box<dyn Params>,
    /// Keys outside the numeric declarations (e.g. `load_scaling`), printed after them.
    pub extra_keys: &'static str,
}

/// Formats a default value for the tables: `∞`, integers without a point, others as Rust prints.
fn fmt_default(v: f64) -> String {
    if v.is_infinite() {
        "∞".into()
    } else if v.fract() == 0.0 && v.abs() < 1e6 {
        format!("{v:.0}")
    } else {
        format!("{v}")
    }
}

/// The markdown table of `rows` (name | model | keys (units) | per-contact defaults).
pub fn markdown_table(rows: &[TableRow]) -> String {
    let mut out = String::from(
        "| name | model | keys (units; accepted values) | per-contact defaults |\n|---|---|---|---|\n",
    );
    for row in rows {
        let names = row
            .names
            .iter()
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(" / ");
        let specs = row.law.specs();
        let mut keys = specs
            .iter()
            .map(|s| {
                let mut k = format!("`{}`", s.key);
                for a in s.aliases {
                    let _ = write!(k, " (or `{a}`)");
                }
                let unit = if s.unit.is_empty() { "–" } else { s.unit };
                let _ = write!(k, " ({unit}; {})", s.rule.describe());
                k
            })
            .collect::<Vec<_>>()
            .join(", ");
        if !row.extra_keys.is_empty() {
            if !keys.is_empty() {
                keys.push_str(", ");
            }
            keys.push_str(row.extra_keys);
        }
        if keys.is_empty() {
            keys = "–".into();
        }
        let defaults = if specs.is_empty() {
            "–".to_string()
        } else {
            specs
                .iter()
                .map(|s| fmt_default(row.law.get(s.key)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let _ = writeln!(out, "| {names} | {} | {keys} | {defaults} |", row.summary);
    }
    out
}

/// The two tables of docs/MODELS.md Part I (normal laws, then friction models), each between
/// its `<!-- law-params:normal -->` / `<!-- law-params:friction -->` markers.
pub fn markdown_tables() -> (String, String) {
    (
        markdown_table(&super::normal::table_rows()),
        markdown_table(&super::friction::table_rows()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::friction::FrictionModel;
    use crate::laws::normal::{NormalModel, NORMAL_MODEL_NAMES};

    /// Replaces the text between `<!-- law-params:NAME -->` and `<!-- /law-params:NAME -->`.
    fn splice(doc: &str, name: &str, table: &str) -> Option<String> {
        let open = format!("<!-- law-params:{name} -->\n");
        let close = format!("<!-- /law-params:{name} -->");
        let a = doc.find(&open)? + open.len();
        let b = doc[a..].find(&close)? + a;
        Some(format!("{}{table}{}", &doc[..a], &doc[b..]))
    }

    /// docs/MODELS.md Part I prints the declarations; `HAPTIC2D_BLESS_DOCS=1` rewrites it.
    #[test]
    fn models_md_part_one_tables_are_the_declared_parameters() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/MODELS.md");
        let doc = std::fs::read_to_string(path).expect("docs/MODELS.md");
        let (normal, friction) = markdown_tables();
        let want = splice(&doc, "normal", &normal)
            .and_then(|d| splice(&d, "friction", &friction))
            .expect("MODELS.md has the law-params:normal and law-params:friction markers");
        if std::env::var_os("HAPTIC2D_BLESS_DOCS").is_some() {
            std::fs::write(path, &want).expect("write docs/MODELS.md");
            return;
        }
        assert!(
            doc == want,
            "docs/MODELS.md Part I is out of date with the law declarations; run \
             HAPTIC2D_BLESS_DOCS=1 cargo test -p haptic2d --lib models_md"
        );
    }

    #[test]
    fn every_declared_key_and_alias_sets_the_value_it_reads_back() {
        for name in NORMAL_MODEL_NAMES {
            let mut m = NormalModel::from_name(name, true).expect("known");
            for s in m.specs() {
                let v = if s.rule == Rule::Switch { 1.0 } else { 3.0 };
                for key in std::iter::once(&s.key).chain(s.aliases) {
                    m.set_param(key, v).expect("declared key");
                    m.validate().expect("in range");
                }
            }
        }
        for name in FrictionModel::NAMES {
            let mut m = FrictionModel::from_name(name, true).expect("known");
            for s in m.specs() {
                // 0.5 is in every friction rule's range; mu_s ≥ mu_k holds with both 0.5.
                m.set_param(s.key, 0.5).expect("declared key");
            }
            m.validate().expect("in range");
        }
    }

    #[test]
    fn a_value_outside_its_rule_is_refused_naming_key_rule_and_unit() {
        let mut m = NormalModel::from_name("paper", true).expect("known");
        m.set_param("bc", -1.0)
            .expect("ranges are checked by validate");
        let e = m.validate().unwrap_err();
        assert!(
            e.contains("`bc`") && e.contains("N·s/m") && e.contains("≥ 0"),
            "{e}"
        );
        let mut p = NormalModel::from_name("pulse", true).expect("known");
        let e = p.set_param("n_p", 0.5).unwrap_err();
        assert!(e.contains("whole number"), "{e}");
        let mut s = NormalModel::from_name("seh", true).expect("known");
        assert!(s.set_param("corrector", 0.5).is_err());
        s.set_param("corrector", 1.0).expect("a switch");
        assert_eq!(s.name(), "seh-pc");
        let mut f = FrictionModel::from_name("dahl", true).expect("known");
        f.set_param("r_stick", 1.0).expect("set");
        let e = f.validate().unwrap_err();
        assert!(e.contains("'dahl'") && e.contains("`r_stick`"), "{e}");
        let e = f.set_param("kr", 1.0).unwrap_err();
        assert!(e.contains("valid parameters: k, mu_k, r_stick"), "{e}");
    }
}
