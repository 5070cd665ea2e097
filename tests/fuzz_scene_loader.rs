//! A fuzz harness for the scene loader that runs on stable Rust: it mutates
//! the shipped scenes (and the corpus of interesting inputs in
//! tests/fuzz/corpus/) with structure-aware TOML mutations, adds random-byte
//! and random-token inputs, and checks that `load_scene_bytes` never panics
//! and never takes longer than a per-input time budget.
//!
//! `cargo test` runs a short round (2,000 inputs). CI runs a long one:
//! `PRISM_FUZZ_INPUTS=100000 cargo test --test fuzz_scene_loader -- --nocapture`,
//! which prints the counts. Other knobs: `PRISM_FUZZ_SEED`,
//! `PRISM_FUZZ_BUDGET_MS` (per input, default 2000), and
//! `PRISM_FUZZ_SAVE=dir`, which writes every input whose outcome (the error's
//! field path and message with numbers and names blanked, or "loaded") was
//! not seen before: the source of the committed corpus.
//!
//! Inputs are loaded from tests/fuzz/corpus/, so relative mesh and image
//! paths (`../assets/bunny.obj`) find the tiny stand-ins in tests/fuzz/assets/.
//! A panicking or hanging input is written to the system temp folder and
//! named in the failure.

use prism::scene::{SceneError, load_scene_bytes};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// SplitMix64 (Steele, Lea & Flood 2014): small, fast, and enough to drive
/// mutations reproducibly from one seed per input.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in 0..n (n > 0).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    fn word(&mut self, words: &[&'static str]) -> &'static str {
        words[self.below(words.len())]
    }

    fn pool(&mut self, pools: &[&'static [&'static str]]) -> &'static [&'static str] {
        pools[self.below(pools.len())]
    }
}

/// Values that sit on or beyond the loader's limits.
const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1",
    "0.5",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "+nan",
    "2147483647",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "-9223372036854775808",
    "1e-320",
    "5e-324",
    "65536",
    "65537",
    "1024",
    "1025",
    "1e12",
    "1.0000001e12",
    "-1e12",
    "100000",
    "15000",
    "256",
    "1e-12",
    "0x10",
    "1_000",
    "3.",
    ".5",
    "1e",
];
/// Names the loader knows, and a few it must refuse.
const STRINGS: &[&str] = &[
    "\"sphere\"",
    "\"box\"",
    "\"quad\"",
    "\"triangle\"",
    "\"mesh\"",
    "\"revolution\"",
    "\"diffuse\"",
    "\"glass\"",
    "\"glossy\"",
    "\"mirror\"",
    "\"emissive\"",
    "\"D65\"",
    "\"A\"",
    "\"pt\"",
    "\"pt-bsdf\"",
    "\"sppm\"",
    "\"sobol\"",
    "\"random\"",
    "\"uv\"",
    "\"sphere\"",
    "\"planar\"",
    "\"repeat\"",
    "\"clamp\"",
    "\"/dev/zero\"",
    "\"/\"",
    "\"\"",
    "\".\"",
    "\"../assets/bunny.obj\"",
    "\"../assets/bunny.mtl\"",
    "\"../assets/earth.png\"",
    "\"../assets\"",
    "\"no-such-file.obj\"",
    "\"white\"",
    "\"light\"",
    "\"\\u0000\"",
    "'literal'",
    "\"\"\"multi\nline\"\"\"",
];
/// Whole values of other shapes, to meet type checks.
const VALUES: &[&str] = &[
    "[]",
    "[0, 0]",
    "[0, 0, 0]",
    "[1, 1, 1, 1]",
    "[[0, 0, 0], [1, 0, 0], [0, 1, 0]]",
    "[[0, 0], [1, 1]]",
    "{}",
    "{ image = \"../assets/earth.png\" }",
    "{ checker = [[0, 0, 0], [1, 1, 1]] }",
    "{ gradient = [[0, 0, 0], [1, 1, 1]], axis = [0, 0, 0] }",
    "{ scale = 0 }",
    "{ translate = [1e12, 0, 0], scale = 1e12 }",
    "true",
    "1979-05-27T07:32:00Z",
    "[1, \"a\"]",
];
/// Keys and headers from the scene format, to splice in.
const KEYS: &[&str] = &[
    "type",
    "center",
    "radius",
    "material",
    "min",
    "max",
    "corner",
    "edge_u",
    "edge_v",
    "vertices",
    "file",
    "transform",
    "translate",
    "rotate_degrees",
    "scale",
    "profile",
    "segments",
    "caps",
    "albedo",
    "tint",
    "ior",
    "roughness",
    "radiance",
    "two_sided",
    "spectrum",
    "temperature",
    "luminance",
    "position",
    "look_at",
    "up",
    "fov_y_degrees",
    "aperture_radius",
    "focal_distance",
    "near_clip",
    "width",
    "height",
    "spp",
    "max_depth",
    "integrator",
    "sampler",
    "seed",
    "photons_per_iteration",
    "initial_radius",
    "alpha",
    "adaptive_threshold",
    "background",
    "image",
    "checker",
    "gradient",
    "mapping",
    "wrap",
    "axis",
    "from",
    "to",
    "origin",
    "[[objects]]",
    "[camera]",
    "[render]",
    "[materials.x]",
    "[objects]",
    "[[materials]]",
    "a.b.c",
    "\"quoted key\"",
];
const BYTES: &[u8] = b"[]{}\"'=,.\n#-+e0123456789 \t\\\0\xff\xc3";

