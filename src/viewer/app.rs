//! The viewer's state and its per-frame cycle: take what the render thread
//! and the scene loader published, lay out the panels, then send the render
//! thread whatever the user changed. Rendering itself never happens here.

use super::camera_input::{self, DepthGrid};
use super::loader::{DEFAULT_SCENE_NAME, FileWatch, LoadResult, SceneLoader};
use super::texture;
use super::{ViewerStart, panels};
use crate::camera::Camera;
use crate::film::{Frame, ToneMap};
use crate::render::RenderSettings;
use crate::render::session::{Command, FrameInfo, RenderSession, RenderStats, SessionError};
use crate::scene::Scene;
use egui::{Color32, Rect, Sense, TextureHandle, TextureOptions, Vec2};
use glam::DVec2;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::mpsc::{self, Receiver};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// While a slider or the camera is being dragged the render runs at this
/// fraction of the chosen resolution scale, then refines on release.
const INTERACTIVE_SCALE: f32 = 0.25;

/// A file dialog that closes faster than this without a path did not
/// really open (no desktop portal, no zenity): offer the path field instead.
const DIALOG_FAILED_WITHIN: Duration = Duration::from_millis(300);

/// Which picture the image area shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewKind {
    /// The tone-mapped render.
    Image,
    /// Per-pixel relative standard error (`Frame::noise`).
    Noise,
}

/// What the image area currently shows.
#[derive(Default)]
pub(super) struct Display {
    pub texture: Option<TextureHandle>,
    pub frame: Option<FrameInfo>,
    pub stats: RenderStats,
    /// (frame sequence, exposure, tone map, view) the texture was made for.
    mapped_for: Option<(u64, f64, ToneMap, ViewKind)>,
    pub noise: Option<f64>,
}

/// Snapshot saving: the dialog runs on its own thread; the path field is
/// the fallback when it cannot open.
pub(super) struct SaveState {
    pub path_text: String,
    pub message: Option<(bool, String)>,
    pub dialog_unavailable: bool,
}

/// A file dialog running on a helper thread.
struct Dialog {
    purpose: DialogPurpose,
    opened: Instant,
    result: Receiver<Option<PathBuf>>,
    thread: Option<JoinHandle<()>>,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum DialogPurpose {
    Save,
    Open,
}

/// Timestamped events on stderr when `PRISM_VIEWER_LOG` is set.
pub(super) struct EventLog {
    enabled: bool,
    launched: Instant,
    first_image_logged: bool,
    /// Requests whose first frame has not been shown yet: (generation, sent at, what).
    pending: Vec<(u64, Instant, String)>,
    frames: u32,
    window_start: Instant,
    worst_frame: Duration,
    last_frame: Option<Instant>,
}

impl EventLog {
    fn new(enabled: bool, launched: Instant) -> Self {
        Self {
            enabled,
            launched,
            first_image_logged: false,
            pending: Vec::new(),
            frames: 0,
            window_start: Instant::now(),
            worst_frame: Duration::ZERO,
            last_frame: None,
        }
    }

    pub fn event(&self, what: &str) {
        if self.enabled {
            eprintln!("[prism-viewer {:9.1} ms] {what}", self.launched.elapsed().as_secs_f64() * 1e3);
        }
    }

    /// Counts UI frames and prints the rate and the longest gap once a second.
    fn frame_tick(&mut self, stats: &RenderStats) {
        if !self.enabled {
            return;
        }
        let now = Instant::now();
        if let Some(last) = self.last_frame {
            self.worst_frame = self.worst_frame.max(now - last);
        }
        self.last_frame = Some(now);
        self.frames += 1;
        let window = now - self.window_start;
        if window >= Duration::from_secs(1) {
            self.event(&format!(
                "ui {:.1} frames/s, longest frame gap {:.1} ms, render {:?} pass {} at {:.2} Msamples/s",
                self.frames as f64 / window.as_secs_f64(),
                self.worst_frame.as_secs_f64() * 1e3,
                stats.state,
                stats.passes,
                stats.samples_per_second / 1e6
            ));
            self.frames = 0;
            self.window_start = now;
            self.worst_frame = Duration::ZERO;
        }
    }
}

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
    depth_grid: DepthGrid,
    pub(super) display: Display,
    pub(super) save: SaveState,
    dialog: Option<Dialog>,
    pub(super) log: EventLog,
}

