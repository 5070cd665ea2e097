//! The edge-avoiding à-trous wavelet filter (Dammertz et al. 2010) with
//! SVGF's variance-guided luminance weight (Schied et al. 2017, §4.3), on
//! planes of `f32` padded left and right so that each tap of a row is one
//! contiguous slice, read four pixels at a time (`wide::f32x4`, SSE on the
//! baseline x86-64 target) with every sum kept in registers across the taps.
//!
//! Iteration `i` convolves with the 3 × 3 kernel `[¼ ½ ¼] ⊗ [¼ ½ ¼]` whose
//! taps are `2^i` pixels apart, each tap weighted by how much the two pixels
//! agree in luminance (in units of the centre's estimated standard
//! deviation) and normal (SVGF's `max(0, n·n')^128`). The colour has been
//! divided by the albedo, so texture and material edges are not in it and
//! need no weight of their own (as in SVGF, which has none either).
//! The variance is carried through each iteration as that of the weighted
//! mean, `Σ w² Var / (Σ w)²`, so later, wider iterations trust smoothed
//! pixels more.

use super::DenoiseSettings;
use rayon::prelude::*;
use wide::{CmpGe, CmpGt, f32x4, i32x4};

/// Pixels filtered at once: one SSE register of `f32`.
const LANES: usize = 4;

/// `LANES` values of one plane.
type Lanes = f32x4;

/// Columns of replicated edge on each side of a padded row: the widest tap
/// offset of [`MAX_ITERATIONS`] iterations (2⁴ = 16).
const PAD: usize = 16;

/// Iterations the padding allows.
pub const MAX_ITERATIONS: u32 = 5;

/// Padded single-channel image: rows of `width` values rounded up to whole
/// [`LANES`], with `PAD` replicated edge values on each side.
#[derive(Clone, Debug)]
pub struct Plane {
    width: usize,
    height: usize,
    values: Vec<f32>,
}

impl Plane {
    /// A plane of `f(index)` for each pixel index (row-major, unpadded).
    pub fn from_fn(width: usize, height: usize, f: impl Fn(usize) -> f32) -> Self {
        let mut plane = Self::zeros(width, height);
        for y in 0..height {
            for (x, value) in plane.row_mut(y).iter_mut().enumerate() {
                *value = f(y * width + x);
            }
        }
        plane.replicate_edges();
        plane
    }

    /// A plane of zeros.
    pub fn zeros(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            values: vec![0.0; (width.next_multiple_of(LANES) + 2 * PAD) * height],
        }
    }

    /// The width rounded up to whole [`LANES`]: the columns the filter computes.
    fn lane_width(&self) -> usize {
        self.width.next_multiple_of(LANES)
    }

    fn stride(&self) -> usize {
        self.lane_width() + 2 * PAD
    }

    /// The value of pixel `index` (row-major, unpadded).
    #[cfg(test)]
    fn get(&self, index: usize) -> f32 {
        let (x, y) = (index % self.width, index / self.width);
        self.values[y * self.stride() + PAD + x]
    }

    /// Row `y` without its padding, to write; call [`Plane::replicate_edges`] after.
    pub fn row_mut(&mut self, y: usize) -> &mut [f32] {
        let (start, width) = (y * self.stride() + PAD, self.width);
        &mut self.values[start..start + width]
    }

    /// The values of every row, without padding, top to bottom.
    pub fn rows(&self) -> impl Iterator<Item = &[f32]> {
        self.values.chunks_exact(self.stride()).map(|row| &row[PAD..PAD + self.width])
    }

    /// The `width` values of row `y` shifted right by `dx` pixels (clamped at the edges).
    #[cfg(test)]
    fn row(&self, y: usize, dx: isize) -> &[f32] {
        &self.lanes(y, dx).as_flattened()[..self.width]
    }

    /// Row `y` shifted right by `dx` pixels (clamped at the edges), over
    /// [`Plane::lane_width`] columns, in groups of [`LANES`].
    #[inline]
    fn lanes(&self, y: usize, dx: isize) -> &[[f32; LANES]] {
        let start = y * self.stride() + (PAD as isize + dx) as usize;
        self.values[start..start + self.lane_width()].as_chunks().0
    }

    /// Row `y` from its first pixel over [`Plane::lane_width`] columns, to write.
    fn lanes_mut(row: &mut [f32], lane_width: usize) -> &mut [[f32; LANES]] {
        row[PAD..PAD + lane_width].as_chunks_mut().0
    }

    /// Copies each row's first and last value into its padding (and into
    /// the columns beyond `width` that round it up to whole lanes).
    pub fn replicate_edges(&mut self) {
        let (width, stride) = (self.width, self.stride());
        for row in self.values.chunks_exact_mut(stride) {
            let (first, last) = (row[PAD], row[PAD + width - 1]);
            row[..PAD].fill(first);
            row[PAD + width..].fill(last);
        }
    }
}

