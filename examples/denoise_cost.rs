//! Time on a CPU of one `denoise` call on a 512 × 512 Cornell frame, on a
//! single worker thread: the thread's own run time from Linux's
//! `/proc/thread-self/schedstat`, which, unlike wall time, does not count the
//! time other processes on a shared machine hold the core (though it still
//! counts the cache and memory bandwidth they share). Prints the minimum and
//! the median of N calls (default 7), and the same for the first-hit guide pass.
//! Some kernels (virtual machines among them) update that run time only at
//! scheduler ticks (4 ms at 250 Hz), so the filter's wall time is printed
//! too: on a quiet machine it is the finer measure.
//!
//! Run with `cargo run --release --example denoise_cost [N]`; with the
//! argument `once` it renders 1 sample per pixel and filters once, for
//! `valgrind --tool=callgrind` (instruction counts).

use prism::denoise::{DenoiseSettings, Guides, denoise};
use prism::render::{RenderSettings, render_with_threads};
use prism::scene::load_scene_file;
use std::path::Path;
use std::time::{Duration, Instant};

const SIZE: u32 = 512;
const DEFAULT_CALLS: usize = 7;

/// This thread's time on a CPU so far, if the kernel reports it.
fn cpu_time() -> Option<Duration> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok().map(Duration::from_nanos)
}

/// The minimum and the median of `calls` measurements, in ms.
fn min_and_median(mut times: Vec<f64>) -> Option<(f64, f64)> {
    times.sort_by(f64::total_cmp);
    Some((*times.first()?, times[times.len() / 2]))
}

/// The minimum and the median time on a CPU of `calls` calls of `f`, in ms.
fn cpu_ms(calls: usize, mut f: impl FnMut()) -> Option<(f64, f64)> {
    let mut times = Vec::with_capacity(calls);
    for _ in 0..calls {
        let start = cpu_time()?;
        f();
        times.push((cpu_time()? - start).as_secs_f64() * 1e3);
    }
    min_and_median(times)
}

/// The minimum and the median wall time of `calls` calls of `f`, in ms.
fn wall_ms(calls: usize, mut f: impl FnMut()) -> Option<(f64, f64)> {
    let times = (0..calls)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    min_and_median(times)
}

fn main() {
    let argument = std::env::args().nth(1);
    let once = argument.as_deref() == Some("once");
    let calls = match argument.as_deref().filter(|_| !once) {
        Some(text) => match text.parse::<usize>() {
            Ok(calls) if calls > 0 => calls,
            _ => {
                eprintln!("denoise_cost: the argument is `once` or a number of calls (≥ 1), not `{text}`");
                std::process::exit(2);
            }
        },
        None => DEFAULT_CALLS,
    };
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
        let filter = cpu_ms(calls, || {
            std::hint::black_box(denoise(&frame, &guides, &denoise_settings).expect("same size"));
        });
        let guide_pass = cpu_ms(calls.min(DEFAULT_CALLS), || {
            std::hint::black_box(Guides::first_hit(&loaded.scene, &loaded.camera, SIZE, SIZE));
        });
        if let Some((wall_min, wall_median)) = wall_ms(calls, || {
            std::hint::black_box(denoise(&frame, &guides, &denoise_settings).expect("same size"));
        }) {
            println!(
                "{SIZE}x{SIZE}, one thread, wall time: denoise min {wall_min:.1} ms, median {wall_median:.1} ms ({calls} calls)"
            );
        }
        match (filter, guide_pass) {
            (Some((filter_min, filter_median)), Some((guide_min, guide_median))) => println!(
                "{SIZE}x{SIZE}, one thread, time on a CPU: denoise min {filter_min:.1} ms, median {filter_median:.1} ms \
                 ({calls} calls); first-hit guides min {guide_min:.1} ms, median {guide_median:.1} ms ({} calls)",
                calls.min(DEFAULT_CALLS)
            ),
            _ => println!("no /proc/thread-self/schedstat: cannot measure time on a CPU here"),
        }
    });
}
