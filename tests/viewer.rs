//! The viewer driven through egui_kittest (no window, real render thread):
//! the aperture slider reaches the render thread and restarts accumulation,
//! clicking the image focuses on the clicked surface, saving writes a valid
//! image with metadata, a broken scene shows its error in the window, Stop
//! and Resume keep the samples, zooming never restarts the render, a typed
//! value beyond a slider's range is kept (and an invalid one refused), and a
//! scene opens through the path field.
//!
//! The renders run at 1/8 of the default scene's resolution (64 × 64) on one
//! worker thread, so each test takes a few seconds in a debug build.

mod common;
use common::ScratchDir;
use egui::accesskit::Role;
use egui::{Event, Modifiers, PointerButton, Pos2, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::DVec2;
use prism::render::session::SessionState;
use prism::scene;
use prism::viewer::{ViewerApp, ViewerStart};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Generous: a loaded CI machine running other tests in parallel.
const TIMEOUT: Duration = Duration::from_secs(60);

fn start(scene: Option<PathBuf>) -> Harness<'static, ViewerApp> {
    let start = ViewerStart {
        scene,
        render_threads: 1,
        render_niceness: 0,
        resolution_scale: 0.125,
        log: false,
        continuous_repaint: false,
        recent_file: None,
    };
    // The render thread's wake-ups go to a context of their own: the test steps the UI itself.
    let app = ViewerApp::new(&egui::Context::default(), start, Instant::now()).expect("viewer starts");
    Harness::builder()
        .with_size(Vec2::new(1200.0, 1100.0))
        .build_ui_state(|ui, app: &mut ViewerApp| app.show(ui), app)
}

