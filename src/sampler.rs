//! Sample generators. Every value is a pure function of (pixel, sample
//! index, dimension, seed), so images never depend on thread scheduling.
//!
//! `Sobol` is the shuffled, Owen-scrambled 2D Sobol' sequence of Burley
//! (2020, "Practical Hash-based Owen Scrambling"): each pair of dimensions
//! takes the first two Sobol' dimensions, with the sample index shuffled and
//! the points scrambled by hashes of the pixel and dimension. Power-of-two
//! prefixes of each pixel's sequence remain (0, m, 2)-nets, which is what
//! lowers error at equal samples. `Random` draws independent uniforms.
//!
//! One 2D draw is paired on purpose: the draw at [`JOINT_DIMENSION`] shares
//! the shuffle of the stream's first 2D draw and takes Sobol' dimensions 3
//! and 4 of it, so the two make one four-dimensional Sobol' point (see
//! `joint`): in a camera path, the film position and the first surface's
//! light sample, stratified together.
//!
//! Only a stream's first [`SOBOL_DIMENSIONS`] dimensions are Sobol' points; later
//! ones are independent hashes, about a sixth of the cost. What
//! stratification buys is concentrated in the integrand's low-dimensional
//! projections (its "effective dimension", Caflisch, Morokoff & Owen 1997):
//! the pixel, the lens and the first bounces. Deep bounces carry little
//! light and gain little from stratification, so they get the cheap draws
//! (Cycles, for one, also stops its low-discrepancy patterns after a few
//! bounces).

use glam::DVec2;

mod joint;
mod lanes;

use crate::accel::Avx2;

/// Which sample generator a render uses (`sampler = "sobol"` or
/// `"random"` in scene files).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplerKind {
    /// Burley's shuffled, Owen-scrambled Sobol' points (see the module doc):
    /// lower error at equal samples. The default.
    #[default]
    Sobol,
    /// Independent uniform values from a hash: the baseline the benchmarks
    /// compare against.
    Random,
}

impl std::fmt::Display for SamplerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SamplerKind::Sobol => "sobol",
            SamplerKind::Random => "random",
        })
    }
}

/// Dimensions of a stream taken from the Sobol' sequence; the rest are
/// independent. For a camera path these are the camera's two 2D draws
/// (film position, lens) and the first two bounces' light choice, light
/// point, BSDF direction and lobe (each bounce takes five dimensions, the
/// fifth its roulette's, which the first bounce never draws: see the path
/// tracer's `BounceDraws`).
pub const SOBOL_DIMENSIONS: u32 = 11;

/// The dimension of a stream's first 2D draw (a camera path's film position).
pub const FIRST_DIMENSION: u32 = 1;

/// The dimension whose 2D draw completes a four-dimensional Sobol' point
/// with the draw at [`FIRST_DIMENSION`]: in a camera path, the first
/// surface's light sample (after the lens and the light's choice). The
/// squared error at equal samples falls by 5–10% on scenes whose pixels
/// straddle penumbrae and shading changes (the bunny, earth), and by
/// nothing measurable elsewhere (docs/performance.md, "The film position
/// and the first light sample as one Sobol' point").
/// A 1D draw there is an ordinary one.
pub const JOINT_DIMENSION: u32 = 4;

/// A 1D draw reserved by [`Sampler::defer_1d`], to be computed only if used.
#[derive(Clone, Copy, Debug)]
pub struct Deferred1d(u32);

/// The factor that spreads dimension numbers before they are mixed with
/// the stream's seed into a dimension's seed.
const DIMENSION_FACTOR: u64 = 0xd1b5_4a32_d192_ed03;

/// Marks an empty slot of [`Sampler::ahead_slots`].
const NO_SLOT: u64 = 0xf;

/// The sample stream of one pixel sample (one camera path).
#[derive(Clone, Debug)]
pub struct Sampler {
    kind: SamplerKind,
    stream_seed: u64,
    sample_index: u32,
    /// `sample_index` with its bits reversed, computed once per stream.
    reversed_index: u32,
    dimension: u32,
    /// 2D draws computed ahead ([`Sampler::draw_ahead`]), and where each
    /// dimension's is: four bits per dimension below 16, the slot in
    /// `ahead` or [`NO_SLOT`].
    ahead: [u32; 8],
    ahead_slots: u64,
}

