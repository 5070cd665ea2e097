//! Time on a CPU of one `denoise` call on a 512 × 512 Cornell frame, on a
//! single worker thread: the thread's own run time from Linux's
//! `/proc/thread-self/schedstat`, which, unlike wall time, does not count the
//! time other processes on a shared machine hold the core. Prints the median
//! of seven calls, and the same for the first-hit guide pass.
//!
//! Run with `cargo run --release --example denoise_cost`; with the argument
//! `once` it renders 1 sample per pixel and filters once, for
//! `valgrind --tool=callgrind` (instruction counts).

use prism::denoise::{DenoiseSettings, Guides, denoise};
use prism::render::{RenderSettings, render_with_threads};
use prism::scene::load_scene_file;
use std::path::Path;
use std::time::Duration;

const SIZE: u32 = 512;
const CALLS: usize = 7;

/// This thread's time on a CPU so far, if the kernel reports it.
fn cpu_time() -> Option<Duration> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok().map(Duration::from_nanos)
}

fn median_cpu_ms(mut f: impl FnMut()) -> Option<f64> {
    let mut times = Vec::with_capacity(CALLS);
    for _ in 0..CALLS {
        let start = cpu_time()?;
        f();
        times.push((cpu_time()? - start).as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Some(times[CALLS / 2])
}

fn main() {
    let once = std::env::args().nth(1).is_some_and(|a| a == "once");
    let loaded = load_scene_file(Path::new("scenes/cornell.toml")).expect("scenes/cornell.toml loads");
    let settings = RenderSettings {
        width: SIZE,
        height: SIZE,
        samples_per_pixel: Some(if once { 1 } else { 4 }),
        time_limit: None,
        ..loaded.settings.clone()
    };
    let frame = render_with_threads(&loaded.scene, &loaded.camera, &settings, None)
        .expect("worker threads")
        .frame();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a worker thread");
    let denoise_settings = DenoiseSettings::default();
    pool.install(|| {
        let guides = Guides::first_hit(&loaded.scene, &loaded.camera, SIZE, SIZE);
        if once {
            std::hint::black_box(denoise(&frame, &guides, &denoise_settings).expect("same size"));
            return;
        }
        let filter = median_cpu_ms(|| {
            std::hint::black_box(denoise(&frame, &guides, &denoise_settings).expect("same size"));
        });
        let guide_pass = median_cpu_ms(|| {
            std::hint::black_box(Guides::first_hit(&loaded.scene, &loaded.camera, SIZE, SIZE));
        });
        match (filter, guide_pass) {
            (Some(filter), Some(guide_pass)) => println!(
                "{SIZE}x{SIZE}, one thread, median of {CALLS} (time on a CPU): denoise {filter:.1} ms, first-hit guides {guide_pass:.1} ms"
            ),
            _ => println!("no /proc/thread-self/schedstat: cannot measure time on a CPU here"),
        }
    });
}