/// Steps the UI until `done` holds, failing after `TIMEOUT`.
fn step_until(harness: &mut Harness<'static, ViewerApp>, what: &str, done: impl Fn(&ViewerApp) -> bool) {
    let begun = Instant::now();
    while !done(harness.state()) {
        assert!(begun.elapsed() < TIMEOUT, "timed out waiting for {what}");
        harness.step();
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// The test's scratch directory, for the files it writes.
fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new("prism-viewer-test", test)
}

fn press(harness: &Harness<'static, ViewerApp>, position: Pos2, pressed: bool) {
    harness.event(Event::PointerButton {
        pos: position,
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::NONE,
    });
}

#[test]
fn aperture_slider_changes_the_render_threads_camera_and_restarts() {
    let mut harness = start(None);
    // Let the first generation accumulate a few passes.
    step_until(&mut harness, "a few passes", |app| {
        app.displayed_frame().is_some_and(|f| f.passes >= 2)
    });
    let before = harness.state().displayed_frame().cloned().expect("frame");
    assert_eq!(before.camera.aperture_radius, 0.0, "the default scene starts as a pinhole");

    // A camera-only change: set the slider's value (as assistive technology
    // does), so no drag makes the resolution coarse meanwhile.
    harness
        .get_by_role_and_label(Role::Slider, "Aperture radius")
        .set_value_accesskit(12.5);
    harness.step();
    assert_eq!(harness.state().camera().expect("camera").aperture_radius, 12.5);
    // The render thread's own camera is the new one…
    step_until(&mut harness, "the render thread's camera", |app| {
        app.render_stats().camera.is_some_and(|c| c.aperture_radius == 12.5)
    });
    // …and the frames it publishes with it belong to a restarted accumulation.
    step_until(&mut harness, "a frame with the new aperture", |app| {
        app.displayed_frame()
            .is_some_and(|f| f.camera.aperture_radius == 12.5 && !f.preview)
    });
    let after = harness.state().displayed_frame().cloned().expect("frame");
    assert_eq!(after.settings, before.settings, "only the camera changed");
    assert!(
        after.generation > before.generation,
        "generation {} → {}",
        before.generation,
        after.generation
    );
    // Had the accumulation continued, it would hold the old passes plus at
    // least one per frame published since; restarted, it holds at most one
    // per frame published since the restart.
    assert!(
        (after.passes as u64) <= after.sequence - before.sequence,
        "passes {} after {} frames: accumulation was not restarted (before: {} passes)",
        after.passes,
        after.sequence - before.sequence,
        before.passes
    );

    // Dragging the slider renders coarse while the mouse is down, then refines.
    let rect = harness.get_by_role_and_label(Role::Slider, "Aperture radius").rect();
    let from = rect.left_center() + Vec2::new(2.0, 0.0);
    let to = rect.lerp_inside(Vec2::new(0.6, 0.5));
    harness.event(Event::PointerMoved(from));
    press(&harness, from, true);
    harness.step();
    for t in [0.25, 0.5, 0.75, 1.0] {
        harness.event(Event::PointerMoved(from + (to - from) * t));
        harness.step();
    }
    step_until(&mut harness, "a coarse render while dragging", |app| {
        app.render_stats().settings.width < 64
    });
    press(&harness, to, false);
    harness.step();
    let dragged = harness.state().camera().expect("camera").aperture_radius;
    assert!(dragged > 0.0 && dragged != 12.5, "the drag moved the slider to {dragged}");
    step_until(&mut harness, "the refined render with the dragged aperture", |app| {
        app.displayed_frame()
            .is_some_and(|f| f.camera.aperture_radius == dragged && f.settings.width == 64 && !f.preview)
    });
}

#[test]
fn clicking_the_image_focuses_on_the_clicked_surface() {
    let mut harness = start(None);
    step_until(&mut harness, "the scene", |app| {
        app.scene().is_some() && app.displayed_frame().is_some()
    });
    let initial_focus = harness.state().camera().expect("camera").focal_distance;

    // The glass sphere's centre projects to about (0.64, 0.74) of the image.
    let rect = harness.state().image_rect().expect("the image is drawn");
    let click = rect.lerp_inside(Vec2::new(0.64, 0.72));
    harness.event(Event::PointerMoved(click));
    press(&harness, click, true);
    harness.step();
    press(&harness, click, false);
    harness.step();

    // Expected: the depth along the view axis of what the scene file's camera sees there.
    let loaded = scene::load_scene_str(scene::DEFAULT_SCENE, Path::new("cornell"), Path::new(".")).expect("default scene");
    let film = DVec2::new(
        ((click.x - rect.min.x) / rect.width()) as f64,
        ((click.y - rect.min.y) / rect.height()) as f64,
    );
    let ray = loaded.camera.generate_ray(film, loaded.settings.aspect(), DVec2::splat(0.5));
    let hit = loaded
        .scene
        .intersect(&ray, f64::INFINITY)
        .expect("the click hits the sphere");
    let expected = loaded.camera.depth_of(hit.hit.point);

    let focus = harness.state().camera().expect("camera").focal_distance;
    // The same ray in the same f64 arithmetic: only float rounding separates them.
    assert!(
        (focus - expected).abs() < 1e-9 * expected,
        "focus {focus} vs expected {expected}"
    );
    assert!(
        (focus - initial_focus).abs() > 1.0,
        "the click changed the focus ({initial_focus} → {focus})"
    );
    assert!(
        expected < 1000.0,
        "the sphere (depth {expected}) is in front of the back wall (1355)"
    );
    step_until(&mut harness, "the render thread to focus there", |app| {
        app.render_stats().camera.is_some_and(|c| c.focal_distance == focus)
    });
}

#[test]
fn save_writes_a_valid_image_with_metadata() {
    let mut harness = start(None);
    step_until(&mut harness, "a full-resolution frame", |app| {
        app.displayed_frame().is_some_and(|f| !f.preview && f.passes >= 1)
    });
    // Pause so that the frame on screen stays the one that is saved.
    harness.get_by_label("Pause").click();
    step_until(&mut harness, "the pause", |app| {
        app.render_stats().state == SessionState::Paused
    });
    harness.step();
    let dir = scratch("save_writes_a_valid_image_with_metadata");
    let path = dir.join("snapshot.png");

    // The path field (the fallback when no file dialog can open), then Save.
    let field = harness.get_by_role_and_label(Role::TextInput, "Snapshot path");
    field.focus();
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::A);
    harness
        .get_by_role_and_label(Role::TextInput, "Snapshot path")
        .type_text(&path.display().to_string());
    harness.step();
    harness.get_by_label("Save").click();
    harness.step();
    harness.step();

    assert!(path.exists(), "{} was written", path.display());
    let saved = prism::output::load_frame(&path).expect("a readable PNG");
    let shown = harness.state().displayed_frame().cloned().expect("frame");
    assert_eq!((saved.width, saved.height), (shown.frame.width, shown.frame.height));
    // Exposure 0 and clamping: the file holds the shown frame up to 8-bit
    // sRGB quantisation, at most half a code × the decoding slope (≤ 2.3) ≈ 0.0045.
    let worst = saved
        .pixels
        .iter()
        .zip(&shown.frame.pixels)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c].clamp(0.0, 1.0)).abs()))
        .fold(0.0f32, f32::max);
    assert!(worst < 0.005, "largest pixel difference {worst}");

    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).expect("open")));
    let reader = decoder.read_info().expect("png header");
    let text: Vec<(String, String)> = reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect();
    let value = |key: &str| text.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
    assert_eq!(value("Scene").as_deref(), Some("<default scene>"));
    assert_eq!(value("Integrator").as_deref(), Some("pt"));
    assert_eq!(value("Seed").as_deref(), Some("0"));
    assert!(
        value("Samples per pixel").is_some_and(|v| v.parse::<u32>().is_ok_and(|n| n >= 1)),
        "{text:?}"
    );
    assert!(value("Render time").is_some(), "{text:?}");
}

