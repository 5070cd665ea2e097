//! Files from the UI: the snapshot save (button, Ctrl+S, or the path field
//! when no file dialog can open) and the open-scene dialog. Dialogs run on a
//! helper thread so the window keeps drawing while they are open.

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
    pub message: Option<(bool, String)>,
    pub dialog_unavailable: bool,
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
            (Some(path), DialogPurpose::Open) => self.load_scene(Some(path)),
            (None, _) if quick => {
                self.save.dialog_unavailable = true;
                self.save.message = Some((
                    false,
                    "The file dialog could not open: type a path in the field and press Save.".into(),
                ));
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
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        let frame: &Frame = &info.frame;
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
