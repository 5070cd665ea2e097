//! Scene errors that say where: file, line and column (when known) and the
//! full path of the field, e.g. `scene.toml:34:10: objects[3].radius: must be
//! positive (found -1)`.

use std::fmt;
use std::path::PathBuf;

/// Where in a text a byte offset lies: 1-based line and column (columns count
/// characters, as editors do).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Location {
    /// Line, from 1.
    pub line: usize,
    /// Column in characters, from 1.
    pub column: usize,
}

impl Location {
    /// The line and column of byte `offset` in `text` (clamped to the text,
    /// and to the start of the character it falls in).
    pub fn of_offset(text: &str, offset: usize) -> Self {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &text[..offset];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Self {
            line: before.bytes().filter(|&b| b == b'\n').count() + 1,
            column: before[line_start..].chars().count() + 1,
        }
    }
}

/// A scene that could not be read, parsed, checked or built. It displays
/// as `file:line:column: field: message`, leaving out what is unknown.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The scene file, as named to the loader; problems in files it refers
    /// to (meshes, images) are reported at the field that names them.
    pub file: PathBuf,
    /// Where in the file, when known.
    pub location: Option<Location>,
    /// Full path of the offending key, e.g. `objects[3].radius`.
    pub field: Option<String>,
    /// What is wrong, for people.
    pub message: String,
}

impl SceneError {
    /// An error in `file`, at `location`, about `field`.
    pub fn new(file: impl Into<PathBuf>, location: Option<Location>, field: Option<String>, message: impl Into<String>) -> Self {
        Self {
            file: file.into(),
            location,
            field,
            message: message.into(),
        }
    }

    /// The 1-based line, when known.
    pub fn line(&self) -> Option<usize> {
        self.location.map(|l| l.line)
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(Location { line, column }) = self.location {
            write!(f, ":{line}:{column}")?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_count_characters_from_one() {
        let text = "a = 1\nbé = [1, x]\n";
        let x = text.find('x').unwrap_or_default();
        assert_eq!(Location::of_offset(text, x), Location { line: 2, column: 10 });
        assert_eq!(Location::of_offset(text, 0), Location { line: 1, column: 1 });
        assert_eq!(Location::of_offset(text, 10_000), Location { line: 3, column: 1 });
    }
}
