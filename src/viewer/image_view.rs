//! The image area: the frame's texture fitted to the panel, mouse
//! navigation, click-to-focus, the focal-plane overlay and the scene-error banner.

use super::app::ViewerApp;
use super::camera_input;
use crate::render::RenderSettings;
use egui::{Color32, Rect, Sense, Vec2};
use glam::DVec2;

impl ViewerApp {
    /// The image area: the texture fitted to the panel, navigation, click-to-focus, overlays.
    pub(super) fn ui_image(&mut self, ui: &mut egui::Ui) {
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
