//! The scene file as a spanned TOML document: every key and value keeps its
//! byte range, so any error can be placed at a file, line and column and
//! named by its full field path. Errors that come with a byte range (syntax,
//! type and unknown-key errors) are named by walking the document down to the
//! innermost value holding that range; errors found later about a field (a
//! range check, an unknown material) are placed by walking the document along
//! the field's path.
//!
//! TOML has no tagged unions, and serde's internally tagged enums buffer
//! their table and so lose every span inside it. [`Document::retagged`]
//! rewrites each `type = "sphere"` table into serde's externally tagged form
//! `{ sphere = { ... } }` with the original spans, so type errors inside an
//! object are still reported where they are written.

use super::error::{Location, SceneError};
use serde::Deserialize;
use std::fmt;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;
use toml::de::{DeTable, DeValue, Deserializer};

/// One step of a field path: a table key or an array index.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Segment {
    /// A table key, as written (unquoted).
    Key(String),
    /// A 0-based array index.
    Index(usize),
}

/// A field's full path, displayed as `objects[3].transform.scale` or
/// `materials."my glass".ior`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FieldPath(Vec<Segment>);

impl FieldPath {
    /// The document itself.
    pub fn root() -> Self {
        Self::default()
    }

    /// This path extended by a key.
    pub fn key(&self, key: &str) -> Self {
        let mut path = self.clone();
        path.0.push(Segment::Key(key.to_string()));
        path
    }

    /// This path extended by an array index.
    pub fn index(&self, index: usize) -> Self {
        let mut path = self.clone();
        path.0.push(Segment::Index(index));
        path
    }

    /// Whether this is the document itself (no segments).
    pub fn is_root(&self) -> bool {
        self.0.is_empty()
    }

