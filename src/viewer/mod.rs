//! The interactive progressive viewer (egui/eframe; egui lives only in this
//! module). A [`RenderSession`](crate::render::session::RenderSession) renders
//! on its own thread; the UI thread only sends commands, uploads the latest
//! frame as a texture and lays out the panels, so it never waits on rendering.
//!
//! Every control is classified once (see `docs/viewer.md`): display-only
//! (exposure, tone map, view, zoom and pan, pixel readout, histogram, A/B
//! comparison, the denoised preview) re-maps the current frame; targets
//! (samples, time) and Pause/Stop/Resume keep the accumulation; sampling
//! (camera, integrator, depth, resolution, region) restarts accumulation and
//! keeps the `Arc<Scene>`; scene (open, drop, file changed) loads on a
//! background thread, then restarts.

mod app;
mod camera_input;
mod denoiser;
mod display;
mod event_log;
mod files;
mod image_view;
mod inputs;
mod inspect;
mod loader;
mod panels;
mod status;
mod texture;
mod watch;

pub use app::{ViewKind, ViewerApp};
pub use display::{CompareMode, DenoiseMode};
pub use watch::{WatchApp, run_watch};

use std::path::PathBuf;
use std::time::Instant;

/// How the viewer starts.
#[derive(Clone, Debug)]
pub struct ViewerStart {
    /// Scene file; the embedded default scene if `None`.
    pub scene: Option<PathBuf>,
    /// Render worker threads (0 = all cores).
    pub render_threads: usize,
    /// Nice value of the render workers (Linux), so the UI keeps a core when it needs one.
    pub render_niceness: u8,
    /// Initial resolution scale (1 = the scene's own width and height).
    pub resolution_scale: f32,
    /// Print timestamped events (first image, restart latency, UI frame
    /// rate) to stderr: `PRISM_VIEWER_LOG=1`.
    pub log: bool,
    /// Repaint continuously, so the logged frame rate is what the UI can
    /// sustain while rendering: `PRISM_VIEWER_LOG=2`.
    pub continuous_repaint: bool,
    /// Where the list of recently opened scenes is kept (`None`: this session only).
    pub recent_file: Option<PathBuf>,
}

impl Default for ViewerStart {
    fn default() -> Self {
        let log_level: u32 = std::env::var("PRISM_VIEWER_LOG")
            .ok()
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or(0);
        Self {
            scene: None,
            render_threads: 2,
            render_niceness: 10,
            resolution_scale: 1.0,
            log: log_level >= 1,
            continuous_repaint: log_level >= 2,
            recent_file: files::default_recent_file(),
        }
    }
}

/// Why the viewer could not start; each message says how to render
/// without a window instead.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    #[error(
        "no display: neither DISPLAY nor WAYLAND_DISPLAY is set, so the viewer cannot open a window.\n\
         To render without a window use `prism render [SCENE] --output image.png`."
    )]
    /// No window system is reachable (neither `DISPLAY` nor
    /// `WAYLAND_DISPLAY` is set).
    NoDisplay,
    /// The window system refused the window (eframe's message).
    #[error("cannot open the viewer window: {0}\nTo render without a window use `prism render [SCENE] --output image.png`.")]
    Window(String),
}

/// Whether a window system is reachable at all (checked before eframe,
/// which would otherwise fail with a less helpful message or panic).
pub fn display_available() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|name| std::env::var_os(name).is_some_and(|v| !v.is_empty()))
}

/// Opens the viewer window and runs until it is closed.
pub fn run(initial: ViewerStart) -> Result<(), ViewerError> {
    if !display_available() {
        return Err(ViewerError::NoDisplay);
    }
    let launched = Instant::now();
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("Prism")
            .with_inner_size([1200.0, 760.0])
            .with_drag_and_drop(true),
        ..Default::default()
    };
    eframe::run_native(
        "Prism",
        options,
        Box::new(move |creation| {
            let app = ViewerApp::new(&creation.egui_ctx, initial, launched)?;
            Ok(Box::new(app))
        }),
    )
    .map_err(|error| ViewerError::Window(error.to_string()))
}
