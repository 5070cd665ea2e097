//! Scene errors that say where: file, line (when known) and field.

use std::fmt;
use std::path::PathBuf;

#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    pub file: PathBuf,
    pub line: Option<usize>,
    /// Dotted path of the offending key, e.g. `objects[3].radius`.
    pub field: Option<String>,
    pub message: String,
}

impl SceneError {
    pub fn new(file: impl Into<PathBuf>, line: Option<usize>, field: Option<String>, message: impl Into<String>) -> Self {
        Self {
            file: file.into(),
            line,
            field,
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        write!(f, ": ")?;
        if let Some(field) = &self.field {
            write!(f, "{field}: ")?;
        }
        // One line, always: TOML's multi-line diagnostics are folded.
        let message: Vec<&str> = self.message.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
        write!(f, "{}", message.join(" "))
    }
}

impl std::error::Error for SceneError {}

/// 1-based line of a byte offset.
pub fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}
