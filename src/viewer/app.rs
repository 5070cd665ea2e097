//! The viewer's state and its per-frame cycle: take what the render thread
//! and the scene loader published, lay out the panels, then send the render
//! thread whatever the user changed. Rendering itself never happens here.

use super::camera_input::DepthGrid;
use super::denoiser::Denoiser;
use super::display::{CompareMode, DenoiseMode, Display, Reference};
use super::event_log::EventLog;
use super::files::{Dialog, DialogPurpose, OpenState, SaveState};
use super::image_view::{ImageZoom, RegionDrag};
use super::loader::{DEFAULT_SCENE_NAME, FileWatch, LoadResult, SceneLoader};
use super::{ViewerStart, panels, status};
use crate::camera::Camera;
use crate::film::ToneMap;
use crate::render::RenderSettings;
use crate::render::session::{Command, FrameInfo, RenderSession, RenderStats, SessionError};
use crate::scene::Scene;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// While a slider or the camera is being dragged the render runs at this
/// fraction of the chosen resolution scale, then refines on release.
const INTERACTIVE_SCALE: f32 = 0.25;

/// Which picture the image area shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewKind {
    /// The tone-mapped render.
    Image,
    /// Per-pixel relative standard error (`Frame::noise`).
    Noise,
    /// SPPM's per-pixel gather radius (the noise view for other integrators).
    Radii,
}

/// Width of the side panel: fixed, so that opening a section or a longer
/// label never moves the image.
const SIDE_PANEL_WIDTH: f32 = 320.0;

/// The viewer application. `show` draws one frame into a `Ui`; eframe calls
/// it through `App::ui`, and tests drive it with egui_kittest.
pub struct ViewerApp {
    pub(super) session: RenderSession,
    loader: SceneLoader,
    pub(super) watch: FileWatch,
    pub(super) auto_reload: bool,
    pub(super) scene: Option<Arc<Scene>>,
    /// The scene file shown (`None`: the embedded default scene).
    pub(super) scene_path: Option<PathBuf>,
    pub(super) scene_error: Option<String>,
    home_camera: Option<Camera>,
    /// The camera the user steers; the render thread gets a copy when it changes.
    pub(super) camera: Option<Camera>,
    /// Sampling settings at the scene's own resolution.
    pub(super) settings: RenderSettings,
    pub(super) resolution_scale: f32,
    pub(super) exposure: f64,
    pub(super) tone_map: ToneMap,
    pub(super) view: ViewKind,
    sent_camera: Option<Camera>,
    sent_settings: Option<RenderSettings>,
    /// Set during layout when a control that restarts the render is being dragged.
    pub(super) interacting: bool,
    /// Set during layout while the focal distance slider is dragged.
    pub(super) show_focal_plane: bool,
    pub(super) depth_grid: DepthGrid,
    pub(super) display: Display,
    pub(super) save: SaveState,
    pub(super) dialog: Option<Dialog>,
    pub(super) log: EventLog,
    continuous_repaint: bool,
    /// The scene path field, recent files and the shipped scenes.
    pub(super) open: OpenState,
    /// Why the last typed value was refused (shown under the controls).
    pub(super) input_error: Option<String>,
    pub(super) denoiser: Option<Denoiser>,
    pub(super) denoise_mode: DenoiseMode,
    /// Display-only cap on pixel luminance (biased), if on.
    pub(super) firefly_clamp: Option<f32>,
    pub(super) compare_mode: CompareMode,
    pub(super) reference: Option<Reference>,
    pub(super) reference_path_text: String,
    pub(super) show_histogram: bool,
    pub(super) zoom: ImageZoom,
    /// Drawing a region: drag on the image instead of orbiting.
    pub(super) region_tool: bool,
    pub(super) region_drag: Option<RegionDrag>,
    /// Image pixel under the cursor.
    pub(super) hovered_pixel: Option<(u32, u32)>,
    /// Where the image (its left copy, side by side) was last drawn.
    pub(super) image_rect: Option<egui::Rect>,
}

