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

impl SceneErrors {
    /// The problems `errors` of the file (or built-in scene) `source`.
    pub(crate) fn new(source: &str, errors: Vec<SceneError>) -> Self {
        Self {
            source: source.to_string(),
            errors,
        }
    }

    /// `text`, the file `source`, read as TOML into a `T`; a syntax (or, for a typed `T`, a field)
    /// error is the file's one problem, with the fix `fix`.
    pub(crate) fn parse<T: serde::de::DeserializeOwned>(
        text: &str,
        source: &str,
        fix: impl Into<String>,
    ) -> Result<T, Self> {
        toml::from_str(text)
            .map_err(|e| Self::new(source, vec![SceneError::from_toml(text, &e, fix)]))
    }
}
