//! A render session: one named render thread that accumulates passes of an
//! integrator while another thread (the viewer's UI) watches and steers it.
//!
//! The owner sends commands over a channel and, for changes that alter the
//! image, raises an `AtomicBool` cancel flag so the pass in flight stops at
//! its next row. The thread then drains every pending command, starts a new
//! *generation* (a fresh integrator: accumulation restarts) and keeps
//! rendering. Pause, Stop, Resume and new sample or time targets keep the
//! generation: they take effect between passes, so nothing rendered is lost,
//! and a finished render whose target is raised simply continues.
//!
//! A region render (`RenderSettings::region`) samples only a rectangle; the
//! published frames show it over the last image of before (the backdrop). After each pass it publishes the frame and its statistics into
//! a shared slot (one mutex swap per pass; the pixel loop itself takes no
//! lock) and calls the `wake` callback. Frames carry the generation they
//! belong to, so a reader can tell a stale frame from a newer one.
//!
//! Invariants: the scene is an `Arc` that is never rebuilt here (camera and
//! sampling changes keep it and its BVH); the thread is joined in `Drop`.
//! Nothing here knows about any UI toolkit.

use super::progressive::{Progress, ProgressiveRender};
use crate::camera::Camera;
use crate::film::Frame;
use crate::integrator;
use crate::scene::Scene;
use crate::settings::{PixelRect, RenderSettings};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// After a restart, one pass is rendered at each of these fractions of the
/// resolution before accumulation starts at full resolution: 1/8 costs 1/64
/// of a pass, so the changed image appears almost at once, and each stage
/// sharpens it (minipath's coarse-then-refine). All stages together cost
/// 1/64 + 1/16 + 1/4 ≈ a third of one full pass, once per restart.
const PREVIEW_DIVISORS: [u32; 3] = [8, 4, 2];

/// Smallest preview worth publishing, in pixels.
const PREVIEW_MIN_PIXELS: usize = 32 * 32;

/// What the owner asks the render thread to do.
#[derive(Clone, Debug)]
pub enum Command {
    /// New sampling parameters (integrator, depth, resolution, sample target…): restart.
    SetSettings(RenderSettings),
    /// New camera (orbit, aperture, focus): restart, keep the scene.
    SetCamera(Camera),
    /// A new scene (already built): restart.
    SetScene(Arc<Scene>),
    /// Stop after the current pass and keep the accumulation.
    Pause,
    /// Continue a paused or stopped render where it was.
    Resume,
    /// End the render after the pass in flight, keeping the accumulation
    /// (`Resume` or a raised target continues it).
    Stop,
    /// New sample and time targets for the same accumulation: no restart.
    SetTargets(Option<u32>, Option<Duration>),
    /// Throw the accumulation away and start again with the same inputs.
    Restart,
    /// End the thread.
    Quit,
}

impl Command {
    /// Whether the command makes the pass in flight worthless.
    fn aborts_pass(&self) -> bool {
        matches!(
            self,
            Command::SetSettings(_) | Command::SetCamera(_) | Command::SetScene(_) | Command::Restart | Command::Quit
        )
    }
}

/// What the render thread is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SessionState {
    /// Waiting for a scene.
    #[default]
    Idle,
    /// Accumulating passes.
    Rendering,
    /// Paused by the owner; the accumulation is kept and `Resume` continues it.
    Paused,
    /// Stopped by the owner.
    Stopped,
    /// The sample target or time limit was reached.
    Finished,
}

/// Statistics of the current generation, updated after every pass.
#[derive(Clone, Debug, Default)]
pub struct RenderStats {
    /// Accumulation number: it grows by one on every restart.
    pub generation: u64,
    /// What the thread is doing.
    pub state: SessionState,
    /// Completed full-resolution passes (samples per pixel, or SPPM iterations).
    pub passes: u32,
    /// The sample target (passes), if any.
    pub target_passes: Option<u32>,
    /// Render time of this generation, pauses excluded.
    pub elapsed: Duration,
    /// The time limit, if any.
    pub time_limit: Option<Duration>,
    /// Pixel samples (or SPPM pixel updates) per second of render time.
    pub samples_per_second: f64,
    /// The integrator's own status line (e.g. the SPPM radius).
    pub integrator_status: String,
    /// When the pass in flight started (while rendering), so a reader can
    /// show the render time running between passes.
    pub pass_started: Option<Instant>,
    /// Samples dropped as NaN or infinite in this generation.
    pub rejected_samples: u64,
    /// The camera and settings the render thread is using now.
    pub camera: Option<Camera>,
    /// The settings the render thread is using now.
    pub settings: RenderSettings,
}

