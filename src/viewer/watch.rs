//! `prism view --watch DIR`: the merge of a folder of film files, shown as a
//! farm writes them. The merging is the library's `farm::watch`; this file
//! only runs it on a scanning thread (a large part takes a moment to read)
//! and lays out the image and a status line: parts merged, samples merged
//! out of those expected, what is missing, the noise, and parts left out.

use super::texture::tone_mapped;
use crate::farm::watch::{FolderWatch, WatchStatus};
use crate::film::{Frame, ToneMap};
use egui::{Color32, Rect, TextureHandle, TextureOptions};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, channel};
use std::thread::JoinHandle;
use std::time::Duration;

/// How often the folder is scanned: a farm's parts take minutes, and a scan
/// that finds nothing new only lists the folder.
pub const SCAN_INTERVAL: Duration = Duration::from_millis(500);

/// What the scanning thread reports.
enum WatchUpdate {
    /// The merge changed (a frame) or only its status did (`None`).
    Merge(WatchStatus, Option<Frame>),
    /// The folder cannot be listed.
    Failed(String),
}

/// The watch window's state.
pub struct WatchApp {
    folder: PathBuf,
    updates: Receiver<WatchUpdate>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    status: WatchStatus,
    frame: Option<Frame>,
    texture: Option<TextureHandle>,
    /// The texture shows this frame with these display settings.
    texture_stale: bool,
    exposure: f32,
    tone_map: ToneMap,
    error: Option<String>,
}

impl WatchApp {
    /// Starts scanning `folder`; `ctx` is woken when something changes.
    pub fn new(ctx: &egui::Context, folder: PathBuf) -> std::io::Result<Self> {
        let (sender, updates) = channel();
        let stop = Arc::new(AtomicBool::new(false));
        let (ctx, stopped, watched) = (ctx.clone(), Arc::clone(&stop), folder.clone());
        let thread = std::thread::Builder::new().name("prism-watch".into()).spawn(move || {
            let mut watch = FolderWatch::new(&watched);
            let mut last_status = None;
            while !stopped.load(Ordering::Relaxed) {
                let update = match watch.scan() {
                    Ok(changed) => {
                        let status = watch.status();
                        let frame = if changed { watch.frame() } else { None };
                        (changed || last_status.as_ref() != Some(&status)).then(|| {
                            last_status = Some(status.clone());
                            WatchUpdate::Merge(status, frame)
                        })
                    }
                    Err(error) => Some(WatchUpdate::Failed(error.to_string())),
                };
                if let Some(update) = update {
                    if sender.send(update).is_err() {
                        return;
                    }
                    ctx.request_repaint();
                }
                std::thread::sleep(SCAN_INTERVAL);
            }
        })?;
        Ok(Self {
            folder,
            updates,
            stop,
            thread: Some(thread),
            status: WatchStatus::default(),
            frame: None,
            texture: None,
            texture_stale: false,
            exposure: 0.0,
            tone_map: ToneMap::default(),
            error: None,
        })
    }

    /// The latest status of the merge.
    pub fn status(&self) -> &WatchStatus {
        &self.status
    }

    /// The merged frame shown, once some part is in.
    pub fn frame(&self) -> Option<&Frame> {
        self.frame.as_ref()
    }

    /// One line: parts, samples, noise.
    pub fn status_line(&self) -> String {
        let status = &self.status;
        if status.parts == 0 {
            return format!("Waiting for film files in {}", self.folder.display());
        }
        let percent = 100.0 * status.samples_held as f64 / status.samples_expected.max(1) as f64;
        let noise = status
            .noise
            .map_or("noise: not yet".into(), |n| format!("noise {:.2}%", 100.0 * n));
        format!(
            "{} parts merged, {} of {} samples ({percent:.1}%), {noise}",
            status.parts, status.samples_held, status.samples_expected
        )
    }

    /// Draws one frame of the window into `ui`.
    pub fn show(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        while let Ok(update) = self.updates.try_recv() {
            match update {
                WatchUpdate::Merge(status, frame) => {
                    self.status = status;
                    self.error = None;
                    if frame.is_some() {
                        self.frame = frame;
                        self.texture_stale = true;
                    }
                }
                WatchUpdate::Failed(error) => self.error = Some(error),
            }
        }
        egui::Panel::top("watch-status").show(ui, |ui| self.ui_status(ui));
        egui::CentralPanel::default().show(ui, |ui| self.ui_image(ui, &ctx));
    }

    fn ui_status(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label(self.status_line());
            ui.separator();
            let exposure = ui.add(egui::Slider::new(&mut self.exposure, -8.0..=8.0).text("Exposure"));
            let mut tone_map = self.tone_map;
            egui::ComboBox::from_label("Tone map")
                .selected_text(format!("{:?}", self.tone_map))
                .show_ui(ui, |ui| {
                    for option in ToneMap::ALL {
                        ui.selectable_value(&mut tone_map, option, format!("{option:?}"));
                    }
                });
            if exposure.changed() || tone_map != self.tone_map {
                self.tone_map = tone_map;
                self.texture_stale = true;
            }
        });
        if !self.status.missing.is_empty() {
            ui.label(format!("Still missing: {}", self.status.missing));
        }
        for problem in &self.status.problems {
            ui.colored_label(Color32::from_rgb(230, 120, 100), format!("Left out: {problem}"));
        }
        if let Some(error) = &self.error {
            ui.colored_label(Color32::from_rgb(230, 120, 100), error);
        }
    }

    fn ui_image(&mut self, ui: &mut egui::Ui, ctx: &egui::Context) {
        if self.texture_stale
            && let Some(frame) = &self.frame
        {
            let image = tone_mapped(frame, self.exposure as f64, self.tone_map);
            match &mut self.texture {
                Some(texture) => texture.set(image, TextureOptions::LINEAR),
                None => self.texture = Some(ctx.load_texture("prism-watch", image, TextureOptions::LINEAR)),
            }
            self.texture_stale = false;
        }
        let available = ui.available_rect_before_wrap();
        let (Some(texture), Some(frame)) = (&self.texture, &self.frame) else {
            ui.centered_and_justified(|ui| ui.label("No parts yet"));
            return;
        };
        let aspect = frame.width as f32 / frame.height.max(1) as f32;
        let size = if available.width() / available.height().max(1.0) > aspect {
            egui::vec2(available.height() * aspect, available.height())
        } else {
            egui::vec2(available.width(), available.width() / aspect)
        };
        let rect = Rect::from_center_size(available.center(), size);
        ui.painter().image(
            texture.id(),
            rect,
            Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
            Color32::WHITE,
        );
    }
}

impl eframe::App for WatchApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.show(ui);
    }
}

impl Drop for WatchApp {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// Opens a window on the merge of the film files in `folder`.
pub fn run_watch(folder: PathBuf) -> Result<(), super::ViewerError> {
    if !super::display_available() {
        return Err(super::ViewerError::NoDisplay);
    }
    let title = format!("Prism: watching {}", folder.display());
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title(title)
            .with_inner_size([1000.0, 760.0]),
        ..Default::default()
    };
    eframe::run_native(
        "Prism watch",
        options,
        Box::new(move |creation| Ok(Box::new(WatchApp::new(&creation.egui_ctx, folder)?))),
    )
    .map_err(|error| super::ViewerError::Window(error.to_string()))
}