    /// The steps from the document's root, outermost first.
    pub fn segments(&self) -> &[Segment] {
        &self.0
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, segment) in self.0.iter().enumerate() {
            match segment {
                Segment::Index(index) => write!(f, "[{index}]")?,
                Segment::Key(key) => {
                    if i > 0 {
                        f.write_str(".")?;
                    }
                    let bare = !key.is_empty() && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
                    if bare {
                        f.write_str(key)?;
                    } else {
                        write!(f, "{key:?}")?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// A parsed scene file with the spans of every key and value.
pub struct Document<'t> {
    text: &'t str,
    file: &'t Path,
    root: Spanned<DeValue<'t>>,
}

impl<'t> Document<'t> {
    /// Parses `text`; a syntax error is placed at its line and column and
    /// named by the innermost field the parser had reached.
    pub fn parse(text: &'t str, file: &'t Path) -> Result<Self, SceneError> {
        let (table, errors) = DeTable::parse_recoverable(text);
        let span = table.span();
        let document = Self {
            text,
            file,
            root: Spanned::new(span, DeValue::Table(table.into_inner())),
        };
        match errors.into_iter().next() {
            None => Ok(document),
            Some(error) => {
                let offset = error.span().map(|span| span.start);
                let mut error = document.error_at(error.span(), error.message());
                // Where the partial document holds nothing at the error (a
                // broken line is left out of it), name the field from the text.
                if let (None, Some(offset)) = (&error.field, offset) {
                    let path = path_from_text(text, offset);
                    error.field = (!path.is_root()).then(|| path.to_string());
                }
                // A parser that stopped inside an array may have recovered
                // elements that are not there; name the array, not an index.
                if let Some(field) = &mut error.field {
                    while field.ends_with(']') {
                        field.truncate(field.rfind('[').unwrap_or(field.len()));
                    }
                }
                Err(error)
            }
        }
    }

    /// The document's top-level table.
    pub fn root(&self) -> &Spanned<DeValue<'t>> {
        &self.root
    }

    /// An error about `path`, placed where the deepest existing part of the
    /// path is written (the table that lacks a key, for a missing one).
    pub fn error(&self, path: &FieldPath, message: impl Into<String>) -> SceneError {
        let location = self.span_of(path).map(|span| Location::of_offset(self.text, span.start));
        let field = (!path.is_root()).then(|| path.to_string());
        SceneError::new(self.file, location, field, message)
    }

    /// An error at a byte range, named by the innermost field holding it.
    /// serde's "missing field `x`" errors point at the table that lacks `x`;
    /// the key is added to the path.
    pub fn error_at(&self, span: Option<Range<usize>>, message: &str) -> SceneError {
        let Some(span) = span else {
            return SceneError::new(self.file, None, None, message);
        };
        let mut path = innermost(&self.root, &span, FieldPath::root()).unwrap_or_default();
        if let Some(missing) = quoted_after(message, "missing field `") {
            path = path.key(missing);
        }
        let field = (!path.is_root()).then(|| path.to_string());
        SceneError::new(self.file, Some(Location::of_offset(self.text, span.start)), field, message)
    }

    /// Deserializes `value` (a part of this document, or a retagged copy of
    /// one) into `T`, placing any error by its span.
    pub fn deserialize<T: for<'de> Deserialize<'de>>(&self, value: Spanned<DeValue<'t>>) -> Result<T, SceneError> {
        let span = value.span();
        let table = match value.into_inner() {
            DeValue::Table(table) => table,
            _ => return Err(self.error_at(Some(span), "expected a table")),
        };
        T::deserialize(Deserializer::from(Spanned::new(span, table))).map_err(|e| self.error_at(e.span(), e.message()))
    }

    /// A copy of the document in which every table under `arrays` (each an
    /// array of tables, like `objects`) and under `tables` (each a table of
    /// tables, like `materials`) has its `type = "kind"` key turned into the
    /// externally tagged form `{ kind = { ...the other keys... } }`.
    pub fn retagged(&self, arrays: &[&str], tables: &[&str]) -> Result<Spanned<DeValue<'t>>, SceneError> {
        let mut root = self.root.clone();
        let DeValue::Table(top) = root.get_mut() else {
            return Ok(root);
        };
        for &name in arrays {
            if let Some(value) = top.get_mut(name)
                && let DeValue::Array(items) = value.get_mut()
            {
                for (i, item) in items.iter_mut().enumerate() {
                    self.retag(item, &FieldPath::root().key(name).index(i))?;
                }
            }
        }
        for &name in tables {
            if let Some(value) = top.get_mut(name)
                && let DeValue::Table(entries) = value.get_mut()
            {
                for (key, item) in entries.iter_mut() {
                    self.retag(item, &FieldPath::root().key(name).key(key.get_ref()))?;
                }
            }
        }
        Ok(root)
    }

    /// `{ type = "kind", rest... }` → `{ kind = { rest... } }`; values that are
    /// not tables are left for serde to report.
    fn retag(&self, item: &mut Spanned<DeValue<'t>>, path: &FieldPath) -> Result<(), SceneError> {
        let span = item.span();
        let DeValue::Table(table) = item.get_mut() else {
            return Ok(());
        };
        let Some((_, kind)) = table.remove_entry("type") else {
            return Err(self.error(&path.key("type"), "missing field `type`"));
        };
        let kind_span = kind.span();
        let DeValue::String(name) = kind.into_inner() else {
            return Err(self.error(&path.key("type"), "must be a string naming the kind, e.g. type = \"sphere\""));
        };
        let rest = std::mem::take(table);
        let mut tagged = DeTable::new();
        tagged.insert(Spanned::new(kind_span, name), Spanned::new(span, DeValue::Table(rest)));
        *item.get_mut() = DeValue::Table(tagged);
        Ok(())
    }

    /// Span of the value at `path`, or of the deepest part of it that exists.
    fn span_of(&self, path: &FieldPath) -> Option<Range<usize>> {
        let mut value = &self.root;
        let mut span = None;
        for segment in path.segments() {
            let next = match (segment, value.get_ref()) {
                (Segment::Key(key), DeValue::Table(table)) => table.get(key.as_str()),
                (Segment::Index(index), DeValue::Array(items)) => items.get(*index),
                _ => None,
            };
            match next {
                Some(next) => {
                    value = next;
                    span = Some(next.span());
                }
                None => return span.or_else(|| Some(self.root.span())),
            }
        }
        span.or_else(|| Some(self.root.span()))
    }
}

/// The path of the innermost key or value in `value` whose span holds `span`.
fn innermost(value: &Spanned<DeValue<'_>>, span: &Range<usize>, path: FieldPath) -> Option<FieldPath> {
    match value.get_ref() {
        DeValue::Table(table) => {
            for (key, child) in table.iter() {
                let child_path = path.key(key.get_ref());
                if holds(&key.span(), span) {
                    return Some(child_path);
                }
                if let Some(found) = innermost(child, span, child_path) {
                    return Some(found);
                }
            }
        }
        DeValue::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                if let Some(found) = innermost(child, span, path.index(i)) {
                    return Some(found);
                }
            }
        }
        _ => {}
    }
    holds(&value.span(), span).then_some(path)
}

