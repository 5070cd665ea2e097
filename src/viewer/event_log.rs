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
        }
    }

    pub fn event(&self, what: &str) {
        if self.enabled {
            eprintln!("[prism-viewer {:9.1} ms] {what}", self.launched.elapsed().as_secs_f64() * 1e3);
        }
    }

    /// Counts UI frames and prints the rate and the longest gap once a second.
    pub fn frame_tick(&mut self, stats: &RenderStats, busy: Duration) {
        if !self.enabled {
            return;
        }
        self.busy += busy;
        let now = Instant::now();
        if let Some(last) = self.last_frame {
            self.worst_frame = self.worst_frame.max(now - last);
        }
        self.last_frame = Some(now);
        self.frames += 1;
        let window = now - self.window_start;
        if window >= Duration::from_secs(1) {
            self.event(&format!(
                "ui {:.1} frames/s, longest frame gap {:.1} ms, {:.2} ms/frame in layout+upload, render {:?} pass {} at {:.2} Msamples/s",
                self.frames as f64 / window.as_secs_f64(),
                self.worst_frame.as_secs_f64() * 1e3,
                self.busy.as_secs_f64() * 1e3 / self.frames.max(1) as f64,
                stats.state,
                stats.passes,
                stats.samples_per_second / 1e6
            ));
            self.frames = 0;
            self.window_start = now;
            self.worst_frame = Duration::ZERO;
            self.busy = Duration::ZERO;
        }
    }
}
