//! The edge-avoiding à-trous wavelet filter (Dammertz et al. 2010) with
//! SVGF's variance-guided luminance weight (Schied et al. 2017, §4.3), on
//! planes of `f32` padded left and right so that each tap of a row is one
//! contiguous slice: the inner loops have no branches and vectorise.
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

/// Columns of replicated edge on each side of a padded row: the widest tap
/// offset of [`MAX_ITERATIONS`] iterations (2⁴ = 16).
const PAD: usize = 16;

/// Iterations the padding allows.
pub const MAX_ITERATIONS: u32 = 5;

/// The 1D kernel: B-spline weights ¼ ½ ¼ at offsets −1, 0, 1.
const KERNEL: [(isize, f32); 3] = [(-1, 0.25), (0, 0.5), (1, 0.25)];

/// Padded single-channel image: rows of `width + 2·PAD` values.
#[derive(Clone, Debug)]
pub struct Plane {
    width: usize,
    height: usize,
    values: Vec<f32>,
}

impl Plane {
    /// A plane of `f(index)` for each pixel index (row-major, unpadded).
    pub fn from_fn(width: usize, height: usize, f: impl Fn(usize) -> f32) -> Self {
        let stride = width + 2 * PAD;
        let mut values = vec![0.0; stride * height];
        for (y, row) in values.chunks_exact_mut(stride).enumerate() {
            for x in 0..width {
                row[PAD + x] = f(y * width + x);
            }
        }
        let mut plane = Self { width, height, values };
        plane.replicate_edges();
        plane
    }

    fn stride(&self) -> usize {
        self.width + 2 * PAD
    }

    /// The value of pixel `index` (row-major, unpadded).
    #[cfg(test)]
    fn get(&self, index: usize) -> f32 {
        let (x, y) = (index % self.width, index / self.width);
        self.values[y * self.stride() + PAD + x]
    }

    /// A plane of zeros.
    pub fn zeros(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            values: vec![0.0; (width + 2 * PAD) * height],
        }
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
    #[inline]
    fn row(&self, y: usize, dx: isize) -> &[f32] {
        let start = y * self.stride() + (PAD as isize + dx) as usize;
        &self.values[start..start + self.width]
    }

    /// Copies each row's first and last value into its padding.
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

/// What the filter reads and rewrites: colour (already divided by albedo)
/// and its variance.
pub struct Signal {
    pub color: [Plane; 3],
    pub variance: Plane,
}

impl Signal {
    fn zeros(width: usize, height: usize) -> Self {
        let plane = || Plane::zeros(width, height);
        Self {
            color: [plane(), plane(), plane()],
            variance: plane(),
        }
    }
}

/// `settings.iterations` (at most [`MAX_ITERATIONS`]) filter iterations;
/// returns the filtered colour planes.
pub fn filter(mut signal: Signal, guides: &GuidePlanes, settings: &DenoiseSettings) -> [Plane; 3] {
    let (width, height) = (signal.variance.width, signal.variance.height);
    let mut next = Signal::zeros(width, height);
    let mut luminance = Plane::zeros(width, height);
    let mut inverse_tolerance = luminance.clone();
    for iteration in 0..settings.iterations.min(MAX_ITERATIONS) {
        fill_luminance(&mut luminance, &signal.color);
        fill_inverse_tolerance(&mut inverse_tolerance, &signal.variance, settings.sigma_luminance);
        let inputs = Inputs {
            signal: &signal,
            luminance: &luminance,
            inverse_tolerance: &inverse_tolerance,
            guides,
        };
        iterate(&inputs, &mut next, 1 << iteration);
        std::mem::swap(&mut signal, &mut next);
    }
    signal.color
}

/// Luminance of the three colour planes (Rec. 709 weights, as `color::luminance`).
fn fill_luminance(out: &mut Plane, color: &[Plane; 3]) {
    let [r, g, b] = color.each_ref().map(|p| p.values.as_slice());
    for (((l, r), g), b) in out.values.iter_mut().zip(r).zip(g).zip(b) {
        *l = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    }
}

/// Per pixel, 1 / (σ_l · standard deviation): the variance smoothed by a
/// 3 × 3 binomial first, as in SVGF, since a single pixel's estimate is itself noisy.
fn fill_inverse_tolerance(out: &mut Plane, variance: &Plane, sigma_luminance: f32) {
    let (width, height) = (variance.width, variance.height);
    let stride = out.stride();
    out.values.par_chunks_exact_mut(stride).enumerate().for_each(|(y, row)| {
        let row = &mut row[PAD..PAD + width];
        row.fill(0.0);
        for (dy, ky) in KERNEL {
            let yj = (y as isize + dy).clamp(0, height as isize - 1) as usize;
            for (dx, kx) in KERNEL {
                for (o, v) in row.iter_mut().zip(variance.row(yj, dx)) {
                    *o += kx * ky * v;
                }
            }
        }
        for o in row.iter_mut() {
            *o = 1.0 / (sigma_luminance * o.max(0.0).sqrt() + 1e-6);
        }
    });
    out.replicate_edges();
}

/// What one iteration reads.
struct Inputs<'a> {
    signal: &'a Signal,
    luminance: &'a Plane,
    inverse_tolerance: &'a Plane,
    guides: &'a GuidePlanes,
}