impl ViewerApp {
    /// Starts the render thread and the first scene load.
    pub fn new(ctx: &egui::Context, start: ViewerStart, launched: Instant) -> Result<Self, SessionError> {
        let repaint = ctx.clone();
        let session = RenderSession::new(
            RenderSettings::default(),
            start.render_threads,
            start.render_niceness,
            Box::new(move || repaint.request_repaint()),
        )?;
        let repaint = ctx.clone();
        let mut loader = SceneLoader::new(Arc::new(move || repaint.request_repaint()));
        let repaint = ctx.clone();
        let denoiser = Denoiser::new(Arc::new(move || repaint.request_repaint())).ok();
        let log = EventLog::new(start.log, launched);
        let open = OpenState::new(start.recent_file.clone(), start.scene.as_deref());
        let mut app = Self {
            session,
            loader: SceneLoader::new(Arc::new(|| {})),
            watch: FileWatch::default(),
            auto_reload: true,
            scene: None,
            scene_path: start.scene.clone(),
            scene_error: None,
            home_camera: None,
            camera: None,
            settings: RenderSettings::default(),
            resolution_scale: start.resolution_scale.clamp(0.05, 4.0),
            exposure: 0.0,
            tone_map: ToneMap::Clamp,
            view: ViewKind::Image,
            sent_camera: None,
            sent_settings: None,
            interacting: false,
            show_focal_plane: false,
            depth_grid: DepthGrid::default(),
            display: Display::default(),
            save: SaveState {
                path_text: "prism-snapshot.png".into(),
                denoised: false,
                message: None,
                dialog_unavailable: false,
            },
            dialog: None,
            log,
            continuous_repaint: start.continuous_repaint,
            open,
            input_error: None,
            denoiser,
            denoise_mode: DenoiseMode::Off,
            firefly_clamp: None,
            compare_mode: CompareMode::Off,
            reference: None,
            reference_path_text: String::new(),
            show_histogram: true,
            zoom: ImageZoom::default(),
            region_tool: false,
            region_drag: None,
            hovered_pixel: None,
            image_rect: None,
        };
        if let Err(error) = loader.load(start.scene) {
            app.scene_error = Some(format!("cannot start the scene loader: {error}"));
        }
        app.loader = loader;
        app.log.event("viewer started, loading scene");
        Ok(app)
    }

    /// The name of the scene shown, for the title, the status and the file metadata.
    pub fn scene_name(&self) -> String {
        self.scene_path
            .as_ref()
            .map_or(DEFAULT_SCENE_NAME.to_string(), |p| p.display().to_string())
    }

    /// The camera being steered (what the next restart renders with).
    pub fn camera(&self) -> Option<Camera> {
        self.camera
    }

    /// The loaded scene, shared with the render thread.
    pub fn scene(&self) -> Option<&Arc<Scene>> {
        self.scene.as_ref()
    }

    /// The error of the last scene load, as shown in the window.
    pub fn scene_error(&self) -> Option<&str> {
        self.scene_error.as_deref()
    }

    /// What the render thread last published.
    pub fn render_stats(&self) -> RenderStats {
        self.session.latest().stats
    }

    /// The sampling settings as the user set them (at the scene's own resolution).
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Image pixels per screen point, or `None` while the image is fitted to the window.
    pub fn image_zoom(&self) -> Option<f32> {
        self.zoom.scale
    }

    /// Where the image was last drawn on screen (its raw copy, side by side).
    pub fn image_rect(&self) -> Option<egui::Rect> {
        self.image_rect
    }

    /// Whether a denoised frame has arrived for the preview.
    pub fn has_denoised_frame(&self) -> bool {
        self.display.denoised.is_some()
    }

    /// The frame on screen.
    pub fn displayed_frame(&self) -> Option<&FrameInfo> {
        self.display.frame.as_ref()
    }