impl RenderStats {
    /// Where the render stands, as the progressive driver reports it.
    pub fn progress(&self) -> Progress {
        Progress {
            passes: self.passes,
            target_passes: self.target_passes,
            elapsed: self.elapsed,
            time_limit: self.time_limit,
        }
    }

    /// Estimated time until the sample target or the time limit, whichever comes first.
    pub fn remaining(&self) -> Option<Duration> {
        self.progress().remaining()
    }

    /// Render time as of `now`: the published time plus the pass in flight.
    pub fn live_elapsed(&self, now: Instant) -> Duration {
        self.elapsed + self.in_flight(now)
    }

    /// Estimated time left as of `now`, counting down during the pass in flight.
    pub fn live_remaining(&self, now: Instant) -> Option<Duration> {
        self.remaining().map(|r| r.saturating_sub(self.in_flight(now)))
    }

    fn in_flight(&self, now: Instant) -> Duration {
        match (self.state, self.pass_started) {
            (SessionState::Rendering, Some(start)) => now.saturating_duration_since(start),
            _ => Duration::ZERO,
        }
    }
}

/// A published frame and what it was rendered with.
#[derive(Clone, Debug)]
pub struct FrameInfo {
    /// The image: linear radiance at the frame's own (possibly preview)
    /// resolution.
    pub frame: Arc<Frame>,
    /// The generation (accumulation) the frame belongs to.
    pub generation: u64,
    /// Publication order; grows with every frame.
    pub sequence: u64,
    /// The camera the frame was rendered with.
    pub camera: Camera,
    /// The settings the frame was rendered with.
    pub settings: RenderSettings,
    /// Full-resolution passes in the frame (0 for a preview).
    pub passes: u32,
    /// Render time of the generation when the frame was published.
    pub elapsed: Duration,
    /// The coarse first pass of a generation.
    pub preview: bool,
    /// SPPM's per-pixel gather radius (row-major, 0 where none yet); `None`
    /// for other integrators.
    pub radii: Option<Arc<Vec<f32>>>,
    /// Samples per pixel where the integrator reports them (adaptive
    /// sampling and region renders make them differ between pixels).
    pub sample_counts: Option<Arc<Vec<u32>>>,
    /// Whether `frame.noise` is an estimate (see `Integrator::estimates_noise`).
    pub noise_estimated: bool,
    /// The rectangle rendered, for a region render.
    pub region: Option<PixelRect>,
}

/// What the render thread publishes: the latest frame and the current statistics.
/// The statistics may be of a newer generation than the frame (right after a
/// restart, before its first pass lands).
#[derive(Clone, Debug, Default)]
pub struct Published {
    /// The latest frame, if any pass has completed.
    pub frame: Option<FrameInfo>,
    /// Statistics of the current generation.
    pub stats: RenderStats,
}

/// Called by the render thread when something new was published.
pub type Wake = Box<dyn Fn() + Send>;

/// Owner's handle on the render thread.
pub struct RenderSession {
    commands: Sender<Command>,
    cancel: Arc<AtomicBool>,
    published: Arc<Mutex<Published>>,
    /// Generation the owner has asked for (the render thread catches up).
    requested_generation: u64,
    /// The settings last sent, to tell a new target from a restart.
    sent_settings: Option<RenderSettings>,
    thread: Option<JoinHandle<()>>,
}