#[test]
fn broken_scene_shows_its_error_in_the_window() {
    let dir = scratch("broken_scene_shows_its_error_in_the_window");
    let path = dir.join("broken.toml");
    std::fs::write(
        &path,
        "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov_y_degrees = \"wide\"\n",
    )
    .expect("write scene");
    let Err(error) = scene::load_scene_file(&path) else {
        panic!("the scene should be broken");
    };
    let expected = error.to_string();
    assert!(
        expected.contains("broken.toml:4"),
        "the error names file and line: {expected}"
    );

    let mut harness = start(Some(path.clone()));
    step_until(&mut harness, "the load to fail", |app| app.scene_error().is_some());
    harness.step();
    assert_eq!(harness.state().scene_error(), Some(expected.as_str()));
    assert!(
        harness.query_by_label(&expected).is_some(),
        "the error is shown in the window"
    );
    assert!(harness.state().displayed_frame().is_none());
}

#[test]
fn stop_and_resume_keep_the_samples() {
    let mut harness = start(None);
    step_until(&mut harness, "two passes", |app| app.render_stats().passes >= 2);
    harness.get_by_label("Stop").click();
    step_until(&mut harness, "the stop", |app| {
        app.render_stats().state == SessionState::Stopped
    });
    harness.step();
    let stopped = harness.state().render_stats();
    assert!(stopped.passes >= 2, "Stop kept the samples: {stopped:?}");
    harness.get_by_label("Resume").click();
    step_until(&mut harness, "more passes after Resume", |app| {
        app.render_stats().passes > stopped.passes
    });
    let resumed = harness.state().render_stats();
    assert_eq!(resumed.generation, stopped.generation, "the same accumulation continues");
}

#[test]
fn zooming_the_image_never_restarts_the_render() {
    let mut harness = start(None);
    step_until(&mut harness, "a full-resolution frame", |app| {
        app.displayed_frame().is_some_and(|f| !f.preview && f.passes >= 1)
    });
    let before = harness.state().render_stats();
    let image = harness.state().image_rect().expect("the image is drawn");
    harness.event(Event::PointerMoved(image.center()));
    harness.event(Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: Vec2::new(0.0, 120.0),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Wheel,
        modifiers: Modifiers::NONE,
    });
    harness.step();
    harness.step();
    let zoomed = harness.state().image_zoom().expect("the wheel zoomed the image");
    assert!(
        harness.state().image_rect().expect("drawn").width() > image.width() * 1.5,
        "{zoomed}"
    );
    harness.get_by_label("1:1").click();
    harness.step();
    assert_eq!(harness.state().image_zoom(), Some(1.0), "one image pixel per screen pixel");
    harness.get_by_label("Fit").click();
    harness.step();
    assert_eq!(harness.state().image_zoom(), None);
    // The camera and the accumulation are untouched: the same generation keeps adding passes.
    step_until(&mut harness, "a further pass", |app| {
        app.render_stats().passes > before.passes
    });
    let after = harness.state().render_stats();
    assert_eq!(after.generation, before.generation, "zoom restarted the render");
    assert_eq!(after.camera, before.camera);
}