/// The fixed guide the filter reads, the first-hit normal, as padded planes:
/// made once per [`Guides`](super::Guides) and reused for every frame
/// filtered with them.
#[derive(Clone, Debug)]
pub struct GuidePlanes {
    pub normal: [Plane; 3],
}

/// What the filter reads and rewrites: colour (already divided by albedo),
/// its luminance, and the variance of that luminance.
pub struct Signal {
    pub color: [Plane; 3],
    pub luminance: Plane,
    pub variance: Plane,
}

impl Signal {
    fn zeros(width: usize, height: usize) -> Self {
        let plane = || Plane::zeros(width, height);
        Self {
            color: [plane(), plane(), plane()],
            luminance: plane(),
            variance: plane(),
        }
    }
}

/// `settings.iterations` (at most [`MAX_ITERATIONS`]) filter iterations;
/// returns the filtered colour planes.
pub fn filter(mut signal: Signal, guides: &GuidePlanes, settings: &DenoiseSettings) -> [Plane; 3] {
    let (width, height) = (signal.variance.width, signal.variance.height);
    let mut next = Signal::zeros(width, height);
    let mut luminance_slope = Plane::zeros(width, height);
    for iteration in 0..settings.iterations.min(MAX_ITERATIONS) {
        fill_luminance_slope(&mut luminance_slope, &signal.variance, settings.sigma_luminance);
        iterate(&signal, &luminance_slope, guides, &mut next, 1 << iteration);
        std::mem::swap(&mut signal, &mut next);
    }
    signal.color
}

/// Per pixel, the luminance weight's exponent per unit of luminance
/// difference, 1 / (σ_l · standard deviation), in the units of
/// [`weight_from_field`] (times [`EXP_SCALE`]). The variance is smoothed by a
/// 3 × 3 binomial first, as in SVGF, since a single pixel's estimate is itself noisy.
fn fill_luminance_slope(out: &mut Plane, variance: &Plane, sigma_luminance: f32) {
    let height = variance.height;
    let (stride, lane_width) = (out.stride(), out.lane_width());
    out.values.par_chunks_exact_mut(stride).enumerate().for_each(|(y, row)| {
        let row = Plane::lanes_mut(row, lane_width);
        let rows = [-1, 0, 1].map(|dy| (y as isize + dy).clamp(0, height as isize - 1) as usize);
        let taps = [-1, 0, 1].map(|dx| rows.map(|yj| variance.lanes(yj, dx)));
        let load = |lanes: &[[f32; LANES]], i: usize| Lanes::from(lanes[i]);
        for (i, out) in row.iter_mut().enumerate() {
            // [¼ ½ ¼] ⊗ [¼ ½ ¼], by rows then columns.
            let column =
                |[above, centre, below]: [&[[f32; LANES]]; 3]| (load(above, i) + load(below, i)) * 0.25 + load(centre, i) * 0.5;
            let [left, middle, right] = taps.map(column);
            let smoothed = (left + right) * 0.25 + middle * 0.5;
            let deviation = smoothed.max(Lanes::ZERO).sqrt();
            *out = (Lanes::splat(EXP_SCALE) / (deviation * sigma_luminance + 1e-6)).to_array();
        }
    });
    out.replicate_edges();
}

/// The normal weight is SVGF's max(0, n·n')^128, taken as e^(−128 (1 − n·n')),
/// which agrees to first order near n·n' = 1 (0.99^128 = 0.276, e^−1.28 = 0.278)
/// and vanishes for unrelated normals, and is folded into the one exponential.
const NORMAL_POWER: f32 = 128.0;

