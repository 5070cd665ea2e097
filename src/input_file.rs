//! Input files (scenes, meshes, textures, film parts): what must hold
//! before one is opened.

use std::path::Path;

/// Checks that `path` names a regular file (following links) before it is
/// opened: a directory, a device such as /dev/zero or a pipe would make a
/// reader fail obscurely, read forever or block. The error names the path.
pub fn regular_file(path: &Path) -> Result<(), String> {
    match not_a_regular_file(path) {
        Some(reason) => Err(format!("{}: {reason}", path.display())),
        None => Ok(()),
    }
}

/// Why `path` is not a regular file that can be read, without the path:
/// for callers whose errors name the file already.
pub fn not_a_regular_file(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Some("no such file".to_string()),
        Err(e) => Some(format!("cannot read: {e}")),
        Ok(m) if m.is_dir() => Some("is a directory, not a file".to_string()),
        Ok(m) if !m.is_file() => Some("is not a regular file (a device, pipe or socket)".to_string()),
        Ok(_) => None,
    }
}
