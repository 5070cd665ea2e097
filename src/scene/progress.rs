//! Loading a scene with progress reports, for a window that shows what a
//! big scene's load is doing (parsing, building objects and meshes, the BVH)
//! instead of a bare "Loading…".

use super::load::load_scene_file_reporting;
use super::{LoadedScene, SceneError};
use std::path::Path;

/// The stage a scene load is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadStage {
    /// Reading and parsing the scene file.
    Parsing,
    /// Building objects (reading meshes); `done` of `total` so far.
    Objects {
        /// Objects built so far.
        done: usize,
        /// Objects in the scene file.
        total: usize,
    },
    /// Building the BVH over this many primitives.
    Bvh {
        /// Primitives (shapes and triangles) the BVH is built over.
        primitives: usize,
    },
}

impl std::fmt::Display for LoadStage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LoadStage::Parsing => write!(f, "parsing"),
            LoadStage::Objects { done, total } => write!(f, "objects and meshes {done}/{total}"),
            LoadStage::Bvh { primitives } => write!(f, "building the BVH over {primitives} primitives"),
        }
    }
}

/// `load_scene_file`, calling `progress` as each stage begins.
pub fn load_scene_file_with_progress(path: &Path, progress: &dyn Fn(LoadStage)) -> Result<LoadedScene, SceneError> {
    load_scene_file_reporting(path, progress)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[test]
    fn a_load_reports_its_stages_in_order() {
        let stages = Mutex::new(Vec::new());
        let record = |stage| stages.lock().map(|mut s| s.push(stage)).unwrap_or(());
        load_scene_file_with_progress(Path::new("scenes/cornell.toml"), &record).expect("cornell loads");
        let stages = stages.into_inner().unwrap_or_default();
        assert_eq!(stages.first(), Some(&LoadStage::Parsing));
        // The Cornell box's eight objects are one primitive each.
        assert_eq!(stages.last(), Some(&LoadStage::Bvh { primitives: 8 }));
        assert!(stages.contains(&LoadStage::Objects { done: 0, total: 8 }), "{stages:?}");
    }
}