impl ViewerApp {
    /// Starts the render thread and the first scene load.
    pub fn new(ctx: &egui::Context, start: ViewerStart, launched: Instant) -> Result<Self, SessionError> {
        let repaint = ctx.clone();
        let session = RenderSession::new(
            RenderSettings::default(),
            start.render_threads,
            Box::new(move || repaint.request_repaint()),
        )?;
        let repaint = ctx.clone();
        let mut loader = SceneLoader::new(Arc::new(move || repaint.request_repaint()));
        let log = EventLog::new(start.log, launched);
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
                message: None,
                dialog_unavailable: false,
            },
            dialog: None,
            log,
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

    /// The frame on screen.
    pub fn displayed_frame(&self) -> Option<&FrameInfo> {
        self.display.frame.as_ref()
    }

    /// Whether a scene load is still running.
    pub fn loading(&self) -> bool {
        self.loader.busy()
    }

    /// Draws one frame of the whole window into `ui`.
    pub fn show(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        self.take_scene_load();
        self.take_published(&ctx);
        self.handle_input(&ctx);
        self.poll_dialog();
        if self.auto_reload && !self.loader.busy() && self.watch.changed(Instant::now()) {
            self.log.event("scene file changed on disk, reloading");
            self.load_scene(self.scene_path.clone());
        }

        self.interacting = false;
        self.show_focal_plane = false;
        egui::Panel::left("controls").default_size(290.0).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| panels::ui_controls(self, ui));
        });
        egui::Panel::bottom("status").show(ui, |ui| panels::ui_status(self, ui));
        egui::CentralPanel::default().show(ui, |ui| self.ui_image(ui));

        self.sync_session();
        let stats = self.display.stats.clone();
        self.log.frame_tick(&stats);
        if self.log.enabled {
            // Repaint continuously so the logged frame rate is what the UI can sustain.
            ctx.request_repaint();
        } else if self.dialog.is_some() || self.loader.busy() {
            ctx.request_repaint_after(Duration::from_millis(100));
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

    /// Uploads the newest published frame, or re-maps the current one after a display-only change.
    fn take_published(&mut self, ctx: &egui::Context) {
        let published = self.session.latest();
        self.display.stats = published.stats;
        if let Some(info) = published.frame {
            let newer = match &self.display.frame {
                Some(shown) => info.sequence != shown.sequence && info.generation >= shown.generation,
                None => true,
            };
            if newer {
                self.display.noise = texture::noise_estimate(&info.frame);
                self.log_refresh(&info);
                self.display.frame = Some(info);
            }
        }
        let Some(info) = &self.display.frame else {
            return;
        };
        let key = (info.sequence, self.exposure, self.tone_map, self.view);
        if self.display.mapped_for == Some(key) {
            return;
        }
        let image = match self.view {
            ViewKind::Image => texture::tone_mapped(&info.frame, self.exposure, self.tone_map),
            ViewKind::Noise => texture::noise_heatmap(&info.frame),
        };
        match &mut self.display.texture {
            Some(texture) => texture.set(image, TextureOptions::LINEAR),
            None => self.display.texture = Some(ctx.load_texture("prism-render", image, TextureOptions::LINEAR)),
        }
        self.display.mapped_for = Some(key);
    }

    fn log_refresh(&mut self, info: &FrameInfo) {
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

    pub(super) fn open_save_dialog(&mut self) {
        self.open_dialog(DialogPurpose::Save);
    }

    pub(super) fn open_scene_dialog(&mut self) {
        self.open_dialog(DialogPurpose::Open);
    }

    fn open_dialog(&mut self, purpose: DialogPurpose) {
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

    fn poll_dialog(&mut self) {
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

    /// The image area: the texture fitted to the panel, navigation, click-to-focus, overlays.
    fn ui_image(&mut self, ui: &mut egui::Ui) {
        let available = ui.available_rect_before_wrap();
        let settings = self.effective_settings();
        let aspect = settings.width as f32 / settings.height.max(1) as f32;
        let size = fit(available.size(), aspect);
        let rect = Rect::from_center_size(available.center(), size);
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "Rendered image"));
        let painter = ui.painter_at(available);
        match &self.display.texture {
            Some(texture) => {
                painter.image(
                    texture.id(),
                    rect,
                    Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                    Color32::WHITE,
                );
            }
            None => {
                painter.rect_filled(rect, 0.0, Color32::from_gray(20));
                let text = if self.loader.busy() {
                    "Loading scene…"
                } else {
                    "No image yet"
                };
                painter.text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    text,
                    egui::FontId::proportional(18.0),
                    Color32::GRAY,
                );
            }
        }
        self.handle_image_input(ui, &response, rect);
        if self.show_focal_plane {
            self.paint_focal_plane(&painter, rect, &settings);
        }
        if let Some(error) = &self.scene_error {
            let banner = Rect::from_min_size(available.min + Vec2::splat(8.0), Vec2::new(available.width() - 16.0, 0.0));
            let mut child = ui.new_child(egui::UiBuilder::new().max_rect(banner));
            egui::Frame::popup(ui.style())
                .fill(Color32::from_rgb(90, 20, 20))
                .show(&mut child, |ui| {
                    ui.colored_label(Color32::WHITE, "Scene error");
                    ui.colored_label(Color32::from_rgb(255, 200, 200), error);
                });
        }
    }

    fn handle_image_input(&mut self, ui: &egui::Ui, response: &egui::Response, rect: Rect) {
        let Some(camera) = self.camera.as_mut() else {
            return;
        };
        let height = rect.height() as f64;
        let delta = response.drag_delta();
        let delta = DVec2::new(delta.x as f64, delta.y as f64);
        let pan = response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle)
            || (response.dragged_by(egui::PointerButton::Primary) && ui.input(|i| i.modifiers.shift));
        if pan {
            camera_input::pan(camera, delta, height);
        } else if response.dragged_by(egui::PointerButton::Primary) {
            camera_input::orbit(camera, delta, height);
        }
        if response.dragged() {
            self.interacting = true;
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y) as f64;
            if scroll != 0.0 {
                camera_input::zoom(camera, scroll);
            }
        }
        if response.clicked()
            && let (Some(position), Some(scene)) = (response.interact_pointer_pos(), &self.scene)
        {
            let film = DVec2::new(
                ((position.x - rect.min.x) / rect.width()) as f64,
                ((position.y - rect.min.y) / rect.height()) as f64,
            );
            let aspect = self.settings.width as f64 / self.settings.height.max(1) as f64;
            if let Some(depth) = camera_input::surface_depth(scene, camera, film, aspect) {
                camera.focal_distance = depth;
                self.log.event(&format!("focus on clicked surface at depth {depth:.4}"));
            }
        }
    }

    /// Tints the cells of a coarse depth grid that lie on the focal plane.
    fn paint_focal_plane(&mut self, painter: &egui::Painter, rect: Rect, settings: &RenderSettings) {
        let (Some(scene), Some(camera)) = (&self.scene, self.camera) else {
            return;
        };
        self.depth_grid.update(scene, &camera, settings.width, settings.height);
        let grid = &self.depth_grid;
        let cell = Vec2::new(rect.width() / grid.columns as f32, rect.height() / grid.rows as f32);
        let tint = Color32::from_rgba_unmultiplied(60, 255, 120, 90);
        for (column, row) in grid.in_focus(camera.focal_distance) {
            let min = rect.min + Vec2::new(column as f32 * cell.x, row as f32 * cell.y);
            painter.rect_filled(Rect::from_min_size(min, cell), 0.0, tint);
        }
    }
}

/// The largest size of the given aspect ratio inside `available`.
fn fit(available: Vec2, aspect: f32) -> Vec2 {
    let width = available.x.min(available.y * aspect).max(1.0);
    Vec2::new(width, width / aspect.max(1e-6))
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.show(ui);
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
