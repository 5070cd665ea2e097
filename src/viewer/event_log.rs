//! The measurement log (`PRISM_VIEWER_LOG`): timestamped events on stderr,
//! the latency from each change to its first refreshed image, and once a
//! second the UI frame rate.

use crate::render::session::RenderStats;
use std::time::{Duration, Instant};

/// Timestamped events on stderr when `PRISM_VIEWER_LOG` is set.
pub(super) struct EventLog {
    pub enabled: bool,
    launched: Instant,
    pub first_image_logged: bool,
    /// Requests whose first frame has not been shown yet: (generation, sent at, what).
    pub pending: Vec<(u64, Instant, String)>,
    frames: u32,
    window_start: Instant,
    worst_frame: Duration,
    last_frame: Option<Instant>,
    /// Time spent in `ViewerApp::show` (layout and uploads, not painting) this second.
    busy: Duration,
    /// eframe's whole-frame time (layout, tessellation, GL painting, buffer swap) this second.
    frame_work: Duration,
    /// The UI thread's scheduler counters at the window's start (see [`SchedulerTimes`]).
    scheduler: Option<SchedulerTimes>,
}

/// The calling thread's time on a CPU and time spent runnable but waiting for
/// one (Linux `/proc/thread-self/schedstat`): a UI thread that waits long for
/// a CPU is starved by other threads, not slow itself.
#[derive(Clone, Copy, Debug)]
struct SchedulerTimes {
    running: Duration,
    waiting: Duration,
}

impl SchedulerTimes {
    fn now() -> Option<Self> {
        let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
        let mut fields = text.split_whitespace().map(|f| f.parse::<u64>().ok());
        let running = fields.next()??;
        let waiting = fields.next()??;
        Some(Self {
            running: Duration::from_nanos(running),
            waiting: Duration::from_nanos(waiting),
        })
    }
}

impl EventLog {
    pub fn new(enabled: bool, launched: Instant) -> Self {
        Self {
            enabled,
            launched,
            first_image_logged: false,
            pending: Vec::new(),
            frames: 0,
            window_start: Instant::now(),
            worst_frame: Duration::ZERO,
            last_frame: None,
            busy: Duration::ZERO,
            frame_work: Duration::ZERO,
            scheduler: None,
        }
    }

    /// Notes a denoised preview and how long its filter took.
    pub fn denoise(&self, took: Duration) {
        self.event(&format!("denoised preview in {:.1} ms", took.as_secs_f64() * 1e3));
    }

    pub fn event(&self, what: &str) {
        if self.enabled {
            eprintln!("[prism-viewer {:9.1} ms] {what}", self.launched.elapsed().as_secs_f64() * 1e3);
        }
    }

    /// Counts UI frames and prints the rate and the longest gap once a second,
    /// with where the time went: `busy` is this frame's layout and upload,
    /// `frame_work` eframe's measure of the previous whole frame (if known).
    pub fn frame_tick(&mut self, stats: &RenderStats, busy: Duration, frame_work: Option<Duration>) {
        if !self.enabled {
            return;
        }
        self.busy += busy;
        self.frame_work += frame_work.unwrap_or_default();
        if self.scheduler.is_none() {
            self.scheduler = SchedulerTimes::now();
        }
        let now = Instant::now();
        if let Some(last) = self.last_frame {
            self.worst_frame = self.worst_frame.max(now - last);
        }
        self.last_frame = Some(now);
        self.frames += 1;
        let window = now - self.window_start;
        if window >= Duration::from_secs(1) {
            let per_frame = |d: Duration| d.as_secs_f64() * 1e3 / self.frames.max(1) as f64;
            let scheduler = match (self.scheduler, SchedulerTimes::now()) {
                (Some(start), Some(end)) => format!(
                    ", ui thread on a CPU {:.0} ms and waiting for one {:.0} ms of {:.0} ms",
                    (end.running.saturating_sub(start.running)).as_secs_f64() * 1e3,
                    (end.waiting.saturating_sub(start.waiting)).as_secs_f64() * 1e3,
                    window.as_secs_f64() * 1e3
                ),
                _ => String::new(),
            };
            self.event(&format!(
                "ui {:.1} frames/s, longest frame gap {:.1} ms, {:.2} ms/frame in layout+upload, {:.2} ms/frame whole frame (paint+swap){scheduler}, render {:?} pass {} at {:.2} Msamples/s",
                self.frames as f64 / window.as_secs_f64(),
                self.worst_frame.as_secs_f64() * 1e3,
                per_frame(self.busy),
                per_frame(self.frame_work),
                stats.state,
                stats.passes,
                stats.samples_per_second / 1e6
            ));
            self.frame_work = Duration::ZERO;
            self.scheduler = SchedulerTimes::now();
            self.frames = 0;
            self.window_start = now;
            self.worst_frame = Duration::ZERO;
            self.busy = Duration::ZERO;
        }
    }
}