/// One unit of the exponent field of an `f32`: 2²³.
const EXPONENT_UNIT: f32 = (1 << 23) as f32;

/// 2²³ · log₂ e: e^(−x) has exponent field `EXP_BIAS − EXP_SCALE · x`.
const EXP_SCALE: f32 = EXPONENT_UNIT * std::f32::consts::LOG2_E;

/// The exponent bias 127 · 2²³, less the shift that centres the relative
/// error of [`weight_from_field`]'s piecewise-linear mantissa: (1 + f) / 2^f
/// ranges over [1, 1.0615] for f in [0, 1], so the result is scaled by
/// 2 / 2.0615 = 2^(−0.04369), which puts it within ±2.99 % of the exact value.
const EXP_BIAS: f32 = 127.0 * EXPONENT_UNIT - 0.043_69 * EXPONENT_UNIT;

/// The field below which a weight is 0: weights under 2⁻²⁴ (a tap whose
/// contribution is below the rounding of the sum, whose centre weight is ¼)
/// are dropped, which also keeps every product clear of subnormal numbers.
const WEIGHT_CUT: f32 = (127 - 24) as f32 * EXPONENT_UNIT;

/// 2^(field / 2²³ − 127) with the mantissa linear between powers of two
/// (Schraudolph 1999, "A fast, compact approximation of the exponential
/// function"), 0 below [`WEIGHT_CUT`]. With `field = EXP_BIAS − EXP_SCALE ·
/// x` this is e^(−x) within ±3 %, monotone, in four instructions and no branch.
#[inline(always)]
fn weight_from_field(field: Lanes) -> Lanes {
    let bits: i32x4 = field.fast_trunc_int();
    // The mask is false for NaN, whatever the conversion made of it; with
    // unit (or zero) normals the field is at most about 127 · 2²³ (a weight
    // of 1), far inside the range of i32.
    bytemuck::cast::<i32x4, Lanes>(bits) & field.cmp_ge(Lanes::splat(WEIGHT_CUT))
}

/// The eight taps around the centre: row and column offset in steps, and
/// the kernel weight `kx · ky`.
const NEIGHBOURS: [(isize, isize, f32); 8] = [
    (-1, -1, 1.0 / 16.0),
    (-1, 0, 1.0 / 8.0),
    (-1, 1, 1.0 / 16.0),
    (0, -1, 1.0 / 8.0),
    (0, 1, 1.0 / 8.0),
    (1, -1, 1.0 / 16.0),
    (1, 0, 1.0 / 8.0),
    (1, 1, 1.0 / 16.0),
];

/// The kernel weight of the centre tap, `½ · ½`.
const CENTRE_WEIGHT: f32 = 0.25;

