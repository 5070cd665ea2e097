//! Files from the UI: the snapshot save (button, Ctrl+S, or the path field
//! when no file dialog can open), opening a scene (its own path field, the
//! recent files and the shipped scenes, or the system dialog when there is
//! one) and loading a reference image. Dialogs run on a helper thread so the
//! window keeps drawing while they are open.

use super::app::ViewerApp;
use crate::film::Frame;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A file dialog that closes faster than this without a path did not
/// really open (no desktop portal, no zenity): offer the path field instead.
const DIALOG_FAILED_WITHIN: Duration = Duration::from_millis(300);

/// Snapshot saving: the dialog runs on its own thread; the path field is
/// the fallback when it cannot open.
pub(super) struct SaveState {
    pub path_text: String,
    /// Save the denoised preview rather than the raw image (off unless asked).
    pub denoised: bool,
    pub message: Option<(bool, String)>,
    pub dialog_unavailable: bool,
}

/// Recently opened scenes kept, newest first.
const RECENT_SCENES: usize = 8;

/// Opening a scene from the window.
pub(super) struct OpenState {
    /// The scene path field.
    pub path_text: String,
    /// Recently opened scene files, newest first.
    pub recent: Vec<PathBuf>,
    /// Where `recent` is kept between sessions.
    recent_file: Option<PathBuf>,
    /// The scene files that ship with Prism (`scenes/*.toml`), if found.
    pub shipped: Vec<PathBuf>,
    pub message: Option<String>,
    /// Give the path field the keyboard on the next frame.
    pub focus_path: bool,
}

impl OpenState {
    pub fn new(recent_file: Option<PathBuf>, initial: Option<&Path>) -> Self {
        let recent = recent_file
            .as_deref()
            .and_then(|file| std::fs::read_to_string(file).ok())
            .map(|text| text.lines().filter(|l| !l.trim().is_empty()).map(PathBuf::from).collect())
            .unwrap_or_default();
        Self {
            path_text: initial.map_or_else(String::new, |p| p.display().to_string()),
            recent,
            recent_file,
            shipped: shipped_scenes(),
            message: None,
            focus_path: false,
        }
    }

    /// Puts `path` first in the recent list and saves the list (best effort:
    /// a read-only home only loses the list).
    pub fn remember(&mut self, path: &Path) {
        let path = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        self.recent.retain(|p| *p != path);
        self.recent.insert(0, path);
        self.recent.truncate(RECENT_SCENES);
        if let Some(file) = &self.recent_file {
            let text: String = self.recent.iter().map(|p| format!("{}\n", p.display())).collect();
            if let Some(folder) = file.parent() {
                let _ = std::fs::create_dir_all(folder);
            }
            let _ = std::fs::write(file, text);
        }
    }
}

