//! The image area: the frame's texture (fitted, or zoomed and panned),
//! mouse navigation, click-to-focus, drawing a render region, the pixel
//! readout under the cursor, and the focal-plane and scene-error overlays.
//!
//! Zoom and pan are display only: they move the picture, never the camera,
//! so they never restart the render. The mouse wheel zooms the image about
//! the cursor; Ctrl+wheel moves the camera (dolly).

use super::app::ViewerApp;
use super::camera_input;
use super::display::DenoiseMode;
use super::inspect;
use crate::render::RenderSettings;
use crate::settings::Region;
use egui::{Color32, Pos2, Rect, Sense, Vec2};
use glam::DVec2;

/// Zoom steps: one wheel notch (~50 points) scales by e^(50/200) ≈ 1.28.
const WHEEL_POINTS_PER_E: f32 = 200.0;

/// How the image is placed in its area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageZoom {
    /// Screen points per image pixel; `None` fits the image to the area.
    pub scale: Option<f32>,
    /// The image point (in [0, 1]², y down) at the area's centre when zoomed.
    pub center: Vec2,
}

impl Default for ImageZoom {
    fn default() -> Self {
        Self {
            scale: None,
            center: Vec2::splat(0.5),
        }
    }
}

impl ImageZoom {
    pub fn fit(&mut self) {
        *self = Self::default();
    }

    /// One image pixel per physical screen pixel, about the current centre.
    pub fn one_to_one(&mut self, pixels_per_point: f32) {
        self.scale = Some(1.0 / pixels_per_point.max(1e-3));
    }

    /// Where an image of `size` pixels lies in `area`.
    pub fn place(&self, area: Rect, size: Vec2) -> Rect {
        match self.scale {
            None => Rect::from_center_size(area.center(), fit(area.size(), size.x / size.y.max(1.0))),
            Some(scale) => {
                let shown = size * scale;
                Rect::from_min_size(area.center() - self.center * shown, shown)
            }
        }
    }

    /// Zooms by e^(`points`/200) keeping the image point under `cursor` there.
    fn zoom_about(&mut self, area: Rect, size: Vec2, cursor: Pos2, points: f32, pixels_per_point: f32) {
        let rect = self.place(area, size);
        let scale = rect.width() / size.x.max(1.0);
        // From an eighth of the fitted size to 64 physical pixels per image pixel.
        let fitted = fit(area.size(), size.x / size.y.max(1.0)).x / size.x.max(1.0);
        let new_scale = (scale * (points / WHEEL_POINTS_PER_E).exp()).clamp(fitted / 8.0, 64.0 / pixels_per_point);
        let under = (cursor - rect.min) / rect.size();
        let new_min = cursor - under * size * new_scale;
        self.scale = Some(new_scale);
        self.center = (area.center() - new_min) / (size * new_scale);
    }

    fn pan(&mut self, area: Rect, size: Vec2, delta: Vec2) {
        let rect = self.place(area, size);
        if self.scale.is_none() {
            self.scale = Some(rect.width() / size.x.max(1.0));
        }
        self.center -= delta / rect.size();
    }
}

/// A region being drawn: where the drag started, in film coordinates.
#[derive(Clone, Copy, Debug)]
pub struct RegionDrag {
    start: [f64; 2],
}

