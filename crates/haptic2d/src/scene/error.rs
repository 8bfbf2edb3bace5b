//! Scene errors: each names the field and says how to fix it.

use std::fmt;

/// One problem found in a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// The field concerned, as a path (e.g. `body[2].polygon`).
    pub field: String,
    /// What is wrong.
    pub message: String,
    /// How to fix it.
    pub fix: String,
}

impl SceneError {
    /// A new error.
    pub fn new(
        field: impl Into<String>,
        message: impl Into<String>,
        fix: impl Into<String>,
    ) -> Self {
        Self {
            field: field.into(),
            message: message.into(),
            fix: fix.into(),
        }
    }
}

impl SceneError {
    /// The error for TOML text `text` that does not parse (`e`): the field is the line of the
    /// problem (`line N`, or `file` when the parser gives no position).
    pub fn from_toml(text: &str, e: &toml::de::Error, fix: impl Into<String>) -> Self {
        let field = e
            .span()
            .map(|sp| {
                let line = text[..sp.start.min(text.len())].matches('\n').count() + 1;
                format!("line {line}")
            })
            .unwrap_or_else(|| "file".into());
        Self::new(field, e.message().trim_end(), fix)
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.message)?;
        if !self.fix.is_empty() {
            write!(f, "\n    fix: {}", self.fix)?;
        }
        Ok(())
    }
}

/// Every problem found in one scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneErrors {
    /// The file (or built-in scene name) the errors belong to.
    pub source: String,
    /// The problems, in file order.
    pub errors: Vec<SceneError>,
}

impl fmt::Display for SceneErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.errors.len();
        writeln!(
            f,
            "{}: {} problem{} found",
            self.source,
            n,
            if n == 1 { "" } else { "s" }
        )?;
        for e in &self.errors {
            writeln!(f, "  - {e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for SceneErrors {}
