//! The library side of `prism bench`: measurements that say how fast Prism
//! converges and how it scales, each written as CSV (with the machine load in
//! its header, since the numbers mean little without it) and drawn as PNG
//! (with the `plots` feature).
//!
//! - [`error_curves`]: error against a reference image at doubling wall times,
//!   one curve per integrator / sampler / adaptive configuration;
//! - [`scaling`]: BVH build time and ray cost against triangle count, render
//!   time against resolution and thread count;
//! - [`stress`]: extreme scenes, counting NaN samples, self-intersections and
//!   leaks through closed surfaces;
//! - [`rays`]: the ray core alone (closest hit and occlusion, coherent and
//!   incoherent rays, build time and memory) on the bunny and its subdivisions;
//! - [`throughput`]: samples per second of each scene on one and two threads;
//! - [`plot`]: the line plots (drawn only with the `plots` feature).

pub mod error_curves;
pub mod plot;
pub mod rays;
pub mod scaling;
pub mod sppm_schedules;
pub mod stress;
pub mod throughput;

use std::io::Write;
use std::path::Path;

/// Why a benchmark could not run or write its results.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// What the operating system reported.
        source: std::io::Error,
    },
    /// A benchmark scene did not load.
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    /// The reference image could not be made or read, or its size differs
    /// from the estimate's.
    #[error("reference image: {0}")]
    Reference(String),
    /// Drawing a plot failed.
    #[error("plot {path}: {message}")]
    Plot {
        /// The PNG file being drawn.
        path: String,
        /// The plotting library's message.
        message: String,
    },
    /// The benchmark's thread pool could not be created.
    #[error("cannot start worker threads: {0}")]
    Threads(#[from] rayon::ThreadPoolBuildError),
}

impl From<crate::metrics::SizeMismatch> for BenchError {
    /// An estimate and its reference image of different sizes.
    fn from(mismatch: crate::metrics::SizeMismatch) -> Self {
        let crate::metrics::SizeMismatch(estimate_width, estimate_height, width, height) = mismatch;
        BenchError::Reference(format!(
            "size {width}x{height} differs from the estimate's {estimate_width}x{estimate_height}"
        ))
    }
}

/// One line describing the machine, its load and this binary's build, for
/// CSV headers: the benchmarks share a machine, and a time means little
/// without its load, nor without the build that made it.
pub fn machine_note() -> String {
    let load = std::fs::read_to_string("/proc/loadavg").map_or_else(
        |_| "unknown".to_string(),
        |s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "),
    );
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!("{cores} logical cores, load average (1/5/15 min) {load}; {}", build_note())
}

/// How this binary was compiled: the same code runs faster when built for
/// a newer instruction set or with a profile (docs/performance.md,
/// "Profile-guided and host-tuned builds"), and which kernel the ray
/// queries chose at run time ([`crate::accel::kernel`]).
/// `benches/pgo/build.sh` sets `PRISM_PGO` while it compiles the
/// profile-guided binary.
pub fn build_note() -> String {
    let kind = if cfg!(debug_assertions) { "debug" } else { "release" };
    let instruction_set = if cfg!(target_feature = "avx512f") {
        "AVX-512"
    } else if cfg!(target_feature = "avx2") {
        "AVX2"
    } else if cfg!(target_arch = "x86_64") {
        "baseline x86-64"
    } else {
        std::env::consts::ARCH
    };
    let profile = if option_env!("PRISM_PGO").is_some() {
        ", profile-guided"
    } else {
        ""
    };
    let queries = match crate::accel::Kernel::chosen() {
        crate::accel::Kernel::Avx2 => "; ray queries and path loop compiled for AVX2, chosen at run time",
        crate::accel::Kernel::Portable => "",
    };
    format!("{kind} build for {instruction_set}{profile}{queries}")
}

/// A CSV table: `#` comment lines, a header, rows; written atomically.
pub struct Csv {
    /// Lines written before the header, each prefixed with `# ` (settings,
    /// machine load).
    pub comments: Vec<String>,
    /// Column names.
    pub header: Vec<&'static str>,
    /// Rows of already formatted cells, one per header column.
    pub rows: Vec<Vec<String>>,
}

impl Csv {
    /// An empty table with the given columns.
    pub fn new(header: Vec<&'static str>) -> Self {
        Self {
            comments: Vec::new(),
            header,
            rows: Vec::new(),
        }
    }

    /// The table as CSV text: comments, header, rows, each line ending in `\n`.
    /// Cells are not quoted, so they must not contain commas.
    pub fn to_text(&self) -> String {
        let mut text = String::new();
        for comment in &self.comments {
            text.push_str("# ");
            text.push_str(comment);
            text.push('\n');
        }
        text.push_str(&self.header.join(","));
        text.push('\n');
        for row in &self.rows {
            text.push_str(&row.join(","));
            text.push('\n');
        }
        text
    }

    /// Writes the table to `path` atomically (see [`write_atomically`]).
    pub fn write(&self, path: &Path) -> Result<(), BenchError> {
        write_atomically(path, self.to_text().as_bytes())
    }
}

/// Writes through a temporary file and a rename, so a reader never sees half a file.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), BenchError> {
    let io = |source| BenchError::Io {
        path: path.display().to_string(),
        source,
    };
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(io)?;
    }
    let temporary = path.with_extension("partial");
    let mut file = std::fs::File::create(&temporary).map_err(io)?;
    file.write_all(bytes).map_err(io)?;
    file.sync_all().map_err(io)?;
    std::fs::rename(&temporary, path).map_err(io)
}

/// A float for CSV: enough digits to plot, no thousands of them.
pub fn format_number(x: f64) -> String {
    format!("{x:.6e}")
}

/// CPU time the calling thread has spent running, from Linux's
/// `/proc/thread-self/schedstat` (nanoseconds on CPU); `None` elsewhere.
/// On a machine shared with other work, a single-threaded measurement's CPU
/// time is far steadier than its wall time.
pub fn thread_cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let nanoseconds: f64 = text.split_whitespace().next()?.parse().ok()?;
    Some(nanoseconds * 1e-9)
}

/// Wall and (where known) thread CPU time of `work`, in seconds.
pub fn time_thread<T>(work: impl FnOnce() -> T) -> (T, f64, Option<f64>) {
    let cpu_start = thread_cpu_seconds();
    let wall_start = std::time::Instant::now();
    let result = work();
    let wall = wall_start.elapsed().as_secs_f64();
    let cpu = cpu_start.and_then(|start| Some(thread_cpu_seconds()? - start));
    (result, wall, cpu)
}