    /// Whether a scene load is still running.
    pub fn loading(&self) -> bool {
        self.loader.busy()
    }

    /// The running load's stage and time so far.
    pub(super) fn loader_stage(&self) -> Option<(crate::scene::LoadStage, Duration)> {
        self.loader.stage()
    }

    /// Draws one frame of the whole window into `ui`.
    pub fn show(&mut self, ui: &mut egui::Ui) {
        self.show_timed(ui, None);
    }

    /// `show`, told how long eframe's previous whole frame took (for the log).
    fn show_timed(&mut self, ui: &mut egui::Ui, previous_frame: Option<Duration>) {
        let began = Instant::now();
        let ctx = ui.ctx().clone();
        self.take_scene_load();
        self.refresh_display(&ctx);
        self.handle_input(&ctx);
        self.poll_dialog();
        if self.auto_reload && !self.loader.busy() && self.watch.changed(Instant::now()) {
            self.log.event("scene file changed on disk, reloading");
            self.load_scene(self.scene_path.clone());
        }

        self.interacting = false;
        self.show_focal_plane = false;
        egui::Panel::left("controls")
            .exact_size(SIDE_PANEL_WIDTH)
            .resizable(false)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| panels::ui_controls(self, ui));
            });
        egui::Panel::bottom("status").show(ui, |ui| status::ui_status(self, ui));
        // No fill: the image covers what it needs, and software GL then paints
        // the window's largest area once instead of twice.
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| self.ui_image(ui));

        self.sync_session();
        let stats = self.display.stats.clone();
        self.log.frame_tick(&stats, began.elapsed(), previous_frame);
        if self.continuous_repaint {
            // The logged frame rate is then what the UI can sustain.
            ctx.request_repaint();
        } else if self.dialog.is_some() || self.loader.busy() {
            ctx.request_repaint_after(Duration::from_millis(100));
        } else if self.display.stats.state == crate::render::session::SessionState::Rendering {
            // The render time and estimate in the status line run between passes.
            ctx.request_repaint_after(Duration::from_millis(250));
        } else if self.auto_reload && self.watch.path.is_some() {
            ctx.request_repaint_after(super::loader::WATCH_INTERVAL);
        }
    }

    /// Starts loading a scene file (or the default scene) in the background.
    pub fn load_scene(&mut self, path: Option<PathBuf>) {
        if let Err(error) = self.loader.load(path) {
            self.scene_error = Some(format!("cannot start the scene loader: {error}"));
        }
    }

    fn take_scene_load(&mut self) {
        let Some(LoadResult {
            path,
            modified,
            outcome,
            took,
            ..
        }) = self.loader.poll()
        else {
            return;
        };
        // Watch the file even when it is broken, so fixing it reloads it.
        self.watch.watch(path.clone(), modified);
        self.scene_path = path;
        match outcome {
            Ok(ready) => {
                if let Some(path) = &self.scene_path {
                    self.open.remember(path);
                }
                self.zoom = ImageZoom::default();
                self.log.event(&format!(
                    "scene {} loaded in {:.1} ms",
                    self.scene_name(),
                    took.as_secs_f64() * 1e3
                ));
                self.scene_error = None;
                self.settings = ready.settings;
                self.home_camera = Some(ready.camera);
                self.camera = Some(ready.camera);
                self.scene = Some(Arc::clone(&ready.scene));
                let generation = self.session.set_scene(ready.scene);
                self.note_request(generation, "scene");
            }
            Err(message) => {
                self.log.event(&format!("scene error: {message}"));
                self.scene_error = Some(message);
            }
        }
    }

    pub(super) fn log_refresh(&mut self, info: &FrameInfo) {
        if !self.log.enabled {
            return;
        }
        if !self.log.first_image_logged {
            self.log.first_image_logged = true;
            self.log.event(&format!(
                "first image shown ({}x{}, preview: {})",
                info.frame.width, info.frame.height, info.preview
            ));
        }
        let now = Instant::now();
        let mut done = Vec::new();
        self.log.pending.retain(|(generation, sent, what)| {
            if info.generation >= *generation {
                done.push(format!(
                    "{what} change → refreshed image in {:.1} ms ({}x{}{})",
                    (now - *sent).as_secs_f64() * 1e3,
                    info.frame.width,
                    info.frame.height,
                    if info.preview { ", preview" } else { "" }
                ));
                false
            } else {
                true
            }
        });
        for line in done {
            self.log.event(&line);
        }
    }

    fn note_request(&mut self, generation: u64, what: &str) {
        if self.log.enabled {
            self.log.pending.retain(|(g, _, _)| *g != generation);
            self.log.pending.push((generation, Instant::now(), what.to_string()));
        }
    }

    /// The settings the render thread should have now: the user's, at the
    /// chosen (or, while dragging, coarser) resolution.
    pub fn effective_settings(&self) -> RenderSettings {
        let mut settings = self.settings.clone();
        let scale = if self.interacting {
            self.resolution_scale * INTERACTIVE_SCALE
        } else {
            self.resolution_scale
        };
        settings.width = ((settings.width as f32 * scale).round() as u32).max(1);
        settings.height = ((settings.height as f32 * scale).round() as u32).max(1);
        settings
    }

    /// Sends the render thread what changed since the last frame.
    fn sync_session(&mut self) {
        if self.scene.is_none() {
            return;
        }
        let settings = self.effective_settings();
        if self.sent_settings.as_ref() != Some(&settings) {
            let generation = self.session.set_settings(settings.clone());
            self.note_request(generation, "settings");
            self.sent_settings = Some(settings);
        }
        if let Some(camera) = self.camera
            && self.sent_camera != Some(camera)
        {
            let generation = self.session.set_camera(camera);
            self.note_request(generation, "camera");
            self.sent_camera = Some(camera);
        }
    }

    pub(super) fn send(&mut self, command: Command) {
        let generation = self.session.send(command);
        self.note_request(generation, "control");
    }

    /// Puts the camera back where the scene file placed it.
    pub fn reset_view(&mut self) {
        if let (Some(home), Some(camera)) = (self.home_camera, self.camera.as_mut()) {
            // Keep the lens: resetting the view is about placement.
            let (aperture, focus) = (camera.aperture_radius, camera.focal_distance);
            *camera = home;
            camera.aperture_radius = aperture;
            camera.focal_distance = focus;
        }
    }

    /// Focal distance from the scene's own camera, for the slider's range.
    pub(super) fn home_distance(&self) -> f64 {
        self.home_camera.map_or(10.0, |c| (c.target - c.position).length().max(1e-6))
    }

    fn handle_input(&mut self, ctx: &egui::Context) {
        let (save, dropped) = ctx.input_mut(|i| {
            let save = i.consume_key(egui::Modifiers::COMMAND, egui::Key::S);
            let dropped: Vec<PathBuf> = i.raw.dropped_files.iter().map(|f| f.path().to_path_buf()).collect();
            (save, dropped)
        });
        if save {
            self.open_dialog(DialogPurpose::Save);
        }
        if let Some(path) = dropped.into_iter().next() {
            self.log.event(&format!("scene dropped: {}", path.display()));
            self.load_scene(Some(path));
        }
    }
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let previous = frame.info().cpu_usage.map(|s| Duration::from_secs_f32(s.max(0.0)));
        self.show_timed(ui, previous);
    }
}

impl Drop for ViewerApp {
    fn drop(&mut self) {
        // A dialog thread blocks inside the toolkit until the user answers;
        // it is detached rather than joined so closing the window never hangs.
        if let Some(mut dialog) = self.dialog.take() {
            drop(dialog.thread.take());
        }
    }
}