/// `$XDG_CONFIG_HOME/prism/recent-scenes` (or `~/.config/…`), if a home is known.
pub fn default_recent_file() -> Option<PathBuf> {
    let config = std::env::var_os("XDG_CONFIG_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|home| PathBuf::from(home).join(".config")))?;
    Some(config.join("prism").join("recent-scenes"))
}

/// `scenes/*.toml` in the working directory, or else in the source tree
/// Prism was built from.
fn shipped_scenes() -> Vec<PathBuf> {
    let candidates = [PathBuf::from("scenes"), Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")];
    for folder in candidates {
        let Ok(entries) = std::fs::read_dir(&folder) else {
            continue;
        };
        let mut scenes: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        if !scenes.is_empty() {
            scenes.sort();
            return scenes;
        }
    }
    Vec::new()
}

/// A file dialog running on a helper thread.
pub(super) struct Dialog {
    purpose: DialogPurpose,
    opened: Instant,
    result: Receiver<Option<PathBuf>>,
    pub thread: Option<JoinHandle<()>>,
}

#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum DialogPurpose {
    Save,
    Open,
}

impl ViewerApp {
    pub(super) fn open_save_dialog(&mut self) {
        self.open_dialog(DialogPurpose::Save);
    }

    pub(super) fn open_scene_dialog(&mut self) {
        self.open_dialog(DialogPurpose::Open);
    }

    /// Opens the scene typed in the path field; says why not if it cannot.
    pub fn open_scene_path(&mut self) {
        let text = self.open.path_text.trim().to_string();
        if text.is_empty() {
            self.open.message = Some("Type the path of a scene file (.toml).".into());
            return;
        }
        let path = PathBuf::from(&text);
        if let Some(reason) = crate::input_file::not_a_regular_file(&path) {
            self.open.message = Some(format!("{text}: {reason}"));
            return;
        }
        self.open.message = None;
        self.log.event(&format!("opening {text} from the path field"));
        self.load_scene(Some(path));
    }

    /// Loads the image in the reference path field as the A/B reference.
    pub(super) fn load_reference(&mut self) {
        let text = self.reference_path_text.trim().to_string();
        match crate::output::load_frame(Path::new(&text)) {
            Ok(frame) => {
                self.reference = Some(super::display::Reference {
                    name: text,
                    frame: std::sync::Arc::new(frame),
                });
                self.save.message = None;
            }
            // The error names the file.
            Err(error) => self.save.message = Some((false, format!("reference {error}"))),
        }
    }

    pub(super) fn open_dialog(&mut self, purpose: DialogPurpose) {
        if self.dialog.is_some() {
            return;
        }
        let (sender, result) = mpsc::channel();
        let file_name = Path::new(&self.save.path_text)
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "prism.png".into());
        let spawned = std::thread::Builder::new().name("prism-file-dialog".into()).spawn(move || {
            let path = match purpose {
                DialogPurpose::Save => rfd::FileDialog::new()
                    .set_title("Save snapshot")
                    .add_filter("PNG image", &["png"])
                    .add_filter("BMP image", &["bmp"])
                    .add_filter("OpenEXR image (linear)", &["exr"])
                    .set_file_name(file_name)
                    .save_file(),
                DialogPurpose::Open => rfd::FileDialog::new()
                    .set_title("Open scene")
                    .add_filter("Prism scene", &["toml"])
                    .pick_file(),
            };
            let _ = sender.send(path);
        });
        match spawned {
            Ok(thread) => {
                self.dialog = Some(Dialog {
                    purpose,
                    opened: Instant::now(),
                    result,
                    thread: Some(thread),
                })
            }
            Err(_) => self.save.dialog_unavailable = true,
        }
    }

    pub(super) fn poll_dialog(&mut self) {
        let Some(dialog) = &mut self.dialog else {
            return;
        };
        let Ok(path) = dialog.result.try_recv() else {
            return;
        };
        let purpose = dialog.purpose;
        let quick = dialog.opened.elapsed() < DIALOG_FAILED_WITHIN;
        if let Some(thread) = dialog.thread.take() {
            let _ = thread.join();
        }
        self.dialog = None;
        match (path, purpose) {
            (Some(path), DialogPurpose::Save) => {
                self.save.path_text = path.display().to_string();
                self.save_snapshot(&path);
            }
            (Some(path), DialogPurpose::Open) => {
                self.open.path_text = path.display().to_string();
                self.load_scene(Some(path));
            }
            (None, DialogPurpose::Save) if quick => {
                self.save.dialog_unavailable = true;
                self.save.message = Some((
                    false,
                    "No file dialog here: type a path in the snapshot field and press Save.".into(),
                ));
            }
            (None, DialogPurpose::Open) if quick => {
                self.open.focus_path = true;
                self.open.message =
                    Some("No file dialog here: type the scene's path above and press Open, or pick one from the list.".into());
            }
            (None, _) => {}
        }
    }

    /// Writes the displayed frame (atomically) with the render's settings in its metadata.
    pub fn save_snapshot(&mut self, path: &Path) {
        let Some(info) = &self.display.frame else {
            self.save.message = Some((false, "Nothing rendered yet.".into()));
            return;
        };
        let stats = &self.display.stats;
        let settings = &info.settings;
        // The raw image unless the denoised preview was asked for (and exists at this size).
        let denoised = self
            .display
            .denoised
            .as_ref()
            .map(|d| &d.frame)
            .filter(|d| self.save.denoised && (d.width, d.height) == (info.frame.width, info.frame.height));
        let passes_name = if settings.integrator == crate::render::IntegratorKind::Sppm {
            "Iterations"
        } else {
            "Samples per pixel"
        };
        let metadata: Vec<(String, String)> = [
            ("Software", format!("prism {} viewer", env!("CARGO_PKG_VERSION"))),
            ("Scene", self.scene_name()),
            ("Integrator", settings.integrator.to_string()),
            (passes_name, info.passes.to_string()),
            ("Render time", format!("{:.3} s", info.elapsed.as_secs_f64())),
            ("Seed", settings.seed.to_string()),
            ("Sampler", settings.sampler.to_string()),
            ("Max depth", settings.max_depth.to_string()),
            ("Resolution", format!("{}x{}", info.frame.width, info.frame.height)),
            ("Aperture radius", format!("{}", info.camera.aperture_radius)),
            ("Focal distance", format!("{}", info.camera.focal_distance)),
            ("Exposure", format!("{} stops, tone map {:?}", self.exposure, self.tone_map)),
            ("Status", stats.integrator_status.clone()),
            (
                "Denoised",
                if denoised.is_some() { "yes (display preview)" } else { "no" }.to_string(),
            ),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        let frame: &Frame = denoised.unwrap_or(&info.frame);
        self.save.message = Some(
            match crate::output::save_frame(frame, path, self.exposure, self.tone_map, &metadata) {
                Ok(()) => {
                    self.log.event(&format!("saved {}", path.display()));
                    (true, format!("Saved {}", path.display()))
                }
                Err(error) => (false, error.to_string()),
            },
        );
    }
}