/// Why a render session could not start.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// The render thread could not be spawned.
    #[error("cannot start the render thread: {0}")]
    Spawn(#[from] std::io::Error),
    /// The pool of render workers could not be created.
    #[error("cannot start the render worker threads: {0}")]
    Pool(#[from] rayon::ThreadPoolBuildError),
}

impl RenderSession {
    /// Starts the render thread with a pool of `threads` workers (all cores
    /// if 0), each raised to `niceness` (0 keeps the default priority). It
    /// idles until it has a scene and a camera.
    pub fn new(settings: RenderSettings, threads: usize, niceness: u8, wake: Wake) -> Result<Self, SessionError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("prism-render-worker-{i}"))
            .start_handler(move |_| lower_thread_priority(niceness))
            .build()?;
        let (commands, receiver) = mpsc::channel();
        let cancel = Arc::new(AtomicBool::new(false));
        let published = Arc::new(Mutex::new(Published::default()));
        let worker = Worker {
            commands: receiver,
            cancel: Arc::clone(&cancel),
            published: Arc::clone(&published),
            wake,
            pool,
            scene: None,
            camera: None,
            settings,
            generation: 0,
            mode: SessionState::Idle,
            render: None,
            sequence: 0,
            backdrop: None,
            last_frame: None,
        };
        let thread = std::thread::Builder::new()
            .name("prism-render".into())
            .spawn(move || worker.run())?;
        Ok(Self {
            commands,
            cancel,
            published,
            requested_generation: 0,
            sent_settings: None,
            thread: Some(thread),
        })
    }

    /// Sends a command; one that alters the image also aborts the pass in
    /// flight. Returns the generation the next frames will carry.
    pub fn send(&mut self, command: Command) -> u64 {
        let aborts = command.aborts_pass();
        if aborts {
            self.requested_generation += 1;
        }
        // Send first, then raise the flag: the thread clears the flag before
        // draining, so a raised flag always has its command in the queue.
        if self.commands.send(command).is_ok() && aborts {
            self.cancel.store(true, Ordering::Relaxed);
        }
        self.requested_generation
    }

    /// New settings: a restart, unless only the sample target or the time
    /// limit changed, which the accumulation takes on as it is.
    pub fn set_settings(&mut self, settings: RenderSettings) -> u64 {
        let only_targets = self.sent_settings.as_ref().is_some_and(|sent| {
            let mut same = settings.clone();
            (same.samples_per_pixel, same.time_limit) = (sent.samples_per_pixel, sent.time_limit);
            same == *sent
        });
        self.sent_settings = Some(settings.clone());
        if only_targets {
            self.send(Command::SetTargets(settings.samples_per_pixel, settings.time_limit))
        } else {
            self.send(Command::SetSettings(settings))
        }
    }

    /// Renders from `camera` from now on (a restart); returns the generation.
    pub fn set_camera(&mut self, camera: Camera) -> u64 {
        self.send(Command::SetCamera(camera))
    }

    /// Renders `scene` from now on (a restart); returns the generation.
    pub fn set_scene(&mut self, scene: Arc<Scene>) -> u64 {
        self.send(Command::SetScene(scene))
    }

    /// The generation of the most recent request; frames of older
    /// generations show a superseded image.
    pub fn requested_generation(&self) -> u64 {
        self.requested_generation
    }

    /// A copy of what was last published (the frame is shared, not copied).
    pub fn latest(&self) -> Published {
        lock(&self.published).clone()
    }
}