/// One mutated input: 1 to 4 mutations of a seed, or (1 in 16) random bytes
/// or tokens.
fn generate(seeds: &Seeds, rng: &mut Rng) -> Vec<u8> {
    match rng.below(16) {
        0 => (0..rng.below(512)).map(|_| rng.next() as u8).collect(),
        1 => {
            let mut text = String::new();
            for _ in 0..rng.below(64) {
                const PUNCTUATION: &[&str] = &["=", "\n", "[", "]", ",", "{", "}", " "];
                let pool = rng.pool(&[KEYS, NUMBERS, STRINGS, VALUES, PUNCTUATION]);
                text.push_str(rng.word(pool));
                text.push_str(rng.word(&[" ", "\n", " = ", ""]));
            }
            text.into_bytes()
        }
        _ => {
            // Three inputs in four start from a shipped scene or reproducer,
            // so mutations reach the builder, not only the parser.
            let pool = if rng.below(4) > 0 || seeds.corpus.is_empty() {
                &seeds.scenes
            } else {
                &seeds.corpus
            };
            let mut input = rng.pick(pool).clone();
            for _ in 0..1 + rng.below(4) {
                mutate(&mut input, &seeds.scenes, rng);
            }
            input
        }
    }
}

/// Byte offsets of the starts of lines.
fn line_starts(input: &[u8]) -> Vec<usize> {
    std::iter::once(0)
        .chain(input.iter().enumerate().filter(|(_, b)| **b == b'\n').map(|(i, _)| i + 1))
        .filter(|&i| i <= input.len())
        .collect()
}

fn line_range(input: &[u8], rng: &mut Rng) -> std::ops::Range<usize> {
    let starts = line_starts(input);
    let k = rng.below(starts.len());
    let start = starts[k];
    let end = starts.get(k + 1).copied().unwrap_or(input.len());
    start..end
}

/// Ranges of number-like and string tokens (for value replacement).
fn tokens(input: &[u8], strings: bool) -> Vec<std::ops::Range<usize>> {
    let mut found = Vec::new();
    let mut i = 0;
    while i < input.len() {
        let b = input[i];
        if strings && b == b'"' {
            let end = input[i + 1..]
                .iter()
                .position(|&c| c == b'"' || c == b'\n')
                .map_or(input.len(), |e| i + 2 + e);
            found.push(i..end.min(input.len()));
            i = end;
        } else if !strings && (b.is_ascii_digit() || b == b'-') {
            let end = input[i..]
                .iter()
                .position(|c| !(c.is_ascii_alphanumeric() || b"+-._".contains(c)))
                .map_or(input.len(), |e| i + e);
            found.push(i..end);
            i = end;
        } else {
            i += 1;
        }
    }
    found
}

