//! Image files: every format round-trips, metadata is recorded, and writes are atomic.

mod common;
use common::ScratchDir;
use prism::film::{Frame, ToneMap};
use prism::output::{load_frame, save_frame};

fn frame() -> Frame {
    Frame {
        width: 3,
        height: 2,
        pixels: vec![
            [0.0, 0.25, 0.5],
            [1.0, 2.0, 4.0],
            [0.1, 0.2, 0.3],
            [0.9, 0.8, 0.7],
            [0.01, 0.02, 0.03],
            [0.5, 0.5, 0.5],
        ],
        noise: Vec::new(),
    }
}

/// The test's scratch directory, for the images it writes.
fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new("prism-output", test)
}

fn metadata() -> Vec<(String, String)> {
    vec![("Scene".into(), "scenes/cornell.toml".into()), ("Seed".into(), "7".into())]
}

#[test]
fn exr_is_linear_and_carries_metadata() {
    let dir = scratch("exr_is_linear_and_carries_metadata");
    let path = dir.join("a.exr");
    save_frame(&frame(), &path, 0.0, ToneMap::Clamp, &metadata()).expect("save");
    let back = load_frame(&path).expect("load");
    assert_eq!(back.pixels, frame().pixels, "EXR stores linear f32 exactly");
    let meta = exr::meta::MetaData::read_from_file(&path, false).expect("read header");
    let text = format!("{:?}", meta.headers[0].own_attributes.other);
    assert!(text.contains("Scene") && text.contains("scenes/cornell.toml"), "{text}");
}

#[test]
fn png_bmp_ppm_round_trip_within_8_bit_quantisation() {
    let dir = scratch("png_bmp_ppm_round_trip_within_8_bit_quantisation");
    for extension in ["png", "bmp", "ppm"] {
        let path = dir.join(format!("b.{extension}"));
        save_frame(&frame(), &path, 0.0, ToneMap::Clamp, &metadata()).expect("save");
        let back = load_frame(&path).expect("load");
        for (a, b) in frame().pixels.iter().zip(&back.pixels) {
            for c in 0..3 {
                // Clamp tone mapping, then one 8-bit sRGB step: under 0.01 in linear below 1.
                assert!((a[c].min(1.0) - b[c]).abs() < 0.01, "{extension}: {a:?} vs {b:?}");
            }
        }
    }
    let png = std::fs::read(dir.join("b.png")).expect("read");
    let needle = b"scenes/cornell.toml";
    assert!(
        png.windows(needle.len()).any(|w| w == needle),
        "PNG text chunk with the scene"
    );
}

#[test]
fn failed_write_leaves_nothing_behind() {
    let dir = scratch("failed_write_leaves_nothing_behind");
    let folder = dir.join("atomic");
    std::fs::create_dir_all(&folder).expect("dir");
    // A directory where the image should go makes the final rename fail.
    let target = folder.join("c.png");
    std::fs::create_dir_all(&target).expect("dir");
    let result = save_frame(&frame(), &target, 0.0, ToneMap::Clamp, &[]);
    assert!(result.is_err());
    let leftovers: Vec<_> = std::fs::read_dir(&folder)
        .expect("list")
        .filter_map(Result::ok)
        .map(|e| e.file_name())
        .collect();
    assert_eq!(leftovers.len(), 1, "temporary file left behind: {leftovers:?}");
    let unsupported = save_frame(&frame(), &folder.join("d.jpg"), 0.0, ToneMap::Clamp, &[]);
    assert!(unsupported.is_err_and(|e| e.to_string().contains("d.jpg")));
}

/// Reading an image back refuses what is not a regular file, naming it
/// once: a named pipe nobody writes to would block the reader (in the
/// viewer, its window) for ever.
#[test]
fn reading_refuses_what_is_not_an_image_file() {
    let dir = scratch("reading_refuses_what_is_not_an_image_file");
    let missing = dir.join("missing.exr");
    let error = load_frame(&missing).err().unwrap_or_default();
    assert_eq!(error, format!("{}: no such file", missing.display()));
    let error = load_frame(dir.path()).err().unwrap_or_default();
    assert_eq!(error, format!("{}: is a directory, not a file", dir.path().display()));
    let pipe = dir.join("pipe.exr");
    let made = std::process::Command::new("mkfifo").arg(&pipe).status();
    if made.is_ok_and(|status| status.success()) {
        let (sender, receiver) = std::sync::mpsc::channel();
        let reader_pipe = pipe.clone();
        std::thread::spawn(move || sender.send(load_frame(&reader_pipe).err()));
        let error = receiver
            .recv_timeout(std::time::Duration::from_secs(60))
            .expect("reading a named pipe did not return within 60 s")
            .unwrap_or_default();
        assert_eq!(
            error,
            format!("{}: is not a regular file (a device, pipe or socket)", pipe.display())
        );
    }
}