/// For a syntax error only: the table header in effect at `offset` (with
/// its index, for an array of tables) and the key its line assigns, read
/// from the text. A fallback for when the parser's partial document has
/// nothing at the error, so it need not handle every TOML form.
fn path_from_text(text: &str, offset: usize) -> FieldPath {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let mut path = FieldPath::root();
    let mut arrays: Vec<(String, usize)> = Vec::new();
    for line in text[..line_start].lines() {
        let line = line.trim();
        if let Some(name) = line.strip_prefix("[[").and_then(|rest| rest.split("]]").next()) {
            let name = name.trim().to_string();
            let index = match arrays.iter_mut().find(|(n, _)| *n == name) {
                Some((_, count)) => {
                    *count += 1;
                    *count - 1
                }
                None => {
                    arrays.push((name.clone(), 1));
                    0
                }
            };
            path = dotted(FieldPath::root(), &name).index(index);
        } else if let Some(name) = line.strip_prefix('[').and_then(|rest| rest.split(']').next()) {
            path = dotted(FieldPath::root(), name);
        }
    }
    match text[line_start..line_end].split_once('=') {
        Some((key, _)) if !key.trim().is_empty() && !key.contains(['[', '{', '#']) => dotted(path, key),
        _ => path,
    }
}

/// `path` extended by a dotted key as written (`a.b`, `"quoted key"`).
fn dotted(mut path: FieldPath, key: &str) -> FieldPath {
    for part in key.split('.') {
        let part = part.trim().trim_matches(['"', '\'']);
        if !part.is_empty() {
            path = path.key(part);
        }
    }
    path
}

/// Whether `outer` holds `inner` (an empty `inner` is a position: it may sit
/// at `outer`'s end, where a parser notices what is missing).
fn holds(outer: &Range<usize>, inner: &Range<usize>) -> bool {
    if inner.is_empty() {
        outer.start <= inner.start && inner.start <= outer.end && !outer.is_empty()
    } else {
        outer.start <= inner.start && inner.end <= outer.end
    }
}

/// The text between `prefix` and the next backquote in `message`.
fn quoted_after<'m>(message: &'m str, prefix: &str) -> Option<&'m str> {
    message.split_once(prefix)?.1.split('`').next()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_display_as_written_in_toml() {
        let path = FieldPath::root().key("objects").index(3).key("transform").key("scale");
        assert_eq!(path.to_string(), "objects[3].transform.scale");
        let quoted = FieldPath::root().key("materials").key("my glass").key("ior");
        assert_eq!(quoted.to_string(), "materials.\"my glass\".ior");
    }

    #[test]
    fn a_span_is_named_by_the_innermost_field_holding_it() {
        let text = "[camera]\nposition = [0, \"x\", 5]\n\n[[objects]]\nradius = 1\n";
        let file = Path::new("s.toml");
        let document = Document::parse(text, file).map_err(|e| e.to_string());
        let document = document.as_ref().expect("parses");
        let x = text.find("\"x\"").unwrap_or_default();
        let error = document.error_at(Some(x..x + 3), "invalid type");
        assert_eq!(error.to_string(), "s.toml:2:16: camera.position[1]: invalid type");
        let error = document.error(&FieldPath::root().key("objects").index(0).key("radius"), "too big");
        assert_eq!(error.to_string(), "s.toml:5:10: objects[0].radius: too big");
        // A syntax error the parser left out of its document is named from the text.
        let text = "[camera]\nposition = [0, 0, 5]\n[[objects]]\nradius = 1\n[[objects]]\nradius = 1.x\n";
        let error = Document::parse(text, file).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(
            error.starts_with("s.toml:6:12: objects[1].radius: invalid fraction"),
            "{error}"
        );
        // A missing key is placed at the table that lacks it.
        let error = document.error(&FieldPath::root().key("camera").key("look_at"), "missing");
        assert_eq!(error.to_string(), "s.toml:1:1: camera.look_at: missing");
    }
}
