//! The denoised preview's worker thread: it filters the newest frame it is
//! given (older requests are dropped, so it never falls behind) and keeps
//! the first-hit guides of the current camera, scene and size, which only a
//! camera, scene or size change makes it recompute. The filter itself is
//! the library's `denoise` module; nothing here changes the render.

use crate::camera::Camera;
use crate::denoise::{self, DenoiseSettings, Guides};
use crate::film::Frame;
use crate::scene::Scene;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A frame to filter, and what its guides depend on.
pub struct Job {
    /// The frame's publication number, handed back with the result.
    pub sequence: u64,
    pub frame: Arc<Frame>,
    pub scene: Arc<Scene>,
    pub camera: Camera,
    /// Cap on luminance before filtering (the optional firefly clamp).
    pub firefly_clamp: Option<f32>,
}

/// A filtered frame.
pub struct Denoised {
    pub sequence: u64,
    pub frame: Arc<Frame>,
    /// Time the filter took (guides excluded).
    pub took: Duration,
}

#[derive(Default)]
struct Shared {
    job: Option<Job>,
    result: Option<Denoised>,
    quit: bool,
}

/// Owner's handle on the denoising thread.
pub struct Denoiser {
    shared: Arc<(Mutex<Shared>, Condvar)>,
    thread: Option<JoinHandle<()>>,
}

fn lock(shared: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    shared.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Denoiser {
    /// Starts the thread; `wake` is called when a result is ready.
    pub fn new(wake: Arc<dyn Fn() + Send + Sync>) -> std::io::Result<Self> {
        let shared = Arc::new((Mutex::new(Shared::default()), Condvar::new()));
        let worker = Arc::clone(&shared);
        let thread = std::thread::Builder::new()
            .name("prism-denoise".into())
            .spawn(move || run(&worker, wake.as_ref()))?;
        Ok(Self {
            shared,
            thread: Some(thread),
        })
    }

    /// Asks for `job`, replacing any request not yet started.
    pub fn request(&self, job: Job) {
        let (mutex, condvar) = &*self.shared;
        lock(mutex).job = Some(job);
        condvar.notify_one();
    }

    /// The newest result, once.
    pub fn take(&self) -> Option<Denoised> {
        lock(&self.shared.0).result.take()
    }
}

impl Drop for Denoiser {
    fn drop(&mut self) {
        let (mutex, condvar) = &*self.shared;
        lock(mutex).quit = true;
        condvar.notify_one();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn run(shared: &(Mutex<Shared>, Condvar), wake: &(dyn Fn() + Send + Sync)) {
    let (mutex, condvar) = shared;
    let mut guides: Option<((usize, Camera, u32, u32), Guides)> = None;
    let settings = DenoiseSettings::default();
    loop {
        let job = {
            let mut state = lock(mutex);
            loop {
                if state.quit {
                    return;
                }
                if let Some(job) = state.job.take() {
                    break job;
                }
                state = condvar.wait(state).unwrap_or_else(PoisonError::into_inner);
            }
        };
        let (width, height) = (job.frame.width, job.frame.height);
        let key = (Arc::as_ptr(&job.scene) as usize, job.camera, width, height);
        if guides.as_ref().is_none_or(|(k, _)| *k != key) {
            guides = Some((key, Guides::first_hit(&job.scene, &job.camera, width, height)));
        }
        let Some((_, guides)) = &guides else { continue };
        let start = Instant::now();
        let clamped;
        let input = match job.firefly_clamp {
            Some(max) => {
                let mut copy = (*job.frame).clone();
                denoise::clamp_fireflies(&mut copy, max);
                clamped = copy;
                &clamped
            }
            None => job.frame.as_ref(),
        };
        if let Ok(frame) = denoise::denoise(input, guides, &settings) {
            lock(mutex).result = Some(Denoised {
                sequence: job.sequence,
                frame: Arc::new(frame),
                took: start.elapsed(),
            });
            wake();
        }
    }
}