/// One iteration with taps `step` pixels apart, from `inputs` into `out`.
fn iterate<'a>(inputs: &Inputs<'a>, out: &mut Signal, step: isize) {
    let Inputs {
        signal,
        luminance,
        inverse_tolerance,
        guides,
    } = *inputs;
    let (width, height) = (luminance.width, luminance.height);
    let stride = luminance.stride();
    let [out_r, out_g, out_b] = &mut out.color;
    let rows = out_r
        .values
        .par_chunks_exact_mut(stride)
        .zip(out_g.values.par_chunks_exact_mut(stride))
        .zip(out_b.values.par_chunks_exact_mut(stride))
        .zip(out.variance.values.par_chunks_exact_mut(stride))
        .enumerate();
    rows.for_each_init(
        || vec![0.0f32; 5 * width],
        |sums, (y, (((row_r, row_g), row_b), row_variance))| {
            sums.fill(0.0);
            let (sum_w, rest) = sums.split_at_mut(width);
            let (sum_r, rest) = rest.split_at_mut(width);
            let (sum_g, rest) = rest.split_at_mut(width);
            let (sum_b, sum_v) = rest.split_at_mut(width);
            let (sum_w, sum_r, sum_g) = (&mut sum_w[..width], &mut sum_r[..width], &mut sum_g[..width]);
            let (sum_b, sum_v) = (&mut sum_b[..width], &mut sum_v[..width]);
            // The centre pixel's own values, for every tap. Every row is cut
            // to exactly `width` so the compiler can drop the bounds checks
            // and vectorise the loop over x.
            let l0 = &luminance.row(y, 0)[..width];
            let t0 = &inverse_tolerance.row(y, 0)[..width];
            let [n0x, n0y, n0z] = guides.normal.each_ref().map(|p| &p.row(y, 0)[..width]);
            for (dy, ky) in KERNEL {
                let yj = (y as isize + dy * step).clamp(0, height as isize - 1) as usize;
                for (dx, kx) in KERNEL {
                    let offset = dx * step;
                    let tap = |plane: &'a Plane| &plane.row(yj, offset)[..width];
                    let lj = tap(luminance);
                    let [njx, njy, njz] = guides.normal.each_ref().map(tap);
                    let [cjr, cjg, cjb] = signal.color.each_ref().map(tap);
                    let vj = tap(&signal.variance);
                    let h = kx * ky;
                    for x in 0..width {
                        let cosine = n0x[x] * njx[x] + n0y[x] * njy[x] + n0z[x] * njz[x];
                        let exponent = (l0[x] - lj[x]).abs() * t0[x] + NORMAL_POWER * (1.0 - cosine);
                        let w = h * exp_negative(exponent);
                        sum_w[x] += w;
                        sum_r[x] += w * cjr[x];
                        sum_g[x] += w * cjg[x];
                        sum_b[x] += w * cjb[x];
                        sum_v[x] += w * w * vj[x];
                    }
                }
            }
            // The centre tap has weight ¼ (a pixel agrees with itself) unless
            // its normal is zero (an escaped ray): then every weight is 0 and
            // the pixel keeps its own value.
            let [c0r, c0g, c0b] = signal.color.each_ref().map(|p| &p.row(y, 0)[..width]);
            let v0 = &signal.variance.row(y, 0)[..width];
            let outputs = [row_r, row_g, row_b, row_variance].map(|row| &mut row[PAD..PAD + width]);
            let [out_r, out_g, out_b, out_v] = outputs;
            for x in 0..width {
                let w = sum_w[x];
                if w > 1e-12 {
                    let inverse = 1.0 / w;
                    out_r[x] = sum_r[x] * inverse;
                    out_g[x] = sum_g[x] * inverse;
                    out_b[x] = sum_b[x] * inverse;
                    out_v[x] = sum_v[x] * inverse * inverse;
                } else {
                    (out_r[x], out_g[x], out_b[x], out_v[x]) = (c0r[x], c0g[x], c0b[x], v0[x]);
                }
            }
        },
    );
    for plane in out.color.iter_mut().chain(std::iter::once(&mut out.variance)) {
        plane.replicate_edges();
    }
}

/// The normal weight is SVGF's max(0, n·n')^128, taken as e^(−128 (1 − n·n')),
/// which agrees to first order near n·n' = 1 (0.99^128 = 0.276, e^−1.28 = 0.278)
/// and vanishes for unrelated normals, and is folded into the one exponential.
const NORMAL_POWER: f32 = 128.0;

/// e^(−x) for x ≥ 0 as (1 − x/256)^256 (0 beyond x = 256): within 5 % of
/// e^(−x) where it exceeds e^(−5) and monotone, which is all an edge-stopping
/// weight needs, at eight multiplications and no branch, so the loop vectorises.
#[inline(always)]
fn exp_negative(x: f32) -> f32 {
    let y = 1.0 - x * (1.0 / 256.0);
    // A plain comparison (not `f32::max`, which must treat NaN specially) is one instruction.
    let mut y = if y > 0.0 { y } else { 0.0 };
    for _ in 0..8 {
        y *= y;
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_exponential_is_close_where_it_matters() {
        for i in 0..=500 {
            let x = i as f32 * 0.01;
            let exact = (-x).exp();
            // 5 %: (1 − x/n)^n = e^(−x − x²/2n − …), x²/512 ≤ 0.049 for x ≤ 5.
            assert!((exp_negative(x) - exact).abs() <= 0.05 * exact, "x = {x}");
        }
        assert_eq!(exp_negative(0.0), 1.0);
        assert_eq!(exp_negative(1000.0), 0.0);
    }

    #[test]
    fn padded_rows_replicate_their_edges() {
        let plane = Plane::from_fn(3, 2, |i| i as f32);
        assert_eq!(plane.row(1, 0), &[3.0, 4.0, 5.0]);
        assert_eq!(plane.row(1, -2), &[3.0, 3.0, 3.0]);
        assert_eq!(plane.row(0, 1), &[1.0, 2.0, 2.0]);
        assert_eq!(plane.get(4), 4.0);
    }
}
