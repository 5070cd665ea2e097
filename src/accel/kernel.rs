//! Which instructions the ray queries are compiled for, chosen at run time.
//!
//! A release build targets baseline x86-64, which every x86-64 CPU runs:
//! SSE2, four `f32` or two `f64` per vector. CPUs since about 2013 (Intel
//! Haswell, AMD Excavator and Zen) also have AVX2 and the bit-manipulation
//! instructions of that generation (x86-64-v3): eight `f32` or four `f64`
//! per vector, three-operand forms, `tzcnt`. As Embree and Cycles do, the
//! hot loops are compiled twice and the copy this CPU runs is chosen when
//! it starts: [`Kernel::chosen`] for the BVH's queries, and [`Avx2::run`]
//! for a caller (the path tracer's loop) that wants its traversals compiled
//! into itself.
//!
//! The two copies compile the same floating-point operations in the same
//! order (Rust never fuses a product and a sum into one rounding), so they
//! give the same answers bit for bit: an image does not depend on the CPU
//! it was rendered on. `PRISM_KERNEL=portable` in the environment forces
//! the baseline copy, to compare them.

/// The instruction set a BVH's traversals run with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Kernel {
    /// Baseline x86-64, or any other architecture.
    #[default]
    Portable,
    /// x86-64 with AVX2, BMI1, BMI2, LZCNT and POPCNT.
    Avx2,
}

impl Kernel {
    /// The fastest kernel this CPU runs, unless `PRISM_KERNEL=portable`.
    pub fn chosen() -> Kernel {
        if Avx2::detect().is_some() {
            Kernel::Avx2
        } else {
            Kernel::Portable
        }
    }

    /// Whether this CPU runs the kernel (and the environment allows it).
    pub fn available(self) -> bool {
        match self {
            Kernel::Portable => true,
            Kernel::Avx2 => Avx2::detect().is_some(),
        }
    }
}

/// Proof that this CPU has AVX2 and its generation's bit-manipulation
/// instructions: only [`Avx2::detect`] makes one, after asking the CPU.
/// Code compiled for those instructions is reached only through a value of
/// this type, so it never runs where they are missing.
#[derive(Clone, Copy, Debug)]
pub struct Avx2(());

impl Avx2 {
    /// The proof, if this CPU has the instructions and `PRISM_KERNEL` is
    /// not `portable`. Cheap after the first call: the standard library
    /// caches the CPU's answers, and the environment is read once.
    #[inline]
    pub fn detect() -> Option<Avx2> {
        #[cfg(target_arch = "x86_64")]
        {
            static ALLOWED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
            let allowed = *ALLOWED.get_or_init(|| std::env::var("PRISM_KERNEL").map_or(true, |kernel| kernel != "portable"));
            let present = std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("bmi1")
                && std::arch::is_x86_feature_detected!("bmi2")
                && std::arch::is_x86_feature_detected!("lzcnt")
                && std::arch::is_x86_feature_detected!("popcnt");
            (allowed && present).then_some(Avx2(()))
        }
        #[cfg(not(target_arch = "x86_64"))]
        None
    }

    /// Runs `body` compiled for AVX2: `body` is compiled into a function
    /// with those instructions enabled (with everything it inlines, such as
    /// the traversal and the leaf tests), and the proof that the CPU has
    /// them makes the call sound.
    #[inline(always)]
    pub fn run<R>(self, body: impl FnOnce() -> R) -> R {
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
            fn compiled_for_avx2<R>(body: impl FnOnce() -> R) -> R {
                body()
            }
            // SAFETY: `self` exists only if the CPU reported every feature
            // enabled above (`Avx2::detect`).
            #[allow(unsafe_code)]
            unsafe {
                compiled_for_avx2(body)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        body()
    }
}
