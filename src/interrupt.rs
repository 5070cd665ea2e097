//! SIGINT and SIGTERM during `prism render`: the first asks the render to stop
//! after the pass in flight, so the image so far is saved (pbrt and Mitsuba
//! lose it); the second exits at once, removing the unfinished temporary
//! file so nothing half-written is left behind.
//!
//! The signals are received on a thread of their own through `signal-hook`'s
//! iterator (a self-pipe), so no Prism code runs inside a signal handler.

use anyhow::{Context, Result};
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::{Handle, Signals};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicI32, Ordering};
use std::thread::JoinHandle;

/// The signal-handling thread and what it has received.
pub struct Interrupt {
    /// The first signal received, 0 while none has been.
    first: Arc<AtomicI32>,
    handle: Handle,
    thread: Option<JoinHandle<()>>,
}

impl Interrupt {
    /// Starts listening; `temporary` is removed if a second signal ends the
    /// process before the image is saved.
    pub fn install(temporary: &Path) -> Result<Self> {
        let mut signals = Signals::new([SIGINT, SIGTERM]).context("cannot listen for SIGINT and SIGTERM")?;
        let handle = signals.handle();
        let first = Arc::new(AtomicI32::new(0));
        let seen = Arc::clone(&first);
        let temporary: PathBuf = temporary.to_path_buf();
        let thread = std::thread::Builder::new()
            .name("prism-signals".into())
            .spawn(move || {
                for signal in signals.forever() {
                    if seen.compare_exchange(0, signal, Ordering::SeqCst, Ordering::SeqCst).is_ok() {
                        eprintln!(
                            "\n{}: finishing the current pass, then saving the image (send it again to quit at once)",
                            name(signal)
                        );
                    } else {
                        let _ = std::fs::remove_file(&temporary);
                        eprintln!("\n{}: quitting without saving", name(signal));
                        std::process::exit(128 + signal);
                    }
                }
            })
            .context("cannot start the signal thread")?;
        Ok(Self {
            first,
            handle,
            thread: Some(thread),
        })
    }

    /// The first signal received, if any.
    pub fn received(&self) -> Option<i32> {
        match self.first.load(Ordering::SeqCst) {
            0 => None,
            signal => Some(signal),
        }
    }

    /// Stops listening and joins the thread.
    pub fn uninstall(mut self) {
        self.stop();
    }

    fn stop(&mut self) {
        self.handle.close();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

impl Drop for Interrupt {
    fn drop(&mut self) {
        self.stop();
    }
}

/// The signal's usual name.
pub fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "SIGINT",
        SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}