/// The number field of the slider labelled `label` (the spin button on its row).
fn slider_field(harness: &Harness<'static, ViewerApp>, label: &str) -> egui::Rect {
    let slider = harness.get_by_role_and_label(Role::Slider, label).rect();
    harness
        .get_all_by_role(Role::SpinButton)
        .map(|node| node.rect())
        .find(|r| r.center().y > slider.top() && r.center().y < slider.bottom() && r.left() >= slider.right() - 1.0)
        .expect("the slider's number field")
}

fn type_into(harness: &mut Harness<'static, ViewerApp>, field: egui::Rect, text: &str) {
    // A click on a number field edits it.
    harness.event(Event::PointerMoved(field.center()));
    press(harness, field.center(), true);
    press(harness, field.center(), false);
    harness.step();
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::A);
    harness.event(Event::Text(text.to_string()));
    harness.key_press(egui::Key::Enter);
    harness.step();
    harness.step();
}

#[test]
fn a_typed_value_beyond_the_sliders_range_is_kept() {
    let mut harness = start(None);
    step_until(&mut harness, "the scene", |app| app.scene().is_some());
    harness.step();
    // The drag range of "Max depth" ends at 64; the scene format and --max-depth allow 1 to 1024.
    let field = slider_field(&harness, "Max depth");
    type_into(&mut harness, field, "100");
    assert_eq!(harness.state().settings().max_depth, 100, "the typed depth is kept");
    step_until(&mut harness, "the render thread's depth", |app| {
        app.render_stats().settings.max_depth == 100
    });
    // Zero is outside the format's limits: refused, the old value stays, and the window says why.
    let field = slider_field(&harness, "Max depth");
    type_into(&mut harness, field, "0");
    assert_eq!(harness.state().settings().max_depth, 100);
    assert!(
        harness.query_by_label_contains("max_depth: must be at least 1").is_some(),
        "the refusal is shown"
    );
}

#[test]
fn a_scene_opens_through_the_path_field() {
    let mut harness = start(None);
    step_until(&mut harness, "the default scene", |app| app.scene().is_some());
    let set_path = |harness: &mut Harness<'static, ViewerApp>, text: &str| {
        harness.get_by_role_and_label(Role::TextInput, "Scene path").focus();
        harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::A);
        harness.get_by_role_and_label(Role::TextInput, "Scene path").type_text(text);
        harness.step();
        harness.get_by_label("Open").click();
        harness.step();
    };
    set_path(&mut harness, "no/such/scene.toml");
    assert!(
        harness.query_by_label_contains("no such file").is_some(),
        "a missing file is reported"
    );
    let smallpt = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/smallpt.toml");
    set_path(&mut harness, &smallpt.display().to_string());
    step_until(&mut harness, "smallpt to load and render", |app| {
        // smallpt is 512 × 384: 64 × 48 at the tests' resolution scale.
        app.scene_name().ends_with("smallpt.toml") && app.displayed_frame().is_some_and(|f| f.frame.height == 48)
    });
    assert_eq!(harness.state().scene_error(), None);
}

/// The "Caustics from the lights" box turns the light paths off (they are
/// on by default) and restarts the render with that setting.
#[test]
fn the_caustics_box_switches_light_paths_and_restarts() {
    let mut harness = start(None);
    step_until(&mut harness, "a first pass", |app| app.render_stats().passes >= 1);
    assert!(harness.state().settings().caustic_light_paths, "on by default");
    let before = harness.state().render_stats().generation;
    harness.get_by_label("Caustics from the lights").click();
    step_until(&mut harness, "the restart", |app| app.render_stats().generation > before);
    assert!(!harness.state().settings().caustic_light_paths);
    harness.get_by_label("Caustics from the lights").click();
    harness.step();
    assert!(harness.state().settings().caustic_light_paths);
}