fn mutate(input: &mut Vec<u8>, seeds: &[Vec<u8>], rng: &mut Rng) {
    let len = input.len();
    match rng.below(13) {
        // Byte-level: flip a bit, set a byte, insert bytes, delete a range.
        0 if len > 0 => {
            let i = rng.below(len);
            input[i] ^= 1 << rng.below(8);
        }
        1 if len > 0 => {
            let i = rng.below(len);
            input[i] = *rng.pick(BYTES);
        }
        2 => {
            let at = rng.below(len + 1);
            let bytes: Vec<u8> = (0..1 + rng.below(8)).map(|_| *rng.pick(BYTES)).collect();
            input.splice(at..at, bytes);
        }
        3 if len > 0 => {
            let start = rng.below(len);
            let end = (start + 1 + rng.below(32)).min(len);
            input.drain(start..end);
        }
        // Line-level: delete, duplicate, swap, splice from another scene.
        4 => {
            let range = line_range(input, rng);
            input.drain(range);
        }
        5 => {
            let range = line_range(input, rng);
            let line = input[range.clone()].to_vec();
            input.splice(range.start..range.start, line);
        }
        6 => {
            let a = line_range(input, rng);
            let b = line_range(input, rng);
            if a.end <= b.start {
                let (first, second) = (input[a.clone()].to_vec(), input[b.clone()].to_vec());
                input.splice(b, first);
                input.splice(a, second);
            }
        }
        7 => {
            let other = rng.pick(seeds);
            let range = line_range(other, rng);
            let line = other[range].to_vec();
            let at = *rng.pick(&line_starts(input));
            input.splice(at..at, line);
        }
        // Value-level: numbers, strings, whole values, keys.
        8 | 9 => {
            let numbers = tokens(input, false);
            if !numbers.is_empty() {
                let range = rng.pick(&numbers).clone();
                input.splice(range, rng.word(NUMBERS).bytes());
            }
        }
        10 => {
            let strings = tokens(input, true);
            if !strings.is_empty() {
                let range = rng.pick(&strings).clone();
                input.splice(range, rng.word(STRINGS).bytes());
            }
        }
        11 => {
            let range = line_range(input, rng);
            if let Some(eq) = input[range.clone()].iter().position(|&b| b == b'=') {
                let value_start = range.start + eq + 1;
                let value_end = range.end.saturating_sub(1).max(value_start);
                let value = format!(" {}", rng.word(VALUES));
                input.splice(value_start..value_end, value.bytes());
            }
        }
        12 => {
            let range = line_range(input, rng);
            let pool = rng.pool(&[NUMBERS, STRINGS, VALUES]);
            let line = format!("{} = {}\n", rng.word(KEYS), rng.word(pool));
            input.splice(range.start..range.start, line.bytes());
        }
        _ => input.truncate(rng.below(len + 1)),
    }
}

/// An outcome's shape, for spotting inputs that reach new code: the field
/// path (indices blanked) and the start of the message with numbers and
/// quoted text blanked.
fn signature(outcome: &Result<(), SceneError>) -> String {
    let Err(error) = outcome else {
        return "loaded".into();
    };
    let field = error.field.as_deref().unwrap_or("-");
    let mut shape = String::new();
    let mut in_index = false;
    for c in field.chars() {
        match c {
            '[' => in_index = true,
            ']' => in_index = false,
            c if !in_index => shape.push(c),
            _ => {}
        }
    }
    shape.push_str(": ");
    let mut quoted: Option<char> = None;
    for c in error.message.chars() {
        match (quoted, c) {
            (Some(q), c) if c == q => quoted = None,
            (Some(_), _) => {}
            (None, '"' | '`') => {
                quoted = Some(c);
                shape.push('Q');
            }
            (None, c) if c.is_ascii_digit() => {
                if !shape.ends_with('N') {
                    shape.push('N');
                }
            }
            (None, c) => shape.push(c),
        }
    }
    shape
}

/// A coarser shape for choosing the corpus: the message's first three
/// words (mutated keys make field paths too varied to group by).
fn corpus_key(signature: &str) -> String {
    let message = signature.split_once(": ").map_or(signature, |(_, m)| m);
    let words: Vec<&str> = message.split_whitespace().take(3).collect();
    words.join(" ")
}

/// What inputs start from: the shipped scenes and the reproducers (valid or
/// nearly), and the corpus (mostly broken already).
struct Seeds {
    scenes: Vec<Vec<u8>>,
    corpus: Vec<Vec<u8>>,
}