impl Sampler {
    /// The stream for sample `sample_index` of the pixel with linear index `pixel`.
    pub fn new(kind: SamplerKind, pixel: u64, sample_index: u32, seed: u64) -> Self {
        Self {
            kind,
            stream_seed: mix64(pixel ^ mix64(seed.wrapping_add(0x9e37_79b9_7f4a_7c15))),
            sample_index,
            reversed_index: sample_index.reverse_bits(),
            dimension: 0,
            ahead: [0; 8],
            ahead_slots: u64::MAX,
        }
    }

    /// Computes the 2D draws of four later `dimensions` (those up to
    /// [`SOBOL_DIMENSIONS`]; the rest stay drawn one by one) now, side by side in
    /// AVX2 lanes: about a third of the instructions of drawing them one by
    /// one. [`Sampler::next_2d`] then returns them at their dimensions, bit
    /// for bit the values it would have computed. Does nothing for the
    /// independent kind.
    #[inline]
    pub fn draw_ahead(&mut self, avx2: Avx2, dimensions: [u32; 4]) {
        if self.kind != SamplerKind::Sobol {
            return;
        }
        debug_assert!(
            dimensions.iter().all(|&d| d > self.dimension),
            "only later dimensions are read"
        );
        #[cfg(target_arch = "x86_64")]
        {
            let _ = avx2;
            // SAFETY: an `Avx2` exists only if the CPU has AVX2 (`Avx2::detect`).
            #[allow(unsafe_code)]
            let draws = unsafe { lanes::sobol_2d_four(self.stream_seed, self.reversed_index, dimensions) };
            self.ahead = draws;
            let mut slots = u64::MAX;
            // A dimension past the Sobol' ones would be an independent draw
            // one by one: never taken from the lanes.
            for (slot, dimension) in dimensions.into_iter().enumerate().filter(|&(_, d)| d <= SOBOL_DIMENSIONS) {
                slots &= !(NO_SLOT << (4 * dimension));
                slots |= (slot as u64) << (4 * dimension);
            }
            self.ahead_slots = slots;
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = (avx2, dimensions);
    }

    /// One uniform value in [0, 1).
    pub fn next_1d(&mut self) -> f64 {
        self.dimension += 1;
        self.draw_1d_at(self.dimension)
    }

    /// Reserves the next 1D draw without computing it: [`Sampler::draw_1d`]
    /// computes it later, if needed, with the value [`Sampler::next_1d`]
    /// would have given here.
    #[inline]
    pub fn defer_1d(&mut self) -> Deferred1d {
        self.dimension += 1;
        Deferred1d(self.dimension)
    }

    /// The value of a draw reserved by [`Sampler::defer_1d`].
    #[inline]
    pub fn draw_1d(&self, deferred: Deferred1d) -> f64 {
        self.draw_1d_at(deferred.0)
    }

    fn draw_1d_at(&self, dimension: u32) -> f64 {
        let dimension_seed = self.dimension_seed(dimension);
        match self.kind {
            SamplerKind::Sobol if dimension <= SOBOL_DIMENSIONS => {
                // The scrambled van der Corput point of the shuffled index:
                // nested_uniform_scramble(reverse(index)), written so that
                // reversals cancel (see `shuffled_index`).
                let (index, _) = self.shuffled_index(dimension_seed as u32);
                to_unit(laine_karras_permutation(index, (dimension_seed >> 32) as u32).reverse_bits())
            }
            _ => to_unit(self.independent_bits(dimension_seed) as u32),
        }
    }

    /// One independent uniform value in [0, 1), whatever the kind: for
    /// decisions that gain nothing from stratification (Russian roulette).
    pub fn next_1d_independent(&mut self) -> f64 {
        let dimension_seed = self.next_dimension_seed();
        to_unit(self.independent_bits(dimension_seed) as u32)
    }

    /// 64 random bits for this stream's sample and dimension.
    #[inline]
    fn independent_bits(&self, dimension_seed: u64) -> u64 {
        mix64(dimension_seed ^ self.sample_index as u64)
    }

    /// Two uniform values in [0, 1)², stratified together.
    // Always inlined, so each copy of the path loop (baseline, AVX2) has
    // its own, and the hashes overlap the work around them.
    #[inline(always)]
    pub fn next_2d(&mut self) -> DVec2 {
        self.dimension += 1;
        // Drawn ahead? (`checked_shr`: dimensions from 16 on never are.)
        let slot = self.ahead_slots.checked_shr(4 * self.dimension).unwrap_or(NO_SLOT) & NO_SLOT;
        if slot != NO_SLOT {
            let slot = slot as usize & 3;
            return DVec2::new(to_unit(self.ahead[2 * slot]), to_unit(self.ahead[2 * slot + 1]));
        }
        let dimension_seed = self.dimension_seed(self.dimension);
        match self.kind {
            SamplerKind::Sobol if self.dimension <= SOBOL_DIMENSIONS => {
                // The first two Sobol' dimensions (van der Corput, which is
                // reverse(index), and x + 1) of the index shuffled for this
                // dimension, or at the joint dimension the next two (Joe &
                // Kuo's 3 and 4) of the index shuffled for the first draw,
                // each bit-reversed ...
                let (x, y) = if self.dimension == JOINT_DIMENSION {
                    self.joint_dimensions_reversed()
                } else {
                    self.shuffled_index(dimension_seed as u32)
                };
                // ... then Owen-scrambled by this dimension's seed:
                // nested_uniform_scramble(v) = reverse(LK(reverse(v))).
                let scramble = mix64(dimension_seed);
                let x = laine_karras_permutation(x, scramble as u32);
                let y = laine_karras_permutation(y, (scramble >> 32) as u32);
                // Both reversed at once: reversing the 64 bits (y, x) gives
                // (reverse(x), reverse(y)), one bit reversal instead of two
                // (x86-64 has no instruction for it: a byte swap and three
                // rounds of masks and shifts).
                let reversed = (u64::from(y) << 32 | u64::from(x)).reverse_bits();
                DVec2::new(to_unit((reversed >> 32) as u32), to_unit(reversed as u32))
            }
            _ => {
                let bits = self.independent_bits(dimension_seed);
                DVec2::new(to_unit(bits as u32), to_unit((bits >> 32) as u32))
            }
        }
    }

    /// Sobol' dimensions 3 and 4 (Joe & Kuo's numbering) of the index
    /// shuffled for the first draw, bit-reversed: the joint dimension's draw
    /// before its scramble. Out of line: read at most once per stream, it
    /// need not be compiled into every 2D draw of every loop.
    #[inline(never)]
    fn joint_dimensions_reversed(&self) -> (u32, u32) {
        joint_dimensions_reversed(self.stream_seed, self.reversed_index)
    }

    /// Passes over one draw (1D or 2D) without computing it, for a value
    /// nothing would read: each draw is a pure function of its dimension,
    /// so every later draw is the one it would have been. Lets a caller that
    /// keeps a fixed sequence of dimensions (the lens of a pinhole camera,
    /// the lobe choice of a diffuse bounce) skip the Sobol' arithmetic.
    #[inline]
    pub fn skip(&mut self) {
        self.dimension += 1;
    }

    /// The per-dimension shuffle of the sample index,
    /// nested_uniform_scramble(index, seed) = reverse(LK(reverse(index))),
    /// with the bit-reversed second Sobol' dimension of the shuffled index.
    #[inline]
    fn shuffled_index(&self, seed: u32) -> (u32, u32) {
        index_and_second_dimension(laine_karras_permutation(self.reversed_index, seed))
    }

    /// A second stream of the same pixel sample, scrambled independently
    /// of this one by `salt` and starting at its first (Sobol') dimension:
    /// for draws that must not shift this stream's dimensions, such as a
    /// spectral path's wavelengths (so an RGB and a spectral render of one
    /// seed follow the same paths wherever their throughputs agree).
    pub fn side_stream(&self, salt: u64) -> Self {
        Self {
            stream_seed: mix64(self.stream_seed ^ salt),
            dimension: 0,
            ahead_slots: u64::MAX,
            ..self.clone()
        }
    }

    fn next_dimension_seed(&mut self) -> u64 {
        self.dimension += 1;
        self.dimension_seed(self.dimension)
    }

    #[inline]
    fn dimension_seed(&self, dimension: u32) -> u64 {
        dimension_seed(self.stream_seed, dimension)
    }
}

/// The seed of `dimension` in the stream with `stream_seed`.
#[inline]
fn dimension_seed(stream_seed: u64, dimension: u32) -> u64 {
    mix64(stream_seed ^ (dimension as u64).wrapping_mul(DIMENSION_FACTOR))
}

/// Sobol' dimensions 3 and 4 (Joe & Kuo's numbering), bit-reversed, of the
/// index shuffled for the first draw of the stream with `stream_seed`, at
/// the bit-reversed sample index `reversed_index`: the joint dimension's
/// draw before its scramble, for [`Sampler`] and its four-lane draws alike.
#[inline]
fn joint_dimensions_reversed(stream_seed: u64, reversed_index: u32) -> (u32, u32) {
    let first_seed = dimension_seed(stream_seed, FIRST_DIMENSION) as u32;
    let (first_draws_index, _) = index_and_second_dimension(laine_karras_permutation(reversed_index, first_seed));
    joint::third_and_fourth_reversed(first_draws_index)
}

/// 32 random bits to a float in [0, 1), never 1.
fn to_unit(bits: u32) -> f64 {
    bits as f64 * (1.0 / 4_294_967_296.0)
}

/// From an index's reversed bits, the index (its bits put back in order)
/// and its second Sobol' dimension (primitive polynomial x + 1),
/// bit-reversed: direction numbers v₁ = 2³¹, vⱼ₊₁ = vⱼ ⊕ (vⱼ >> 1), XORed
/// for each set bit of the index. Both maps are linear over XOR, so one table
/// per byte gives both, the index in the low half of each entry: four loads
/// instead of four loads and a bit reversal (x86-64 has no instruction for
/// it: a byte swap and three rounds of masks and shifts).
#[inline]
fn index_and_second_dimension(reversed: u32) -> (u32, u32) {
    let both = xor_of_byte_tables(&INDEX_AND_SECOND_DIMENSION, reversed);
    (both as u32, (both >> 32) as u32)
}

/// A map of 32 bits that is linear over XOR, read from one table per byte
/// (`tables[k]` maps byte k): the XOR of the four bytes' entries.
#[inline]
fn xor_of_byte_tables(tables: &[[u64; 256]; 4], bits: u32) -> u64 {
    tables[0][(bits & 0xff) as usize]
        ^ tables[1][((bits >> 8) & 0xff) as usize]
        ^ tables[2][((bits >> 16) & 0xff) as usize]
        ^ tables[3][(bits >> 24) as usize]
}

/// The Sobol' dimension with direction numbers `directions` (v₁…v₃₂) of
/// `index`: the XOR of vⱼ over the set bits j of the index.
const fn sobol(index: u32, directions: &[u32; 32]) -> u32 {
    let mut value = 0;
    let mut bit = 0;
    while bit < 32 {
        if index & (1 << bit) != 0 {
            value ^= directions[bit];
        }
        bit += 1;
    }
    value
}

const INDEX_AND_SECOND_DIMENSION: [[u64; 256]; 4] = {
    let mut directions = [0u32; 32];
    let mut v = 1u32 << 31;
    let mut j = 0;
    while j < 32 {
        directions[j] = v;
        v ^= v >> 1;
        j += 1;
    }
    let mut tables = [[0u64; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut value = 0;
        while value < 256 {
            let index = ((value as u32) << (8 * byte)).reverse_bits();
            let second = sobol(index, &directions).reverse_bits();
            tables[byte][value] = index as u64 | (second as u64) << 32;
            value += 1;
        }
        byte += 1;
    }
    tables
};

/// The second Sobol' dimension computed bit by bit (the definition the
/// tables are checked against).
#[cfg(test)]
fn sobol_second_dimension(mut index: u32) -> u32 {
    let mut result = 0;
    let mut direction = 1u32 << 31;
    while index != 0 {
        if index & 1 != 0 {
            result ^= direction;
        }
        index >>= 1;
        direction ^= direction >> 1;
    }
    result
}

/// Owen scrambling of a 32-bit fixed-point value: a hash-based
/// Laine–Karras permutation applied to the bit-reversed value (Burley 2020).
#[cfg(test)]
fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras_permutation(x.reverse_bits(), seed).reverse_bits()
}

/// The hash-based permutation of Laine & Karras (2011, "Stratified Sampling
/// for Stochastic Transparency"), with Burley's (2020) improved constants.
/// Each output bit depends only on the input bits below it and the seed.
fn laine_karras_permutation(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// A strong 64-bit mixer: the finaliser of SplitMix64 (Steele, Lea & Flood
/// 2014), Stafford's "Mix13" variant of MurmurHash3's `fmix64`.
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sobol_prefixes_are_stratified_in_2d() {
        // The first 16 points of a pixel put exactly one point in each cell
        // of every 16-cell elementary grid (1×16, 2×8, 4×4, 8×2, 16×1).
        for pixel in 0..20 {
            let points: Vec<DVec2> = (0..16)
                .map(|i| Sampler::new(SamplerKind::Sobol, pixel, i, 7).next_2d())
                .collect();
            for log_x in 0..=4 {
                let (nx, ny) = (1usize << log_x, 1usize << (4 - log_x));
                let mut cells = [0; 16];
                for p in &points {
                    let cx = (p.x * nx as f64) as usize;
                    let cy = (p.y * ny as f64) as usize;
                    cells[cy * nx + cx] += 1;
                }
                assert!(cells.iter().all(|&c| c == 1), "pixel {pixel}, grid {nx}x{ny}");
            }
        }
    }

    /// The fast paths compute exactly Burley's formulation.
    #[test]
    fn fast_sobol_equals_the_definition() {
        for index in [0u32, 1, 2, 3, 77, 1 << 20, u32::MAX, 0x1234_5678]
            .into_iter()
            .chain((0..10_000u64).map(|i| mix64(i) as u32))
        {
            assert_eq!(
                index_and_second_dimension(index.reverse_bits()),
                (index, sobol_second_dimension(index).reverse_bits())
            );
        }
        let (pixel, sample, seed) = (12u64, 37u32, 5u64);
        let mut fast = Sampler::new(SamplerKind::Sobol, pixel, sample, seed);
        let mut reference = Sampler::new(SamplerKind::Sobol, pixel, sample, seed);
        for _ in 0..5 {
            let dimension_seed = reference.next_dimension_seed();
            let scramble = mix64(dimension_seed);
            let (x, y) = if reference.dimension == JOINT_DIMENSION {
                // Sobol' dimensions 3 and 4 of the first draw's shuffled index.
                let first_seed = reference.dimension_seed(FIRST_DIMENSION);
                let index = nested_uniform_scramble(sample, first_seed as u32);
                let (third, fourth) = joint::third_and_fourth_reversed_by_definition(index);
                (third.reverse_bits(), fourth.reverse_bits())
            } else {
                let index = nested_uniform_scramble(sample, dimension_seed as u32);
                (index.reverse_bits(), sobol_second_dimension(index))
            };
            let x = nested_uniform_scramble(x, scramble as u32);
            let y = nested_uniform_scramble(y, (scramble >> 32) as u32);
            assert_eq!(fast.next_2d(), DVec2::new(to_unit(x), to_unit(y)));
        }
    }

    /// The film position and the joint draw are stratified together. Over
    /// a pixel's first 64 samples, the mean of an integrand of both at once
    /// errs far less than with a 2D draw of its own shuffle in place of the
    /// joint one, which pairs with the film position at random (each pixel
    /// a fresh scramble; 400 pixels): for a smooth one, x₁x₂ (integral 1/4),
    /// whose interaction (x₁ − ½)(x₂ − ½) random pairing integrates at the
    /// Monte Carlo rate, and for a step across both, 1[x₁ + x₂ < 1]
    /// (integral 1/2), as where a pixel straddles a penumbra.
    #[test]
    fn the_joint_draw_is_stratified_with_the_film_position() {
        let squared_error = |second: u32, integrand: &dyn Fn(DVec2, DVec2) -> f64, integral: f64| {
            let mut sum = 0.0;
            for pixel in 0..400 {
                let mut estimate = 0.0;
                for sample in 0..64 {
                    let mut sampler = Sampler::new(SamplerKind::Sobol, pixel, sample, 3);
                    let film = sampler.next_2d();
                    sampler.dimension = second - 1;
                    estimate += integrand(film, sampler.next_2d()) / 64.0;
                }
                sum += (estimate - integral).powi(2);
            }
            sum / 400.0
        };
        let product = |a: DVec2, b: DVec2| a.x * b.x;
        let step = |a: DVec2, b: DVec2| f64::from(u8::from(a.y + b.y < 1.0));
        for (name, integrand, integral, factor) in [
            ("product", &product as &dyn Fn(_, _) -> f64, 0.25, 20.0),
            ("step", &step, 0.5, 2.0),
        ] {
            let joint = squared_error(JOINT_DIMENSION, integrand, integral);
            let separate = squared_error(JOINT_DIMENSION + 1, integrand, integral);
            assert!(
                joint * factor < separate,
                "{name}: joint {joint:.3e}, separate {separate:.3e}"
            );
        }
    }

    /// A deferred draw, computed after later draws, is the value a plain
    /// draw at its place gives, and the draws after it are unchanged.
    #[test]
    fn deferred_draws_equal_plain_draws_in_their_place() {
        for kind in [SamplerKind::Sobol, SamplerKind::Random] {
            for index in 0..64 {
                let mut plain = Sampler::new(kind, 5, index, 2);
                let mut deferring = plain.clone();
                let expected: Vec<f64> = (0..14).map(|_| plain.next_1d()).collect();
                let deferred: Vec<Deferred1d> = (0..7).map(|_| deferring.defer_1d()).collect();
                for (dimension, &value) in expected.iter().enumerate().skip(7) {
                    assert_eq!(deferring.next_1d(), value, "{kind}: sample {index}, dimension {dimension}");
                }
                for (dimension, draw) in deferred.into_iter().enumerate().rev() {
                    assert_eq!(deferring.draw_1d(draw), expected[dimension], "{kind}: deferred {dimension}");
                }
            }
        }
    }

    /// Skipping a draw leaves every later draw as it was, for both kinds,
    /// whether the skipped draw was 1D or 2D and Sobol' or independent
    /// (the SPPM images stay bit for bit the same only if this holds).
    #[test]
    fn skipped_draws_leave_later_draws_unchanged() {
        for kind in [SamplerKind::Sobol, SamplerKind::Random] {
            for skipped in 0..14 {
                let mut drawn = Sampler::new(kind, 21, 6, 9);
                let mut skipping = drawn.clone();
                for dimension in 0..16 {
                    // Alternate 2D and 1D draws, as paths do.
                    let draw = |s: &mut Sampler| match dimension % 2 {
                        0 => s.next_2d(),
                        _ => DVec2::splat(s.next_1d()),
                    };
                    let expected = draw(&mut drawn);
                    if dimension == skipped {
                        skipping.skip();
                    } else {
                        assert_eq!(
                            draw(&mut skipping),
                            expected,
                            "{kind}: dimension {dimension}, {skipped} skipped"
                        );
                    }
                }
            }
        }
    }

    /// Draws computed ahead are returned at their dimensions as computed
    /// one by one; every other draw, 1D, deferred, skipped or in a side
    /// stream, is as it was.
    #[test]
    fn draws_ahead_change_no_draw() {
        let Some(avx2) = Avx2::detect() else { return };
        for kind in [SamplerKind::Sobol, SamplerKind::Random] {
            for index in 0..256 {
                let mut plain = Sampler::new(kind, 40 + u64::from(index), index, 3);
                let mut ahead = plain.clone();
                let dimensions = [[1, 2, 4, 5], [1, 4, 5, 9], [2, 3, 5, 8], [8, 9, 10, 11]][index as usize % 4];
                ahead.draw_ahead(avx2, dimensions);
                for dimension in 1..=16 {
                    match (dimension + index) % 4 {
                        0 => assert_eq!(ahead.next_2d(), plain.next_2d()),
                        1 => assert_eq!(ahead.next_1d(), plain.next_1d()),
                        2 => {
                            let (a, p) = (ahead.defer_1d(), plain.defer_1d());
                            assert_eq!(ahead.draw_1d(a), plain.draw_1d(p));
                        }
                        _ => {
                            assert_eq!(ahead.side_stream(7).next_2d(), plain.side_stream(7).next_2d());
                            ahead.skip();
                            plain.skip();
                        }
                    }
                }
                // Every dimension drawn in 2D, as the path tracer mostly does.
                let mut plain = Sampler::new(kind, 40 + u64::from(index), index, 3);
                let mut ahead = plain.clone();
                ahead.draw_ahead(avx2, dimensions);
                for dimension in 1..=16 {
                    assert_eq!(
                        ahead.next_2d(),
                        plain.next_2d(),
                        "{kind}: sample {index}, dimension {dimension}"
                    );
                }
            }
        }
    }

    #[test]
    fn streams_are_deterministic_and_distinct() {
        let a = Sampler::new(SamplerKind::Sobol, 3, 5, 1).next_2d();
        let b = Sampler::new(SamplerKind::Sobol, 3, 5, 1).next_2d();
        let c = Sampler::new(SamplerKind::Sobol, 4, 5, 1).next_2d();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn random_sampler_has_uniform_mean() {
        let n = 100_000;
        let mean: f64 = (0..n)
            .map(|i| Sampler::new(SamplerKind::Random, 9, i, 0).next_1d())
            .sum::<f64>()
            / n as f64;
        // Standard error of the mean of U(0,1) is 1/sqrt(12 n) ≈ 0.0009; allow 5σ.
        assert!((mean - 0.5).abs() < 0.0046);
    }
}