impl Drop for RenderSession {
    fn drop(&mut self) {
        let _ = self.commands.send(Command::Quit);
        self.cancel.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// Raises the calling thread's nice value so that, with every core
/// rendering, an interactive thread (the UI) still gets a core when it wakes:
/// CFS weighs nice 10 at about a tenth of nice 0. Linux only, and best effort:
/// `setpriority` on a thread id affects that thread alone, and `renice` is
/// used because this crate keeps `unsafe` to its AVX2 kernels alone.
fn lower_thread_priority(niceness: u8) {
    if niceness == 0 || !cfg!(target_os = "linux") {
        return;
    }
    // "/proc/thread-self" links to "<pid>/task/<tid>".
    let Some(thread_id) = std::fs::read_link("/proc/thread-self")
        .ok()
        .and_then(|link| link.file_name().map(|tid| tid.to_string_lossy().into_owned()))
    else {
        return;
    };
    let _ = std::process::Command::new("renice")
        .args(["-n", &niceness.to_string(), "-p", &thread_id])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status();
}

/// A poisoned slot only means a panic elsewhere; the data is still whole.
fn lock(published: &Mutex<Published>) -> MutexGuard<'_, Published> {
    published.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The render thread's state.
struct Worker {
    commands: Receiver<Command>,
    cancel: Arc<AtomicBool>,
    published: Arc<Mutex<Published>>,
    wake: Wake,
    pool: rayon::ThreadPool,
    scene: Option<Arc<Scene>>,
    camera: Option<Camera>,
    settings: RenderSettings,
    generation: u64,
    mode: SessionState,
    /// `None` until the first pass of a generation.
    render: Option<ProgressiveRender>,
    sequence: u64,
    /// What a region render is shown over: the last frame of before the region.
    backdrop: Option<Arc<Frame>>,
    /// The frame last published (after compositing).
    last_frame: Option<Arc<Frame>>,
}

/// What a batch of commands asks for.
enum Next {
    Continue,
    Quit,
}

impl Worker {
    fn run(mut self) {
        loop {
            // Block while there is nothing to render; otherwise just drain.
            self.cancel.store(false, Ordering::Relaxed);
            let first = if self.can_render() {
                None
            } else {
                match self.commands.recv() {
                    Ok(command) => Some(command),
                    Err(_) => return,
                }
            };
            let batch: Vec<Command> = first.into_iter().chain(self.commands.try_iter()).collect();
            if !batch.is_empty() {
                if let Next::Quit = self.apply(batch) {
                    return;
                }
                self.publish_stats();
                continue;
            }
            self.render_one_pass();
        }
    }

    fn can_render(&self) -> bool {
        self.scene.is_some() && self.camera.is_some() && self.mode == SessionState::Rendering
    }

    /// Applies a batch of commands in order; at most one restart results.
    fn apply(&mut self, batch: Vec<Command>) -> Next {
        let mut restart = false;
        for command in batch {
            // The owner counts generations the same way (see `RenderSession::send`).
            if command.aborts_pass() {
                self.generation += 1;
            }
            match command {
                Command::SetSettings(settings) => {
                    restart |= settings != self.settings;
                    self.settings = settings;
                }
                Command::SetCamera(camera) => {
                    restart |= Some(camera) != self.camera;
                    self.camera = Some(camera);
                }
                Command::SetScene(scene) => {
                    self.scene = Some(scene);
                    restart = true;
                }
                Command::Pause => {
                    if self.mode == SessionState::Rendering {
                        self.mode = SessionState::Paused;
                    }
                }
                Command::Resume => {
                    if matches!(self.mode, SessionState::Paused | SessionState::Stopped) {
                        self.mode = SessionState::Rendering;
                        self.finish_if_done();
                    }
                }
                Command::Stop => {
                    if matches!(self.mode, SessionState::Rendering | SessionState::Paused) {
                        self.mode = SessionState::Stopped;
                    }
                }
                Command::SetTargets(passes, time_limit) => {
                    (self.settings.samples_per_pixel, self.settings.time_limit) = (passes, time_limit);
                    if let Some(render) = self.render.as_mut() {
                        render.set_targets(passes, time_limit);
                    }
                    match self.mode {
                        // A finished render whose target was raised continues.
                        SessionState::Finished => self.mode = SessionState::Rendering,
                        SessionState::Rendering => {}
                        _ => continue,
                    }
                    self.finish_if_done();
                }
                Command::Restart => restart = true,
                Command::Quit => return Next::Quit,
            }
        }
        if restart {
            self.render = None;
            // A region is shown over the image of before it.
            self.backdrop = self.settings.region.and(self.last_frame.clone());
            // A change made while paused or stopped is shown at once: it renders.
            self.mode = SessionState::Rendering;
        }
        Next::Continue
    }

    /// Marks the render finished if its targets are already met.
    fn finish_if_done(&mut self) {
        if self.render.as_ref().is_some_and(ProgressiveRender::is_finished) {
            self.mode = SessionState::Finished;
        }
    }

    fn render_one_pass(&mut self) {
        let (Some(scene), Some(camera)) = (self.scene.clone(), self.camera) else {
            return;
        };
        if self.render.is_none() {
            let render = ProgressiveRender::new(&self.settings);
            // A region keeps the full image around it; coarse previews would replace it.
            let divisors = if self.settings.region.is_some() {
                &[][..]
            } else {
                &PREVIEW_DIVISORS[..]
            };
            for &divisor in divisors {
                self.render_preview(render.integrator(), &scene, &camera, divisor);
                if self.cancel.load(Ordering::Relaxed) {
                    return;
                }
            }
            self.render = Some(render);
        }
        self.publish_pass_start();
        let Some(render) = self.render.as_mut() else { return };
        let cancel = &self.cancel;
        let completed = self.pool.install(|| render.step(&scene, &camera, cancel));
        if !completed {
            // Whatever aborted the pass is in the queue; its state is unspecified.
            self.render = None;
            return;
        }
        if render.is_finished() {
            self.mode = SessionState::Finished;
        }
        // On the render pool: building a frame is a pass over every pixel
        // (see `Film::frame`), and the pool would otherwise idle through it.
        let (width, height) = (self.settings.width, self.settings.height);
        let region = self.settings.region.map(|r| r.pixels(width, height));
        let backdrop = self.backdrop.as_deref();
        let (frame, extras) = self.pool.install(move || {
            let integrator = render.integrator();
            let frame = match (region, backdrop) {
                // A region render shows its pixels over the image of before:
                // only they are computed, not the whole film (most of a pass's
                // time when the region is small).
                (Some(region), Some(backdrop)) if (backdrop.width, backdrop.height) == (width, height) => {
                    let (columns, rows) = (region.x0 as usize..region.x1 as usize, region.y0 as usize..region.y1 as usize);
                    match integrator.film() {
                        Some(film) => film.frame_over(backdrop, columns, rows),
                        None => {
                            let frame = integrator.frame();
                            let noise = |i: usize| frame.noise.get(i).copied().unwrap_or(f32::INFINITY);
                            backdrop.with_region(columns, rows, |i| (frame.pixels[i], noise(i)))
                        }
                    }
                }
                _ => integrator.frame(),
            };
            (frame, Extras::of(integrator))
        });
        self.publish(Some(frame), extras, false);
    }

    /// One pass at 1/`divisor` of the resolution, published as a stand-in
    /// until the first full pass lands; skipped if it would be tiny.
    fn render_preview(&mut self, full: &dyn integrator::Integrator, scene: &Scene, camera: &Camera, divisor: u32) {
        let preview_pixels = (self.settings.width / divisor).max(1) as usize * (self.settings.height / divisor).max(1) as usize;
        if preview_pixels < PREVIEW_MIN_PIXELS {
            return;
        }
        let mut preview = full.preview(divisor);
        let cancel = &self.cancel;
        if self.pool.install(|| preview.render_pass(scene, camera, cancel)) {
            // (Moved in as `&mut`: an integrator is `Send`, not `Sync`.)
            let preview = &mut preview;
            let (frame, extras) = self.pool.install(move || (preview.frame(), Extras::of(preview.as_ref())));
            self.publish(Some(frame), extras, true);
        }
    }

    /// Render time of this generation, pauses excluded.
    fn elapsed(&self) -> Duration {
        self.render
            .as_ref()
            .map_or(Duration::ZERO, |render| render.progress().elapsed)
    }

    fn stats(&self) -> RenderStats {
        let (passes, status, rejected) = match &self.render {
            Some(render) => {
                let integrator = render.integrator();
                (integrator.passes(), integrator.status(), integrator.rejected_samples())
            }
            None => (0, String::new(), 0),
        };
        let samples = passes as f64 * self.settings.sampled_pixels().pixel_count() as f64;
        RenderStats {
            generation: self.generation,
            state: self.mode,
            passes,
            target_passes: self.settings.samples_per_pixel,
            elapsed: self.elapsed(),
            time_limit: self.settings.time_limit,
            samples_per_second: samples / self.elapsed().as_secs_f64().max(1e-9),
            integrator_status: status,
            pass_started: None,
            rejected_samples: rejected,
            camera: self.camera,
            settings: self.settings.clone(),
        }
    }

    /// Replaces the published frame (if `frame` is given) and statistics, then wakes the owner.
    fn publish(&mut self, frame: Option<Frame>, extras: Extras, preview: bool) {
        let stats = self.stats();
        let info = match (frame, self.camera) {
            (Some(frame), Some(camera)) => {
                self.sequence += 1;
                let mut settings = self.settings.clone();
                settings.width = frame.width;
                settings.height = frame.height;
                // (A region render's frame comes composited over its backdrop.)
                let region = settings.region.map(|r| r.pixels(frame.width, frame.height));
                let frame = Arc::new(frame);
                self.last_frame = Some(Arc::clone(&frame));
                Some(FrameInfo {
                    frame,
                    generation: self.generation,
                    sequence: self.sequence,
                    camera,
                    settings,
                    passes: if preview { 0 } else { stats.passes },
                    elapsed: self.elapsed(),
                    preview,
                    radii: extras.radii.map(Arc::new),
                    sample_counts: extras.sample_counts.map(Arc::new),
                    noise_estimated: extras.noise_estimated,
                    region,
                })
            }
            _ => None,
        };
        {
            let mut slot = lock(&self.published);
            if let Some(info) = info {
                slot.frame = Some(info);
            }
            slot.stats = stats;
        }
        (self.wake)();
    }

    fn publish_stats(&mut self) {
        self.publish(None, Extras::default(), false);
    }

    /// Marks the start of a pass in the published statistics (no wake-up:
    /// the owner reads it with its next frame).
    fn publish_pass_start(&mut self) {
        let mut stats = self.stats();
        stats.pass_started = Some(Instant::now());
        lock(&self.published).stats = stats;
    }
}

/// What a frame is published with besides its pixels.
#[derive(Default)]
struct Extras {
    radii: Option<Vec<f32>>,
    sample_counts: Option<Vec<u32>>,
    noise_estimated: bool,
}

impl Extras {
    fn of(integrator: &dyn integrator::Integrator) -> Self {
        Self {
            radii: integrator.gather_radii(),
            sample_counts: integrator.sample_counts(),
            noise_estimated: integrator.estimates_noise(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{DEFAULT_SCENE, load_scene_str};
    use std::path::Path;

    fn session_on_default_scene(samples: Option<u32>) -> (RenderSession, Camera) {
        let loaded = load_scene_str(DEFAULT_SCENE, Path::new("cornell"), Path::new(".")).expect("default scene");
        let mut settings = loaded.settings.clone();
        (settings.width, settings.height, settings.samples_per_pixel) = (24, 24, samples);
        let mut session = RenderSession::new(settings, 1, 0, Box::new(|| {})).expect("session");
        session.set_camera(loaded.camera);
        session.set_scene(Arc::new(loaded.scene));
        (session, loaded.camera)
    }

    /// Polls the published state until `done` holds (10 s is ample for 24 × 24 pixels).
    fn wait_for(session: &RenderSession, what: &str, done: impl Fn(&Published) -> bool) -> Published {
        let start = Instant::now();
        loop {
            let published = session.latest();
            if done(&published) {
                return published;
            }
            assert!(
                start.elapsed() < Duration::from_secs(10),
                "timed out waiting for {what}: {:?}",
                published.stats
            );
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    #[test]
    fn camera_change_restarts_with_the_new_camera() {
        let (mut session, camera) = session_on_default_scene(Some(3));
        let first = wait_for(&session, "the first render", |p| p.stats.state == SessionState::Finished);
        assert_eq!(first.stats.passes, 3);
        let mut lens = camera;
        lens.aperture_radius = 5.0;
        let generation = session.set_camera(lens);
        let second = wait_for(&session, "the second render", |p| {
            p.stats.generation == generation && p.stats.state == SessionState::Finished
        });
        let frame = second.frame.expect("frame");
        assert_eq!(frame.camera.aperture_radius, 5.0);
        assert_eq!(frame.generation, generation);
        // Restarted: the target of 3 passes counts from the change, not from the start.
        assert_eq!(frame.passes, 3);
        assert!(generation > first.stats.generation);
    }

    #[test]
    fn pause_holds_the_accumulation_and_resume_continues_it() {
        let (mut session, _) = session_on_default_scene(None);
        wait_for(&session, "two passes", |p| p.stats.passes >= 2);
        session.send(Command::Pause);
        let paused = wait_for(&session, "the pause", |p| p.stats.state == SessionState::Paused);
        std::thread::sleep(Duration::from_millis(50));
        assert_eq!(session.latest().stats.passes, paused.stats.passes, "no passes while paused");
        session.send(Command::Resume);
        wait_for(&session, "more passes", |p| {
            p.stats.passes > paused.stats.passes && p.stats.state == SessionState::Rendering
        });
        session.send(Command::Stop);
        wait_for(&session, "the stop", |p| p.stats.state == SessionState::Stopped);
    }

    #[test]
    fn stop_keeps_the_samples_and_resume_continues_them() {
        let (mut session, _) = session_on_default_scene(None);
        wait_for(&session, "two passes", |p| p.stats.passes >= 2);
        session.send(Command::Stop);
        let stopped = wait_for(&session, "the stop", |p| p.stats.state == SessionState::Stopped);
        assert!(stopped.stats.passes >= 2, "the samples are kept: {:?}", stopped.stats);
        let frame = stopped.frame.expect("a frame");
        assert_eq!(frame.passes, stopped.stats.passes, "the image shown holds them");
        session.send(Command::Resume);
        let resumed = wait_for(&session, "more passes", |p| p.stats.passes > stopped.stats.passes);
        assert_eq!(resumed.stats.generation, stopped.stats.generation, "the same accumulation");
    }

    #[test]
    fn a_raised_target_continues_a_finished_render() {
        let loaded = load_scene_str(DEFAULT_SCENE, Path::new("cornell"), Path::new(".")).expect("default scene");
        let mut settings = loaded.settings.clone();
        (settings.width, settings.height, settings.samples_per_pixel) = (16, 16, Some(2));
        let mut session = RenderSession::new(settings.clone(), 1, 0, Box::new(|| {})).expect("session");
        session.set_settings(settings.clone());
        session.set_camera(loaded.camera);
        let generation = session.set_scene(Arc::new(loaded.scene));
        wait_for(&session, "the first target", |p| p.stats.state == SessionState::Finished);
        settings.samples_per_pixel = Some(4);
        assert_eq!(session.set_settings(settings), generation, "a new target is no restart");
        let more = wait_for(&session, "the raised target", |p| {
            p.stats.state == SessionState::Finished && p.stats.passes == 4
        });
        assert_eq!(more.stats.generation, generation);
        assert_eq!(more.frame.expect("a frame").passes, 4);
    }

    #[test]
    fn a_region_render_keeps_the_image_around_it() {
        let (mut session, _) = session_on_default_scene(Some(2));
        let full = wait_for(&session, "the full image", |p| p.stats.state == SessionState::Finished);
        let full_frame = full.frame.expect("a frame").frame;
        let mut settings = full.stats.settings.clone();
        settings.region = crate::settings::Region::from_corners([0.25, 0.25], [0.5, 0.75]);
        let generation = session.set_settings(settings);
        let region = wait_for(&session, "the region", |p| {
            p.stats.generation == generation && p.stats.state == SessionState::Finished
        });
        let info = region.frame.expect("a frame");
        let rect = info.region.expect("a region frame");
        assert_eq!(
            rect,
            PixelRect {
                x0: 6,
                y0: 6,
                x1: 12,
                y1: 18
            }
        );
        let counts = info.sample_counts.expect("path tracing counts samples");
        for y in 0..24 {
            for x in 0..24 {
                let i = (y * 24 + x) as usize;
                if rect.contains(x, y) {
                    assert_eq!(counts[i], 2, "({x}, {y}) rendered");
                } else {
                    assert_eq!(counts[i], 0, "({x}, {y}) not rendered");
                    assert_eq!(info.frame.pixels[i], full_frame.pixels[i], "({x}, {y}) kept");
                }
            }
        }
    }
}