/// The `.toml` files in `folders` under `root`, in name order.
fn read_toml_files(root: &Path, folders: &[&str]) -> Vec<Vec<u8>> {
    let mut files = Vec::new();
    for folder in folders {
        if let Ok(entries) = std::fs::read_dir(root.join(folder)) {
            files.extend(entries.filter_map(|e| e.ok()).map(|e| e.path()));
        }
    }
    files.retain(|p| p.extension().is_some_and(|e| e == "toml"));
    files.sort();
    files.iter().filter_map(|p| std::fs::read(p).ok()).collect()
}

fn env_number(name: &str, default: u64) -> u64 {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// How the inputs fared, for the summary.
#[derive(Default)]
struct Counts {
    loaded: AtomicUsize,
    with_field: AtomicUsize,
    without_location: AtomicUsize,
    not_utf8: AtomicUsize,
}

impl Counts {
    fn add(&self, outcome: &Result<(), SceneError>) {
        let count = |counter: &AtomicUsize, yes: bool| counter.fetch_add(usize::from(yes), Ordering::Relaxed);
        match outcome {
            Ok(()) => count(&self.loaded, true),
            Err(e) => {
                count(&self.without_location, e.location.is_none());
                count(&self.not_utf8, e.message.starts_with("the file is not valid UTF-8"));
                count(&self.with_field, e.field.is_some())
            }
        };
    }
}

/// Loads one input the way `prism render` would.
fn load(input: &[u8], base: &Path) -> Result<(), SceneError> {
    load_scene_bytes(input, Path::new("fuzz.toml"), base).map(|_| ())
}

/// Writes a failing input where a developer can find it.
fn keep(kind: &str, index: u64, input: &[u8]) -> PathBuf {
    let path = std::env::temp_dir().join(format!("prism-fuzz-{kind}-{index}.toml"));
    let _ = std::fs::write(&path, input);
    path
}

#[test]
fn the_corpus_loads_or_fails_cleanly() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = root.join("tests/fuzz/corpus");
    let mut count = 0;
    for entry in std::fs::read_dir(&base).expect("corpus folder").filter_map(|e| e.ok()) {
        let input = std::fs::read(entry.path()).expect("read");
        let started = Instant::now();
        let outcome = std::panic::catch_unwind(|| load(&input, &base));
        assert!(outcome.is_ok(), "{}: panicked", entry.path().display());
        assert!(
            started.elapsed() < Duration::from_secs(2),
            "{}: too slow",
            entry.path().display()
        );
        if let Ok(Err(error)) = outcome {
            // Every error has a location, except a file that is not TOML at all.
            assert!(error.location.is_some(), "{error}");
        }
        count += 1;
    }
    assert!(count >= 20, "the corpus has only {count} inputs");
}

