//! Scene loading off the UI thread, and the on-disk change check that
//! drives automatic reload. Each load runs on its own named thread and
//! reports through a channel; results carry a request number so a slow,
//! older load never replaces a newer one. While it runs, the stage it is in
//! (parsing, objects and meshes, BVH) is shared for the status line.

use crate::camera::Camera;
use crate::render::RenderSettings;
use crate::scene::{self, LoadStage, Scene};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime};

/// How often the scene file's modification time is checked.
pub const WATCH_INTERVAL: Duration = Duration::from_millis(500);

/// Name shown for the embedded scene.
pub const DEFAULT_SCENE_NAME: &str = "<default scene>";

/// A built scene, ready to share with the render thread.
pub struct ReadyScene {
    pub scene: Arc<Scene>,
    pub camera: Camera,
    pub settings: RenderSettings,
}

/// The outcome of one load request.
pub struct LoadResult {
    pub request: u64,
    /// `None` for the embedded default scene.
    pub path: Option<PathBuf>,
    /// The file's modification time when it was read.
    pub modified: Option<SystemTime>,
    /// The error is `SceneError`'s one-line `file:line: field: message`.
    pub outcome: Result<ReadyScene, String>,
    pub took: Duration,
}

pub struct SceneLoader {
    sender: Sender<LoadResult>,
    results: Receiver<LoadResult>,
    wake: Arc<dyn Fn() + Send + Sync>,
    threads: Vec<JoinHandle<()>>,
    next_request: u64,
    /// Newest request whose result has been handed out.
    applied_request: u64,
    /// The newest load's stage and when the load started.
    stage: Arc<Mutex<Option<(LoadStage, Instant)>>>,
}

impl SceneLoader {
    pub fn new(wake: Arc<dyn Fn() + Send + Sync>) -> Self {
        let (sender, results) = mpsc::channel();
        Self {
            sender,
            results,
            wake,
            threads: Vec::new(),
            next_request: 0,
            applied_request: 0,
            stage: Arc::new(Mutex::new(None)),
        }
    }

    /// Starts loading `path` (or the default scene) on a background thread.
    pub fn load(&mut self, path: Option<PathBuf>) -> Result<(), std::io::Error> {
        self.next_request += 1;
        let request = self.next_request;
        let sender = self.sender.clone();
        let wake = Arc::clone(&self.wake);
        let stage = Arc::clone(&self.stage);
        self.threads.retain(|thread| !thread.is_finished());
        let thread = std::thread::Builder::new().name("prism-scene-loader".into()).spawn(move || {
            let start = Instant::now();
            let modified = path.as_deref().and_then(modified_time);
            let report = |now: LoadStage| {
                *stage.lock().unwrap_or_else(PoisonError::into_inner) = Some((now, start));
                wake();
            };
            let loaded = match &path {
                Some(path) => scene::load_scene_file_with_progress(path, &report),
                None => scene::load_scene_str(scene::DEFAULT_SCENE, Path::new(DEFAULT_SCENE_NAME), Path::new(".")),
            };
            let outcome = loaded
                .map(|loaded| ReadyScene {
                    scene: Arc::new(loaded.scene),
                    camera: loaded.camera,
                    settings: loaded.settings,
                })
                .map_err(|error| error.to_string());
            let _ = sender.send(LoadResult {
                request,
                path,
                modified,
                outcome,
                took: start.elapsed(),
            });
            wake();
        })?;
        self.threads.push(thread);
        Ok(())
    }

    /// Whether a requested load has not reported yet.
    pub fn busy(&self) -> bool {
        self.applied_request < self.next_request
    }

    /// While busy: the stage of the newest load and how long it has run.
    pub fn stage(&self) -> Option<(LoadStage, Duration)> {
        if !self.busy() {
            return None;
        }
        let stage = *self.stage.lock().unwrap_or_else(PoisonError::into_inner);
        stage.map(|(stage, start)| (stage, start.elapsed()))
    }

    /// The newest finished load, if one arrived; superseded ones are dropped.
    pub fn poll(&mut self) -> Option<LoadResult> {
        let mut newest: Option<LoadResult> = None;
        for result in self.results.try_iter() {
            if result.request > self.applied_request {
                self.applied_request = result.request;
                newest = Some(result);
            }
        }
        newest
    }
}

impl Drop for SceneLoader {
    fn drop(&mut self) {
        for thread in self.threads.drain(..) {
            let _ = thread.join();
        }
    }
}

/// The file's modification time, if it can be read.
pub fn modified_time(path: &Path) -> Option<SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

/// Polls a file's modification time at most every [`WATCH_INTERVAL`].
#[derive(Debug, Default)]
pub struct FileWatch {
    pub path: Option<PathBuf>,
    /// Modification time of the version last loaded (or attempted).
    pub seen: Option<SystemTime>,
    last_check: Option<Instant>,
}

impl FileWatch {
    pub fn watch(&mut self, path: Option<PathBuf>, seen: Option<SystemTime>) {
        self.path = path;
        self.seen = seen;
        self.last_check = Some(Instant::now());
    }

    /// True once when the watched file's modification time changed.
    pub fn changed(&mut self, now: Instant) -> bool {
        let Some(path) = &self.path else {
            return false;
        };
        if self.last_check.is_some_and(|last| now.duration_since(last) < WATCH_INTERVAL) {
            return false;
        }
        self.last_check = Some(now);
        let modified = modified_time(path);
        if modified.is_some() && modified != self.seen {
            self.seen = modified;
            return true;
        }
        false
    }
}