impl ViewerApp {
    /// The image area: texture(s), navigation, click-to-focus, region, readout, overlays.
    pub(super) fn ui_image(&mut self, ui: &mut egui::Ui) {
        let area = ui.available_rect_before_wrap();
        let settings = self.effective_settings();
        let size = self
            .display
            .frame
            .as_ref()
            .map_or(Vec2::new(settings.width as f32, settings.height as f32), |f| {
                Vec2::new(f.frame.width as f32, f.frame.height as f32)
            });
        // Side by side: raw on the left half, denoised on the right.
        let side_by_side = self.denoise_mode == DenoiseMode::SideBySide && self.display.side_texture.is_some();
        let (main_area, side_area) = if side_by_side {
            let half = area.width() / 2.0;
            (
                Rect::from_min_size(area.min, Vec2::new(half - 2.0, area.height())),
                Some(Rect::from_min_size(
                    area.min + Vec2::new(half + 2.0, 0.0),
                    Vec2::new(half - 2.0, area.height()),
                )),
            )
        } else {
            (area, None)
        };
        let rect = self.zoom.place(main_area, size);
        self.image_rect = Some(rect);
        let response = ui.allocate_rect(area, Sense::click_and_drag());
        response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "Rendered image"));
        let painter = ui.painter_at(area);
        let full_uv = Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        match &self.display.texture {
            Some(texture) => {
                painter
                    .with_clip_rect(main_area)
                    .image(texture.id(), rect, full_uv, Color32::WHITE);
            }
            None => {
                painter.rect_filled(rect, 0.0, Color32::from_gray(20));
                let text = if self.loading() { "Loading scene…" } else { "No image yet" };
                painter.text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    text,
                    egui::FontId::proportional(18.0),
                    Color32::GRAY,
                );
            }
        }
        if let (Some(side_area), Some(texture)) = (side_area, &self.display.side_texture) {
            let side_rect = self.zoom.place(side_area, size);
            painter
                .with_clip_rect(side_area)
                .image(texture.id(), side_rect, full_uv, Color32::WHITE);
            let label = |at: Rect, text: &str| {
                painter.text(
                    at.left_top() + Vec2::new(8.0, 8.0),
                    egui::Align2::LEFT_TOP,
                    text,
                    egui::FontId::proportional(15.0),
                    Color32::from_rgb(255, 230, 120),
                );
            };
            label(main_area, "raw");
            label(side_area, "denoised (display only)");
        }
        self.handle_image_input(ui, &response, (main_area, side_area), size);
        self.paint_region(&painter, rect, &settings, &response);
        if self.show_focal_plane {
            self.paint_focal_plane(&painter, rect, &settings);
        }
        self.paint_readout(ui, &painter, area);
        if let Some(error) = &self.scene_error {
            let banner = Rect::from_min_size(area.min + Vec2::splat(8.0), Vec2::new(area.width() - 16.0, 0.0));
            let mut child = ui.new_child(egui::UiBuilder::new().max_rect(banner));
            egui::Frame::popup(ui.style())
                .fill(Color32::from_rgb(90, 20, 20))
                .show(&mut child, |ui| {
                    ui.colored_label(Color32::WHITE, "Scene error");
                    ui.colored_label(Color32::from_rgb(255, 200, 200), error);
                });
        }
    }

    fn handle_image_input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        (area, side_area): (Rect, Option<Rect>),
        size: Vec2,
    ) {
        let pixels_per_point = ui.ctx().pixels_per_point();
        // The image rect under the pointer, in either half of a side-by-side view.
        let zoom = self.zoom;
        let pointer_rect = move |pos: Pos2| match side_area {
            Some(side) if side.contains(pos) => zoom.place(side, size),
            _ => zoom.place(area, size),
        };
        let hover = response.hover_pos();
        self.hovered_pixel = hover.and_then(|pos| {
            let rect = pointer_rect(pos);
            let uv = (pos - rect.min) / rect.size();
            ((0.0..1.0).contains(&uv.x) && (0.0..1.0).contains(&uv.y)).then_some(((uv.x * size.x) as u32, (uv.y * size.y) as u32))
        });

        // The wheel zooms the image; with Ctrl it moves the camera.
        if let Some(cursor) = hover {
            let wheel: Vec<(f32, bool)> = ui.input(|i| {
                i.events
                    .iter()
                    .filter_map(|event| match event {
                        egui::Event::MouseWheel {
                            unit, delta, modifiers, ..
                        } => {
                            let points = match unit {
                                egui::MouseWheelUnit::Point => delta.y,
                                egui::MouseWheelUnit::Line => delta.y * 50.0,
                                egui::MouseWheelUnit::Page => delta.y * 500.0,
                            };
                            Some((points, modifiers.ctrl || modifiers.command))
                        }
                        _ => None,
                    })
                    .collect()
            });
            for (points, dolly) in wheel {
                match (dolly, self.camera.as_mut()) {
                    (true, Some(camera)) => camera_input::zoom(camera, points as f64),
                    (true, None) => {}
                    (false, _) => self.zoom.zoom_about(area, size, cursor, points, pixels_per_point),
                }
            }
        }
        if response.dragged_by(egui::PointerButton::Middle) {
            self.zoom.pan(area, size, response.drag_delta());
        }

        // Drawing a region: with the region tool, or Ctrl+drag.
        let rect_at = |pos: Pos2| pointer_rect(pos);
        let film_at = |pos: Pos2| {
            let rect = rect_at(pos);
            let uv = (pos - rect.min) / rect.size();
            [uv.x as f64, uv.y as f64]
        };
        let ctrl = ui.input(|i| i.modifiers.ctrl || i.modifiers.command);
        if response.drag_started_by(egui::PointerButton::Primary)
            && (self.region_tool || ctrl)
            && let Some(pos) = response.interact_pointer_pos()
        {
            self.region_drag = Some(RegionDrag { start: film_at(pos) });
        }
        if let Some(drag) = self.region_drag {
            if response.drag_stopped() {
                if let Some(pos) = response.interact_pointer_pos() {
                    self.settings.region = Region::from_corners(drag.start, film_at(pos));
                }
                self.region_drag = None;
                self.region_tool = false;
            }
            return;
        }

        let Some(camera) = self.camera.as_mut() else {
            return;
        };
        let height = area.height().min(size.y * self.zoom.scale.unwrap_or(f32::INFINITY)) as f64;
        let delta = response.drag_delta();
        let delta = DVec2::new(delta.x as f64, delta.y as f64);
        let pan = response.dragged_by(egui::PointerButton::Secondary)
            || (response.dragged_by(egui::PointerButton::Primary) && ui.input(|i| i.modifiers.shift));
        if pan {
            camera_input::pan(camera, delta, height);
        } else if response.dragged_by(egui::PointerButton::Primary) {
            camera_input::orbit(camera, delta, height);
        }
        if response.dragged_by(egui::PointerButton::Primary) || response.dragged_by(egui::PointerButton::Secondary) {
            self.interacting = true;
        }
        if response.clicked()
            && let (Some(position), Some(scene)) = (response.interact_pointer_pos(), &self.scene)
        {
            let film = film_at(position);
            if (0.0..=1.0).contains(&film[0]) && (0.0..=1.0).contains(&film[1]) {
                let aspect = self.settings.width as f64 / self.settings.height.max(1) as f64;
                if let Some(depth) = camera_input::surface_depth(scene, camera, DVec2::from_array(film), aspect) {
                    camera.focal_distance = depth;
                    self.log.event(&format!("focus on clicked surface at depth {depth:.4}"));
                }
            }
        }
    }

    /// The region being drawn, or the one rendering, outlined on the image.
    fn paint_region(&self, painter: &egui::Painter, rect: Rect, settings: &RenderSettings, response: &egui::Response) {
        let to_screen = |film: [f64; 2]| rect.min + Vec2::new(film[0] as f32, film[1] as f32) * rect.size();
        let outline = |a: Pos2, b: Pos2, color: Color32| {
            painter.rect_stroke(
                Rect::from_two_pos(a, b),
                0.0,
                egui::Stroke::new(1.5, color),
                egui::StrokeKind::Outside,
            );
        };
        if let (Some(drag), Some(pos)) = (self.region_drag, response.interact_pointer_pos()) {
            outline(to_screen(drag.start), pos, Color32::from_rgb(255, 220, 60));
        } else if let Some(region) = settings.region {
            outline(to_screen(region.min), to_screen(region.max), Color32::from_rgb(255, 220, 60));
        }
    }

    /// The readout of the pixel under the cursor, in the area's top-left corner.
    fn paint_readout(&self, ui: &egui::Ui, painter: &egui::Painter, area: Rect) {
        let (Some((x, y)), Some(info)) = (self.hovered_pixel, &self.display.frame) else {
            return;
        };
        let Some(pixel) = inspect::readout(info, x, y) else {
            return;
        };
        let samples = pixel.samples.map_or("—".to_string(), |n| n.to_string());
        let error = pixel
            .relative_error
            .map_or("—".to_string(), |e| format!("{:.2} %", e * 100.0));
        let [r, g, b] = pixel.rgb;
        let text = format!(
            "pixel ({}, {})\nRGB {r:.4} {g:.4} {b:.4} (linear)\nluminance {:.4}\nsamples {samples}\nrel. std. error {error}",
            pixel.x, pixel.y, pixel.luminance
        );
        let galley = painter.layout_no_wrap(text, egui::FontId::monospace(13.0), Color32::WHITE);
        let at = area.left_bottom() + Vec2::new(8.0, -8.0 - galley.size().y);
        let background = Rect::from_min_size(at, galley.size()).expand(6.0);
        painter.rect_filled(background, 4.0, Color32::from_black_alpha(200));
        painter.galley(at, galley, Color32::WHITE);
        let _ = ui;
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
        let mut cells = 0;
        for (column, row) in grid.in_focus(camera.focal_distance) {
            let min = rect.min + Vec2::new(column as f32 * cell.x, row as f32 * cell.y);
            painter.rect_filled(Rect::from_min_size(min, cell), 0.0, tint);
            cells += 1;
        }
        let note = if cells == 0 { " (no surface at this depth)" } else { "" };
        painter.text(
            rect.left_bottom() + Vec2::new(8.0, -8.0),
            egui::Align2::LEFT_BOTTOM,
            format!("focal plane at {:.4}{note}", camera.focal_distance),
            egui::FontId::proportional(15.0),
            Color32::from_rgb(120, 255, 160),
        );
    }
}

/// The largest size of the given aspect ratio inside `available`.
fn fit(available: Vec2, aspect: f32) -> Vec2 {
    let width = available.x.min(available.y * aspect).max(1.0);
    Vec2::new(width, width / aspect.max(1e-6))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wheel_zoom_keeps_the_point_under_the_cursor() {
        let area = Rect::from_min_size(Pos2::new(100.0, 50.0), Vec2::new(800.0, 600.0));
        let size = Vec2::new(400.0, 300.0);
        let mut zoom = ImageZoom::default();
        let cursor = Pos2::new(300.0, 200.0);
        let before = zoom.place(area, size);
        let under = (cursor - before.min) / before.size();
        zoom.zoom_about(area, size, cursor, 100.0, 1.0);
        let after = zoom.place(area, size);
        // Fitted, 400x300 fills 800x600 at scale 2; 100 points → × e^0.5.
        assert!((after.width() / size.x - 2.0 * 0.5f32.exp()).abs() < 1e-4);
        let still = after.min + under * after.size();
        assert!((still - cursor).length() < 1e-3, "{still:?} vs {cursor:?}");
        zoom.one_to_one(1.0);
        assert_eq!(zoom.place(area, size).size(), size);
    }
}