/// The planes one iteration reads, cut to one length: every plane has the
/// same layout, so one index reads the same pixel of each, and a single
/// bounds check covers all of them.
struct View<'a> {
    luminance: &'a [f32],
    slope: &'a [f32],
    normal: [&'a [f32]; 3],
    color: [&'a [f32]; 3],
    variance: &'a [f32],
}

/// The [`LANES`] values of `plane` from index `at`.
#[inline(always)]
fn load(plane: &[f32], at: usize) -> Lanes {
    let values: [f32; LANES] = plane[at..at + LANES].try_into().expect("a slice of LANES values");
    Lanes::from(values)
}

/// One iteration with taps `step` pixels apart, from `signal` into `out`.
fn iterate(signal: &Signal, luminance_slope: &Plane, guides: &GuidePlanes, out: &mut Signal, step: isize) {
    let plane = &signal.luminance;
    let (height, stride, lane_width) = (plane.height, plane.stride(), plane.lane_width());
    let length = plane.values.len();
    let Signal {
        color: [out_r, out_g, out_b],
        luminance: out_l,
        variance: out_v,
    } = out;
    let rows = out_r
        .values
        .par_chunks_exact_mut(stride)
        .zip(out_g.values.par_chunks_exact_mut(stride))
        .zip(out_b.values.par_chunks_exact_mut(stride))
        .zip(out_l.values.par_chunks_exact_mut(stride))
        .zip(out_v.values.par_chunks_exact_mut(stride))
        .enumerate();
    rows.for_each(|(y, ((((row_r, row_g), row_b), row_l), row_v))| {
        // Cut here, in the closure, so that the compiler sees one length.
        fn cut(plane: &Plane, length: usize) -> &[f32] {
            &plane.values[..length]
        }
        let cut = |plane| cut(plane, length);
        let view = View {
            luminance: cut(&signal.luminance),
            slope: cut(luminance_slope),
            normal: guides.normal.each_ref().map(cut),
            color: signal.color.each_ref().map(cut),
            variance: cut(&signal.variance),
        };
        // Each tap's index of this row's first pixel, and the constant part
        // of its weight's field: `EXP_BIAS + 2²³ log₂ h − EXP_SCALE ·
        // NORMAL_POWER` folds the kernel weight `h` and the constant of
        // `128 (1 − n·n')` into the exponent.
        let taps = NEIGHBOURS.map(|(dy, dx, h)| {
            let yj = (y as isize + dy * step).clamp(0, height as isize - 1) as usize;
            let start = yj * stride + (PAD as isize + dx * step) as usize;
            let field = EXP_BIAS + EXPONENT_UNIT * h.log2() - EXP_SCALE * NORMAL_POWER;
            (start, Lanes::splat(field))
        });
        let centre_field = EXP_BIAS + EXPONENT_UNIT * CENTRE_WEIGHT.log2() - EXP_SCALE * NORMAL_POWER;
        let centre_start = y * stride + PAD;
        let outputs = [row_r, row_g, row_b, row_l, row_v].map(|row| Plane::lanes_mut(row, lane_width));
        let [out_r, out_g, out_b, out_l, out_v] = outputs;
        for i in 0..lane_width / LANES {
            let at = centre_start + i * LANES;
            let (l0, slope) = (load(view.luminance, at), load(view.slope, at));
            // The normal scaled so that its dot product with a tap's normal
            // is the field of e^(128 n·n').
            let n0 = view.normal.map(|n| load(n, at) * (EXP_SCALE * NORMAL_POWER));
            let dot = |at: usize| {
                let [x, y, z] = view.normal;
                n0[0] * load(x, at) + n0[1] * load(y, at) + n0[2] * load(z, at)
            };
            // The centre tap: a pixel agrees with itself, so its weight is
            // ¼, or 0 if its normal is zero (an escaped ray).
            let [c0r, c0g, c0b] = view.color.map(|c| load(c, at));
            let v0 = load(view.variance, at);
            let w = weight_from_field(dot(at) + centre_field);
            let (mut sum_w, mut sum_r, mut sum_g, mut sum_b) = (w, w * c0r, w * c0g, w * c0b);
            let mut sum_v = w * w * v0;
            for &(start, field) in &taps {
                let at = start + i * LANES;
                let field = dot(at) + field - (l0 - load(view.luminance, at)).abs() * slope;
                let w = weight_from_field(field);
                sum_w += w;
                sum_r += w * load(view.color[0], at);
                sum_g += w * load(view.color[1], at);
                sum_b += w * load(view.color[2], at);
                sum_v += w * w * load(view.variance, at);
            }
            // Where every weight is 0 (an escaped ray's pixel) the pixel
            // keeps its own value.
            let valid = sum_w.cmp_gt(Lanes::splat(1e-12));
            let inverse = Lanes::ONE / sum_w;
            let r = valid.blend(sum_r * inverse, c0r);
            let g = valid.blend(sum_g * inverse, c0g);
            let b = valid.blend(sum_b * inverse, c0b);
            out_r[i] = r.to_array();
            out_g[i] = g.to_array();
            out_b[i] = b.to_array();
            out_l[i] = luminance(r, g, b).to_array();
            out_v[i] = valid.blend(sum_v * inverse * inverse, v0).to_array();
        }
    });
    for plane in out.color.iter_mut().chain([&mut out.luminance, &mut out.variance]) {
        plane.replicate_edges();
    }
}

/// Rec. 709 luminance, as `color::luminance`.
#[inline(always)]
fn luminance(r: Lanes, g: Lanes, b: Lanes) -> Lanes {
    r * 0.2126 + g * 0.7152 + b * 0.0722
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weight of `e^(−x)` as the filter computes it (kernel weight 1).
    fn exp_negative(x: f32) -> f32 {
        weight_from_field(Lanes::splat(EXP_BIAS - EXP_SCALE * x)).to_array()[0]
    }

    #[test]
    fn the_fast_exponential_is_within_three_percent_and_monotone() {
        // Weights stop at 2⁻²⁴ of the shifted field, x = (24 − 0.04369) ln 2
        // = 16.605; sampled far finer than the mantissa's linear pieces (one
        // per ln 2 = 0.69 of x).
        let cut = (EXP_BIAS - WEIGHT_CUT) / EXP_SCALE;
        assert!((cut - 16.605).abs() < 0.001, "cut at x = {cut}");
        let mut previous = f32::INFINITY;
        for i in 0..=20_000 {
            let x = i as f32 * 0.001;
            let (fast, exact) = (exp_negative(x), (-x).exp());
            // ±2.99 % by construction (EXP_BIAS), plus the f32 rounding of
            // the field (its ulp, 128, is 1.5·10⁻⁵ of the exponent unit).
            if x < cut - 0.001 {
                assert!((fast - exact).abs() <= 0.0300 * exact, "x = {x}: {fast} vs {exact}");
            } else if x > cut + 0.001 {
                assert_eq!(fast, 0.0, "x = {x}");
            }
            assert!(fast <= previous, "not monotone at x = {x}");
            previous = fast;
        }
        // The bound is tight: the error reaches 2.9 % on both sides.
        let errors = (0..2000).map(|i| {
            let x = i as f32 * 0.001;
            exp_negative(x) / (-x).exp() - 1.0
        });
        let (low, high) = errors.fold((0f32, 0f32), |(l, h), e| (l.min(e), h.max(e)));
        assert!(low < -0.029 && high > 0.029, "error range {low} to {high}");
        // Exponents far past the cut (an escaped ray's zero normal gives
        // 128), infinite or NaN give exactly 0.
        for x in [128.0, 1e30, f32::INFINITY, f32::NAN] {
            assert_eq!(exp_negative(x), 0.0, "x = {x}");
        }
    }

    #[test]
    fn padded_rows_replicate_their_edges() {
        let plane = Plane::from_fn(3, 2, |i| i as f32);
        assert_eq!(plane.row(1, 0), &[3.0, 4.0, 5.0]);
        assert_eq!(plane.row(1, -2), &[3.0, 3.0, 3.0]);
        assert_eq!(plane.row(0, 1), &[1.0, 2.0, 2.0]);
        assert_eq!(plane.get(4), 4.0);
    }

    /// One iteration, written out per pixel in `f64` with the exact
    /// exponential, as the module doc states it.
    fn reference_iteration(
        width: usize,
        height: usize,
        signal: &Signal,
        normals: &[[f32; 3]],
        sigma_luminance: f64,
        step: isize,
    ) -> Vec<([f64; 3], f64)> {
        let kernel = [0.25, 0.5, 0.25];
        let at = |x: isize, y: isize| {
            let x = x.clamp(0, width as isize - 1) as usize;
            let y = y.clamp(0, height as isize - 1) as usize;
            y * width + x
        };
        let get = |plane: &Plane, i: usize| plane.get(i) as f64;
        let mut out = Vec::new();
        for y in 0..height as isize {
            for x in 0..width as isize {
                let i = at(x, y);
                let mut smoothed = 0.0;
                for dy in -1..=1isize {
                    for dx in -1..=1isize {
                        let h = kernel[(dx + 1) as usize] * kernel[(dy + 1) as usize];
                        smoothed += h * get(&signal.variance, at(x + dx, y + dy));
                    }
                }
                let slope = 1.0 / (sigma_luminance * smoothed.sqrt() + 1e-6);
                let (mut sum_w, mut sum_c, mut sum_v) = (0.0, [0.0; 3], 0.0);
                for dy in -1..=1isize {
                    for dx in -1..=1isize {
                        let j = at(x + dx * step, y + dy * step);
                        let h = kernel[(dx + 1) as usize] * kernel[(dy + 1) as usize];
                        let cosine: f64 = (0..3).map(|c| normals[i][c] as f64 * normals[j][c] as f64).sum();
                        let difference = (get(&signal.luminance, i) - get(&signal.luminance, j)).abs();
                        let w = h * (-(difference * slope) - NORMAL_POWER as f64 * (1.0 - cosine)).exp();
                        sum_w += w;
                        for (c, sum) in sum_c.iter_mut().enumerate() {
                            *sum += w * get(&signal.color[c], j);
                        }
                        sum_v += w * w * get(&signal.variance, j);
                    }
                }
                out.push(if sum_w > 1e-12 {
                    (sum_c.map(|s| s / sum_w), sum_v / (sum_w * sum_w))
                } else {
                    ([0, 1, 2].map(|c| get(&signal.color[c], i)), get(&signal.variance, i))
                });
            }
        }
        out
    }

    /// The vectorised iteration against [`reference_iteration`] on an image
    /// whose width is not a whole number of lanes, with taps up to beyond
    /// its size (clamped), normals that agree, nearly agree, disagree or are
    /// zero, and random colour and variance.
    #[test]
    fn an_iteration_matches_its_definition() {
        let (width, height) = (13, 9);
        let count = width * height;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || (crate::math::xorshift64(&mut state) >> 40) as f32 / (1u64 << 24) as f32;
        let tilted = [0.0, 0.1f32.sin(), 0.1f32.cos()];
        let choices = [[0.0, 0.0, 1.0], tilted, [1.0, 0.0, 0.0], [0.0; 3]];
        let normals: Vec<[f32; 3]> = (0..count).map(|_| choices[((uniform() * 4.0) as usize).min(3)]).collect();
        let colors: Vec<[f32; 3]> = (0..count).map(|_| [uniform(), uniform(), uniform()]).collect();
        let variances: Vec<f32> = (0..count).map(|_| 0.01 + 0.09 * uniform()).collect();
        let signal = Signal {
            color: [0, 1, 2].map(|c| Plane::from_fn(width, height, |i| colors[i][c])),
            luminance: Plane::from_fn(width, height, |i| {
                let [r, g, b] = colors[i];
                0.2126 * r + 0.7152 * g + 0.0722 * b
            }),
            variance: Plane::from_fn(width, height, |i| variances[i]),
        };
        let guides = GuidePlanes {
            normal: [0, 1, 2].map(|c| Plane::from_fn(width, height, |i| normals[i][c])),
        };
        let sigma_luminance = 4.0;
        for step in [1, 2, 4, 16] {
            let mut slope = Plane::zeros(width, height);
            fill_luminance_slope(&mut slope, &signal.variance, sigma_luminance);
            let mut out = Signal::zeros(width, height);
            iterate(&signal, &slope, &guides, &mut out, step);
            let expected = reference_iteration(width, height, &signal, &normals, sigma_luminance as f64, step);
            for (i, (color, variance)) in expected.iter().enumerate() {
                // Each weight is within ±3 % (δ) of the exact one, so the
                // weighted mean moves by at most δ/(1 − δ) < 3.1 % of the
                // largest distance of a tap's value from it, here below 1
                // (colours lie in [0, 1)); Σw²V/(Σw)² by at most
                // (1 + δ)²/(1 − δ)² − 1 < 13 %.
                for (c, (plane, expected)) in out.color.iter().zip(color).enumerate() {
                    let got = plane.get(i) as f64;
                    assert!(
                        (got - expected).abs() < 0.031,
                        "step {step}, pixel {i}, channel {c}: {got} vs {expected}"
                    );
                }
                let got = out.variance.get(i) as f64;
                assert!(
                    (got - variance).abs() <= 0.13 * variance,
                    "step {step}, pixel {i}: variance {got} vs {variance}"
                );
                let [r, g, b] = [0, 1, 2].map(|c| out.color[c].get(i));
                assert!((out.luminance.get(i) - (0.2126 * r + 0.7152 * g + 0.0722 * b)).abs() < 1e-6);
            }
        }
    }
}
