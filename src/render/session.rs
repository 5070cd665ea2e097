//! A render session: one named render thread that accumulates passes of an
//! integrator while another thread (the viewer's UI) watches and steers it.
//!
//! The owner sends commands over a channel and, for changes that alter the
//! image, raises an `AtomicBool` cancel flag so the pass in flight stops at
//! its next row. The thread then drains every pending command, starts a new
//! *generation* (a fresh integrator: accumulation restarts) and keeps
//! rendering. After each pass it publishes the frame and its statistics into
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
use crate::settings::RenderSettings;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration;

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
    /// Continue a paused render, or start again after `Stop` or a finished render.
    Resume,
    /// Abort now; the last published frame stays.
    Stop,
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
            Command::SetSettings(_)
                | Command::SetCamera(_)
                | Command::SetScene(_)
                | Command::Stop
                | Command::Restart
                | Command::Quit
        )
    }
}

/// What the render thread is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SessionState {
    /// Waiting for a scene.
    #[default]
    Idle,
    Rendering,
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
    pub state: SessionState,
    /// Completed full-resolution passes (samples per pixel, or SPPM iterations).
    pub passes: u32,
    pub target_passes: Option<u32>,
    /// Render time of this generation, pauses excluded.
    pub elapsed: Duration,
    pub time_limit: Option<Duration>,
    /// Pixel samples (or SPPM pixel updates) per second of render time.
    pub samples_per_second: f64,
    /// The integrator's own status line (e.g. the SPPM radius).
    pub integrator_status: String,
    pub rejected_samples: u64,
    /// The camera and settings the render thread is using now.
    pub camera: Option<Camera>,
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
}

/// A published frame and what it was rendered with.
#[derive(Clone, Debug)]
pub struct FrameInfo {
    pub frame: Arc<Frame>,
    /// The generation (accumulation) the frame belongs to.
    pub generation: u64,
    /// Publication order; grows with every frame.
    pub sequence: u64,
    pub camera: Camera,
    pub settings: RenderSettings,
    /// Full-resolution passes in the frame (0 for a preview).
    pub passes: u32,
    pub elapsed: Duration,
    /// The coarse first pass of a generation.
    pub preview: bool,
    /// SPPM's per-pixel gather radius (row-major, 0 where none yet); `None`
    /// for other integrators.
    pub radii: Option<Arc<Vec<f32>>>,
}

/// What the render thread publishes: the latest frame and the current statistics.
/// The statistics may be of a newer generation than the frame (right after a
/// restart, before its first pass lands).
#[derive(Clone, Debug, Default)]
pub struct Published {
    pub frame: Option<FrameInfo>,
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
    thread: Option<JoinHandle<()>>,
}

#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    #[error("cannot start the render thread: {0}")]
    Spawn(#[from] std::io::Error),
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
        };
        let thread = std::thread::Builder::new()
            .name("prism-render".into())
            .spawn(move || worker.run())?;
        Ok(Self {
            commands,
            cancel,
            published,
            requested_generation: 0,
            thread: Some(thread),
        })
    }

    /// Sends a command; one that alters the image also aborts the pass in
    /// flight. Returns the generation the next frames will carry.
    pub fn send(&mut self, command: Command) -> u64 {
        let aborts = command.aborts_pass();
        if aborts || matches!(command, Command::Resume) {
            self.requested_generation += 1;
        }
        // Send first, then raise the flag: the thread clears the flag before
        // draining, so a raised flag always has its command in the queue.
        if self.commands.send(command).is_ok() && aborts {
            self.cancel.store(true, Ordering::Relaxed);
        }
        self.requested_generation
    }

    pub fn set_settings(&mut self, settings: RenderSettings) -> u64 {
        self.send(Command::SetSettings(settings))
    }

    pub fn set_camera(&mut self, camera: Camera) -> u64 {
        self.send(Command::SetCamera(camera))
    }

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
/// used because this crate has no `unsafe` to call it directly.
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
            if command.aborts_pass() || matches!(command, Command::Resume) {
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
                Command::Resume => match self.mode {
                    SessionState::Paused => self.mode = SessionState::Rendering,
                    SessionState::Stopped | SessionState::Finished => restart = true,
                    SessionState::Idle | SessionState::Rendering => {}
                },
                Command::Stop => {
                    self.render = None;
                    self.mode = SessionState::Stopped;
                }
                Command::Restart => restart = true,
                Command::Quit => return Next::Quit,
            }
        }
        if restart {
            self.render = None;
            // A change made while paused or stopped is shown at once: it renders.
            self.mode = SessionState::Rendering;
        }
        Next::Continue
    }

    fn render_one_pass(&mut self) {
        let (Some(scene), Some(camera)) = (self.scene.clone(), self.camera) else {
            return;
        };
        if self.render.is_none() {
            let render = ProgressiveRender::new(&self.settings);
            for divisor in PREVIEW_DIVISORS {
                self.render_preview(render.integrator(), &scene, &camera, divisor);
                if self.cancel.load(Ordering::Relaxed) {
                    return;
                }
            }
            self.render = Some(render);
        }
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
        let integrator = render.integrator();
        let (frame, radii) = (integrator.frame(), integrator.gather_radii());
        self.publish(Some(frame), radii, false);
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
            self.publish(Some(preview.frame()), None, true);
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
        let samples = passes as f64 * self.settings.pixel_count() as f64;
        RenderStats {
            generation: self.generation,
            state: self.mode,
            passes,
            target_passes: self.settings.samples_per_pixel,
            elapsed: self.elapsed(),
            time_limit: self.settings.time_limit,
            samples_per_second: samples / self.elapsed().as_secs_f64().max(1e-9),
            integrator_status: status,
            rejected_samples: rejected,
            camera: self.camera,
            settings: self.settings.clone(),
        }
    }

    /// Replaces the published frame (if `frame` is given) and statistics, then wakes the owner.
    fn publish(&mut self, frame: Option<Frame>, radii: Option<Vec<f32>>, preview: bool) {
        let stats = self.stats();
        let info = match (frame, self.camera) {
            (Some(frame), Some(camera)) => {
                self.sequence += 1;
                let mut settings = self.settings.clone();
                settings.width = frame.width;
                settings.height = frame.height;
                Some(FrameInfo {
                    frame: Arc::new(frame),
                    generation: self.generation,
                    sequence: self.sequence,
                    camera,
                    settings,
                    passes: if preview { 0 } else { stats.passes },
                    elapsed: self.elapsed(),
                    preview,
                    radii: radii.map(Arc::new),
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
        self.publish(None, None, false);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{DEFAULT_SCENE, load_scene_str};
    use std::path::Path;
    use std::time::Instant;

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
}