#[test]
fn mutated_scenes_never_panic_or_hang() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = Arc::new(root.join("tests/fuzz/corpus"));
    let seeds = Arc::new(Seeds {
        scenes: read_toml_files(root, &["scenes", "tests/scenes/reproducers"]),
        corpus: read_toml_files(root, &["tests/fuzz/corpus"]),
    });
    assert!(seeds.scenes.len() >= 8, "no seed scenes found");
    let inputs = env_number("PRISM_FUZZ_INPUTS", 2_000);
    let seed = env_number("PRISM_FUZZ_SEED", 1);
    let budget = Duration::from_millis(env_number("PRISM_FUZZ_BUDGET_MS", 2_000));
    let save = std::env::var_os("PRISM_FUZZ_SAVE").map(PathBuf::from);
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get()).min(4);

    // Work is handed out by index; each input is a pure function of (seed,
    // index), so a failure is reproducible whatever the thread count.
    let next = Arc::new(AtomicU64::new(0));
    // Per worker: the index being loaded and when it started (u64::MAX: idle).
    let current: Arc<Vec<Mutex<(u64, Instant)>>> =
        Arc::new((0..workers).map(|_| Mutex::new((u64::MAX, Instant::now()))).collect());
    let panics = Arc::new(Mutex::new(Vec::new()));
    let signatures = Arc::new(Mutex::new(BTreeMap::<String, usize>::new()));
    let corpus_keys = Arc::new(Mutex::new(BTreeMap::<String, usize>::new()));
    let counts = Arc::new(Counts::default());
    let slowest = Arc::new(Mutex::new(Duration::ZERO));
    // A panic is counted and its input kept; the default hook's report of
    // it would only interleave with the summary.
    std::panic::set_hook(Box::new(|_| {}));
    let started = Instant::now();
    let handles: Vec<_> = (0..workers)
        .map(|w| {
            let (next, current, panics, signatures, corpus_keys, counts, slowest, seeds, base, save) = (
                Arc::clone(&next),
                Arc::clone(&current),
                Arc::clone(&panics),
                Arc::clone(&signatures),
                Arc::clone(&corpus_keys),
                Arc::clone(&counts),
                Arc::clone(&slowest),
                Arc::clone(&seeds),
                Arc::clone(&base),
                save.clone(),
            );
            std::thread::spawn(move || {
                loop {
                    let index = next.fetch_add(1, Ordering::SeqCst);
                    if index >= inputs {
                        break;
                    }
                    let mut rng = Rng(seed.wrapping_mul(0x1000_0000_01B3) ^ index);
                    let input = generate(&seeds, &mut rng);
                    if let Ok(mut slot) = current[w].lock() {
                        *slot = (index, Instant::now());
                    }
                    let began = Instant::now();
                    let outcome = std::panic::catch_unwind(|| load(&input, &base));
                    let took = began.elapsed();
                    if let Ok(mut slot) = current[w].lock() {
                        slot.0 = u64::MAX;
                    }
                    if let Ok(mut s) = slowest.lock() {
                        *s = (*s).max(took);
                    }
                    let outcome = match outcome {
                        Ok(outcome) => outcome,
                        Err(_) => {
                            if let Ok(mut p) = panics.lock() {
                                p.push(keep("panic", index, &input));
                            }
                            continue;
                        }
                    };
                    counts.add(&outcome);
                    let shape = signature(&outcome);
                    let key = corpus_key(&shape);
                    if let Ok(mut s) = signatures.lock() {
                        *s.entry(shape).or_default() += 1;
                    }
                    let new = corpus_keys.lock().is_ok_and(|mut s| {
                        let count = s.entry(key).or_default();
                        *count += 1;
                        *count == 1
                    });
                    if let (true, Some(dir), true) = (new, &save, input.len() <= 4096) {
                        let _ = std::fs::create_dir_all(dir);
                        let _ = std::fs::write(dir.join(format!("input-{index}.toml")), &input);
                    }
                }
            })
        })
        .collect();

    // The watchdog: an input running past the budget is a hang. Its thread
    // cannot be stopped, so the run ends here with the input kept.
    let mut hang = None;
    while handles.iter().any(|h| !h.is_finished()) {
        std::thread::sleep(Duration::from_millis(50));
        for slot in current.iter() {
            if let Ok(slot) = slot.lock()
                && slot.0 != u64::MAX
                && slot.1.elapsed() > budget
            {
                let mut rng = Rng(seed.wrapping_mul(0x1000_0000_01B3) ^ slot.0);
                hang = Some(keep("hang", slot.0, &generate(&seeds, &mut rng)));
            }
        }
        if hang.is_some() {
            break;
        }
    }
    let elapsed = started.elapsed();
    let _ = std::panic::take_hook();
    assert!(hang.is_none(), "an input took longer than {budget:?}: {:?}", hang);
    for handle in handles {
        let _ = handle.join();
    }
    let panics = panics.lock().map(|p| p.clone()).unwrap_or_default();
    let signatures = signatures.lock().map(|s| s.len()).unwrap_or_default();
    println!(
        "fuzz: {inputs} inputs (seed {seed}) in {:.1} s on {workers} threads: {} loaded, {} errors ({} naming a field, {} invalid UTF-8, {} without a line) of {signatures} kinds, {} panics, 0 hangs; {:.0} µs per input per thread, slowest {:.1} ms (budget {} ms)",
        elapsed.as_secs_f64(),
        counts.loaded.load(Ordering::Relaxed),
        inputs as usize - counts.loaded.load(Ordering::Relaxed) - panics.len(),
        counts.with_field.load(Ordering::Relaxed),
        counts.not_utf8.load(Ordering::Relaxed),
        counts.without_location.load(Ordering::Relaxed),
        panics.len(),
        elapsed.as_secs_f64() * 1e6 * workers as f64 / inputs.max(1) as f64,
        slowest.lock().map(|s| s.as_secs_f64() * 1e3).unwrap_or_default(),
        budget.as_millis(),
    );
    assert!(panics.is_empty(), "inputs that panicked: {panics:?}");
}
