//! A watched folder of parts (`prism view --watch`, without the window):
//! parts merge as they appear, the status says what is in and what is
//! missing, a part of another image or a broken file is left out and
//! named, temporary files are ignored, and the finished merge equals the
//! render of one process exactly.

mod common;
use common::{ScratchDir, shipped_scene};
use prism::farm::file::write_film;
use prism::farm::watch::FolderWatch;
use prism::farm::{FilmHeader, PartRequest, content_hash, plan_share};
use prism::film::Film;
use prism::integrator::{self, Share};
use prism::render::{ProgressiveRender, RenderSettings};
use prism::scene::LoadedScene;
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn render(loaded: &LoadedScene, settings: &RenderSettings, share: &Share) -> Film {
    let driver = RenderSettings {
        samples_per_pixel: Some(share.passes()),
        ..settings.clone()
    };
    let mut render = ProgressiveRender::with_integrator(integrator::create_share(settings, share), &driver);
    render.run(&loaded.scene, &loaded.camera, &AtomicBool::new(false), |_| {
        ControlFlow::Continue(())
    });
    render.integrator().film().expect("film").clone()
}

fn write_part(folder: &Path, name: &str, loaded: &LoadedScene, settings: &RenderSettings, part: u32) {
    let share = plan_share(settings, &PartRequest::Part { part, parts: 3 }).expect("splits");
    let hash = content_hash::scene_hash(&loaded.scene, &loaded.camera);
    let header = FilmHeader::new("cornell.toml", settings, &hash, &share, settings.samples_per_pixel);
    write_film(&folder.join(name), &header, &render(loaded, settings, &share)).expect("writes");
}

#[test]
fn a_watched_folder_merges_parts_as_they_arrive() {
    let dir = ScratchDir::new("prism-farm-watch", "a_watched_folder_merges_parts_as_they_arrive");
    let folder = dir.path();
    let loaded = shipped_scene("cornell.toml");
    let settings = RenderSettings {
        width: 12,
        height: 10,
        samples_per_pixel: Some(9),
        seed: 3,
        ..loaded.settings.clone()
    };
    let mut watch = FolderWatch::new(folder);
    assert!(!watch.scan().expect("lists"));
    assert_eq!((watch.status().parts, watch.frame()), (0, None));

    write_part(folder, "part-0.film", &loaded, &settings, 0);
    std::fs::write(folder.join(".part-1.film.123.tmp"), b"being written").expect("write");
    assert!(watch.scan().expect("lists"));
    let status = watch.status();
    assert_eq!(
        (status.parts, status.samples_held, status.samples_expected),
        (1, 12 * 10 * 3, 12 * 10 * 9)
    );
    assert_eq!(status.missing.to_string(), "samples 3..9 of every row");
    assert!(status.problems.is_empty(), "{:?}", status.problems);
    // Nothing new: nothing re-read, nothing changed.
    let generation = watch.generation();
    assert!(!watch.scan().expect("lists"));
    assert_eq!(watch.generation(), generation);

    // A part of another image and a file that is not a film are left out, named.
    let other = RenderSettings {
        seed: 4,
        ..settings.clone()
    };
    write_part(folder, "other-seed.film", &loaded, &other, 1);
    std::fs::write(folder.join("junk.film"), b"PRISMFLM").expect("write");
    watch.scan().expect("lists");
    let problems = watch.status().problems;
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(
        problems
            .iter()
            .any(|p| p.contains("other-seed.film: not a part of the same image") && p.contains("seed is 3 there but 4 here"))
    );
    assert!(problems.iter().any(|p| p.contains("junk.film: truncated")));
    std::fs::remove_file(folder.join("other-seed.film")).expect("remove");
    std::fs::remove_file(folder.join("junk.film")).expect("remove");

    write_part(folder, "part-1.film", &loaded, &settings, 1);
    write_part(folder, "part-2.film", &loaded, &settings, 2);
    assert!(watch.scan().expect("lists"));
    let status = watch.status();
    assert_eq!((status.parts, status.samples_held), (3, 12 * 10 * 9));
    assert!(status.missing.is_empty() && status.problems.is_empty(), "{status:?}");
    assert!(status.noise.is_some_and(|n| n > 0.0 && n.is_finite()));
    let whole = render(&loaded, &settings, &Share::whole(9));
    assert!(watch.film() == Some(&whole), "the watched merge differs from one run");

    // A part rewritten (a task re-run) is taken out by starting over.
    std::fs::remove_file(folder.join("part-1.film")).expect("remove");
    assert!(watch.scan().expect("lists"));
    assert_eq!(watch.status().parts, 2);
    write_part(folder, "part-1.film", &loaded, &settings, 1);
    watch.scan().expect("lists");
    assert!(watch.film() == Some(&whole));
}
