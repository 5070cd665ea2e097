//! `prism view --watch` driven through egui_kittest (no window): the window
//! shows the merge of a folder's film files as they arrive, with the parts,
//! samples and what is missing in its status line.

mod common;
use common::ScratchDir;
use egui::Vec2;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use prism::farm::file::write_film;
use prism::farm::{FilmHeader, PartRequest, content_hash, plan_share};
use prism::integrator::{self, Share};
use prism::render::{ProgressiveRender, RenderSettings};
use prism::scene::{DEFAULT_SCENE, LoadedScene, load_scene_str};
use prism::viewer::WatchApp;
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Generous: a loaded CI machine; a scan comes every half second.
const TIMEOUT: Duration = Duration::from_secs(30);

fn write_part(folder: &Path, loaded: &LoadedScene, settings: &RenderSettings, part: u32) {
    let share = plan_share(settings, &PartRequest::Part { part, parts: 2 }).expect("splits");
    let driver = RenderSettings {
        samples_per_pixel: Some(share.passes()),
        ..settings.clone()
    };
    let mut render = ProgressiveRender::with_integrator(integrator::create_share(settings, &share), &driver);
    render.run(&loaded.scene, &loaded.camera, &AtomicBool::new(false), |_| {
        ControlFlow::Continue(())
    });
    let hash = content_hash::scene_hash(&loaded.scene, &loaded.camera);
    let header = FilmHeader::new("cornell", settings, &hash, &share, settings.samples_per_pixel);
    let film = render.integrator().film().expect("film");
    write_film(&folder.join(format!("part-{part}.film")), &header, film).expect("writes");
}

fn step_until(harness: &mut Harness<'static, WatchApp>, what: &str, done: impl Fn(&WatchApp) -> bool) {
    let begun = Instant::now();
    while !done(harness.state()) {
        assert!(begun.elapsed() < TIMEOUT, "timed out waiting for {what}");
        harness.step();
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn the_watch_window_shows_parts_as_they_arrive() {
    // Declared first, so removed last: after the window and its scanning thread.
    let dir = ScratchDir::new("prism-viewer-watch", "the_watch_window_shows_parts_as_they_arrive");
    let folder = dir.path();
    let loaded = load_scene_str(DEFAULT_SCENE, Path::new("cornell"), Path::new(".")).expect("scene");
    let settings = RenderSettings {
        width: 16,
        height: 12,
        samples_per_pixel: Some(4),
        ..loaded.settings.clone()
    };
    let app = WatchApp::new(&egui::Context::default(), folder.to_path_buf()).expect("scanning thread");
    let mut harness = Harness::builder()
        .with_size(Vec2::new(800.0, 600.0))
        .build_ui_state(|ui, app: &mut WatchApp| app.show(ui), app);
    harness.step();
    harness.get_by_label_contains("Waiting for film files");

    write_part(folder, &loaded, &settings, 0);
    step_until(&mut harness, "the first part", |app| app.status().parts == 1);
    harness.step();
    harness.get_by_label_contains("1 parts merged, 384 of 768 samples (50.0%)");
    harness.get_by_label_contains("Still missing: samples 2..4 of every row");
    assert_eq!(harness.state().frame().map(|f| (f.width, f.height)), Some((16, 12)));

    write_part(folder, &loaded, &settings, 1);
    step_until(&mut harness, "the second part", |app| app.status().parts == 2);
    harness.step();
    harness.get_by_label_contains("2 parts merged, 768 of 768 samples (100.0%), noise");
    assert!(harness.query_by_label_contains("Still missing").is_none());
    // The frame shown is the whole render's.
    let mut whole = ProgressiveRender::with_integrator(integrator::create_share(&settings, &Share::whole(4)), &settings);
    whole.run(&loaded.scene, &loaded.camera, &AtomicBool::new(false), |_| {
        ControlFlow::Continue(())
    });
    assert_eq!(harness.state().frame(), Some(&whole.integrator().frame()));
}
