//! χ² goodness-of-fit tests of sampling routines against their densities, as
//! in Nori's `chi2test` and pbrt-v4's BSDF sampling tests: draw many samples,
//! count them in a 2D histogram, integrate the claimed density over each bin
//! for the expected counts, pool bins expecting fewer than
//! [`MIN_EXPECTED`] samples, and compare with Pearson's statistic
//! X² = Σ (observed − expected)² / expected, whose distribution under the
//! hypothesis "the samples follow the density" tends to χ² with one degree of
//! freedom fewer than the number of cells.
//!
//! Every test adds one cell for the samples that land nowhere in the
//! histogram: outside its domain, or not drawn at all (a sampler may fail,
//! as GGX reflections below the horizon do). Its expected count is
//! N (1 − ∫ density over the domain), so a density that integrates to the
//! probability of a successful sample is tested exactly, and a sampler that
//! loses samples its density claims, or places them where the density is
//! zero, is rejected.
//!
//! Samples come from [`Sampler`]'s independent stream ([`SamplerKind::Random`]):
//! the χ² distribution assumes independent draws (stratified points would
//! make the statistic too small), and a fixed seed makes every run the same.

use super::quadrature::integrate_rectangle;
use super::{Frame, gamma::chi_square_p_value};
use crate::sampler::{Sampler, SamplerKind};
use glam::{DVec2, DVec3};
use std::f64::consts::TAU;

/// Cells expecting fewer samples than this are pooled: below it the χ²
/// approximation to the multinomial statistic breaks down (the usual rule,
/// and Nori's `minExpFrequency`).
pub const MIN_EXPECTED: f64 = 5.0;

/// Significance level for one test out of `tests` run together, so that the
/// whole family wrongly rejects a correct sampler with probability at most
/// `family_significance` (Šidák's correction, as Nori uses).
pub fn sidak_significance(family_significance: f64, tests: usize) -> f64 {
    1.0 - (1.0 - family_significance).powf(1.0 / tests.max(1) as f64)
}

/// How a χ² test draws and bins its samples.
#[derive(Clone, Copy, Debug)]
pub struct ChiSquareTest {
    /// Number of samples drawn.
    pub samples: u32,
    /// Seed of the independent sample stream.
    pub seed: u64,
    /// Bins along the first and second coordinate (cos θ and φ for directions).
    pub bins: (usize, usize),
}

/// The region of the sphere of directions a test bins: directions w with
/// cos θ = w · axis ≥ `cos_theta_min`, in bins equal in solid angle over
/// (cos θ, φ) about `axis` (dω = d cos θ dφ).
#[derive(Clone, Copy, Debug)]
pub struct SphericalCap {
    /// The cap's centre (the pole of the binning); unit length.
    pub axis: DVec3,
    /// −1 for the whole sphere, 0 for a hemisphere.
    pub cos_theta_min: f64,
}

impl SphericalCap {
    /// The whole sphere, binned about +z.
    pub const SPHERE: Self = Self {
        axis: DVec3::Z,
        cos_theta_min: -1.0,
    };
}

/// The verdict of one χ² test.
#[derive(Clone, Debug)]
pub struct ChiSquareOutcome {
    /// Pearson's X² over the cells after pooling (∞ if samples fell where none may).
    pub statistic: f64,
    /// Cells after pooling, minus one for the fixed total.
    pub degrees_of_freedom: usize,
    /// Probability of a statistic at least this large if the samples follow the density.
    pub p_value: f64,
    /// Number of histogram cells merged into the pool of small expectations.
    pub pooled_cells: usize,
    /// The cells contributing most to the statistic, for diagnosis.
    pub worst_cells: Vec<CellDeviation>,
}

/// One histogram cell's observed and expected counts.
#[derive(Clone, Debug)]
pub struct CellDeviation {
    /// Which cell: its coordinate ranges, or "elsewhere".
    pub cell: String,
    /// Samples counted in it.
    pub observed: u64,
    /// N × the density's integral over it.
    pub expected: f64,
}

impl ChiSquareOutcome {
    /// True if the test does not reject the density at `significance`.
    pub fn accepts(&self, significance: f64) -> bool {
        self.p_value >= significance
    }
}

impl std::fmt::Display for ChiSquareOutcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "X² = {:.2} with {} degrees of freedom ({} cells pooled), p = {:.3e}",
            self.statistic, self.degrees_of_freedom, self.pooled_cells, self.p_value
        )?;
        for cell in &self.worst_cells {
            write!(f, "; {} observed {} expected {:.1}", cell.cell, cell.observed, cell.expected)?;
        }
        Ok(())
    }
}

/// Pearson's χ² test of `observed` counts against `expected` counts (same
/// length, totals equal): cells expecting fewer than [`MIN_EXPECTED`] are
/// pooled, smallest first, until the pool expects at least that many; a
/// sample in a cell expecting exactly 0 rejects outright (p = 0).
/// `labels` names a cell by index, for the diagnosis of the worst cells.
pub fn pearson_test(observed: &[u64], expected: &[f64], labels: impl Fn(usize) -> String) -> ChiSquareOutcome {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut pooled_observed, mut pooled_expected, mut pooled_cells) = (0u64, 0.0, 0usize);
    let mut statistic = 0.0;
    let mut cells = 0usize;
    let mut contributions = Vec::new();
    let mut impossible = false;
    for &i in &order {
        if expected[i] == 0.0 {
            // No sample may land here; one that does refutes the density.
            impossible |= observed[i] > 0;
        } else if expected[i] < MIN_EXPECTED || (pooled_expected > 0.0 && pooled_expected < MIN_EXPECTED) {
            pooled_observed += observed[i];
            pooled_expected += expected[i];
            pooled_cells += 1;
        } else {
            let contribution = (observed[i] as f64 - expected[i]).powi(2) / expected[i];
            statistic += contribution;
            cells += 1;
            contributions.push((contribution, i));
        }
    }
    let mut worst_cells = Vec::new();
    if pooled_expected > 0.0 {
        statistic += (pooled_observed as f64 - pooled_expected).powi(2) / pooled_expected;
        cells += 1;
        worst_cells.push(CellDeviation {
            cell: format!("pool of {pooled_cells} cells"),
            observed: pooled_observed,
            expected: pooled_expected,
        });
    }
    if impossible {
        statistic = f64::INFINITY;
        worst_cells.extend(
            (0..expected.len())
                .filter(|&i| expected[i] == 0.0 && observed[i] > 0)
                .take(3)
                .map(|i| CellDeviation {
                    cell: labels(i),
                    observed: observed[i],
                    expected: 0.0,
                }),
        );
    }
    contributions.sort_by(|a, b| b.0.total_cmp(&a.0));
    worst_cells.extend(contributions.iter().take(3).map(|&(_, i)| CellDeviation {
        cell: labels(i),
        observed: observed[i],
        expected: expected[i],
    }));
    let degrees_of_freedom = cells.saturating_sub(1);
    let p_value = if statistic.is_infinite() {
        0.0
    } else if degrees_of_freedom == 0 {
        // One cell holds every sample: nothing to test, nothing contradicted.
        1.0
    } else {
        chi_square_p_value(statistic, degrees_of_freedom)
    };
    ChiSquareOutcome {
        statistic,
        degrees_of_freedom,
        p_value,
        pooled_cells,
        worst_cells,
    }
}

impl ChiSquareTest {
    /// Tests points drawn by `sample` (from a fresh sample stream each, or
    /// `None` when no point is drawn) against `density` (per unit area),
    /// binned over the rectangle `x_range` × `y_range`.
    pub fn planar(
        &self,
        x_range: (f64, f64),
        y_range: (f64, f64),
        sample: impl FnMut(&mut Sampler) -> Option<DVec2>,
        mut density: impl FnMut(DVec2) -> f64,
    ) -> ChiSquareOutcome {
        self.run(x_range, y_range, sample, |x, y| density(DVec2::new(x, y)))
    }

    /// Tests directions drawn by `sample` (unit vectors, or `None` when no
    /// direction is drawn) against `pdf` (per steradian), binned over `cap`
    /// in (cos θ, φ) about its axis: bins of equal solid angle.
    pub fn directions(
        &self,
        cap: SphericalCap,
        mut sample: impl FnMut(&mut Sampler) -> Option<DVec3>,
        mut pdf: impl FnMut(DVec3) -> f64,
    ) -> ChiSquareOutcome {
        let frame = Frame::from_normal(cap.axis);
        let to_coordinates = |w: DVec3| {
            let local = frame.to_local(w);
            let phi = local.y.atan2(local.x);
            DVec2::new(local.z, if phi < 0.0 { phi + TAU } else { phi })
        };
        let from_coordinates = |cos_theta: f64, phi: f64| {
            let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
            frame.to_world(DVec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta))
        };
        self.run(
            (cap.cos_theta_min, 1.0),
            (0.0, TAU),
            |sampler| sample(sampler).map(to_coordinates),
            |cos_theta, phi| pdf(from_coordinates(cos_theta, phi)),
        )
    }

    fn run(
        &self,
        (x0, x1): (f64, f64),
        (y0, y1): (f64, f64),
        mut sample: impl FnMut(&mut Sampler) -> Option<DVec2>,
        mut density: impl FnMut(f64, f64) -> f64,
    ) -> ChiSquareOutcome {
        let (nx, ny) = self.bins;
        let elsewhere = nx * ny;
        let cell_of = |p: DVec2| {
            let x = (p.x - x0) / (x1 - x0);
            let y = (p.y - y0) / (y1 - y0);
            // The rectangle is closed: a point on its far edges is in the last bin.
            if !((0.0..=1.0).contains(&x) && (0.0..=1.0).contains(&y)) {
                return elsewhere;
            }
            let ix = ((x * nx as f64) as usize).min(nx - 1);
            let iy = ((y * ny as f64) as usize).min(ny - 1);
            iy * nx + ix
        };

        // Count the samples.
        let mut observed = vec![0u64; nx * ny + 1];
        for index in 0..self.samples {
            let mut sampler = Sampler::new(SamplerKind::Random, 0, index, self.seed);
            observed[sample(&mut sampler).map_or(elsewhere, cell_of)] += 1;
        }

        // Integrate the density over each bin. Each bin's probability is
        // wanted to 1% of one sample, far below the √expected noise the test
        // resolves; 20 halvings bound the work at a jump in the density.
        let n = self.samples as f64;
        let (width, height) = ((x1 - x0) / nx as f64, (y1 - y0) / ny as f64);
        let tolerance = 0.01 / n;
        let mut expected = vec![0.0; nx * ny + 1];
        for iy in 0..ny {
            for ix in 0..nx {
                let xs = (x0 + ix as f64 * width, x0 + (ix + 1) as f64 * width);
                let ys = (y0 + iy as f64 * height, y0 + (iy + 1) as f64 * height);
                let probability = integrate_rectangle(&mut |x, y| density(x, y), xs, ys, tolerance, 20);
                expected[iy * nx + ix] = n * probability;
            }
        }
        let inside: f64 = expected[..elsewhere].iter().sum();
        expected[elsewhere] = (n - inside).max(0.0);

        let label = |i: usize| {
            if i == elsewhere {
                return "elsewhere (outside the bins, or not drawn)".to_string();
            }
            let (ix, iy) = (i % nx, i / nx);
            format!(
                "[{:.3}, {:.3}] × [{:.3}, {:.3}]",
                x0 + ix as f64 * width,
                x0 + (ix + 1) as f64 * width,
                y0 + iy as f64 * height,
                y0 + (iy + 1) as f64 * height
            )
        };
        pearson_test(&observed, &expected, label)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One test of a correct density, 5% significance: a correct sampler
    /// passes with probability 0.95, and the fixed seed makes that one draw.
    const SIGNIFICANCE: f64 = 0.05;

    /// Known statistics: counts equal to their expectations give X² = 0 and
    /// p = 1; a hand-computed table gives its X² and the χ²₂ tail e^(−X²/2).
    #[test]
    fn pearson_statistic_matches_hand_computation() {
        let exact = pearson_test(&[10, 20, 30], &[10.0, 20.0, 30.0], |i| i.to_string());
        assert_eq!((exact.statistic, exact.degrees_of_freedom, exact.p_value), (0.0, 2, 1.0));
        // (12 − 10)²/10 + (18 − 20)²/20 + (30 − 30)²/30 = 0.6.
        let off = pearson_test(&[12, 18, 30], &[10.0, 20.0, 30.0], |i| i.to_string());
        assert!((off.statistic - 0.6).abs() < 1e-12 && off.degrees_of_freedom == 2);
        assert!((off.p_value - (-0.3_f64).exp()).abs() < 1e-12);
    }

    /// Cells expecting fewer than 5 are pooled until the pool expects 5;
    /// a sample in a cell whose expectation is exactly 0 rejects outright.
    #[test]
    fn small_cells_are_pooled_and_impossible_samples_reject() {
        let outcome = pearson_test(&[1, 2, 3, 50, 44], &[1.5, 2.0, 2.5, 50.0, 44.0], |i| i.to_string());
        // The pool {1.5, 2, 2.5} expects 6 and holds 6: X² = 0 over 3 cells.
        assert_eq!((outcome.pooled_cells, outcome.degrees_of_freedom), (3, 2));
        assert!(outcome.statistic.abs() < 1e-12);
        let impossible = pearson_test(&[1, 99], &[0.0, 100.0], |i| i.to_string());
        assert_eq!(impossible.p_value, 0.0);
    }

    /// Šidák: 20 independent tests at 1 − 0.99^(1/20) each fail together with
    /// probability exactly 0.01.
    #[test]
    fn sidak_correction_keeps_the_family_level() {
        let each = sidak_significance(0.01, 20);
        assert!(((1.0 - each).powi(20) - 0.99).abs() < 1e-14);
        assert!(each < 0.01 / 19.0 && each > 0.01 / 21.0);
    }

    /// The independent sample stream is uniform on the square (the control
    /// every other test relies on), and a density off by a gentle tilt
    /// 1 + 0.25 (x − ½) is rejected.
    #[test]
    fn uniform_stream_passes_and_a_tilted_density_is_rejected() {
        let test = ChiSquareTest {
            samples: 50_000,
            seed: 1,
            bins: (10, 10),
        };
        let uniform = test.planar((0.0, 1.0), (0.0, 1.0), |s| Some(s.next_2d()), |_| 1.0);
        assert!(uniform.accepts(SIGNIFICANCE), "{uniform}");
        let tilted = test.planar((0.0, 1.0), (0.0, 1.0), |s| Some(s.next_2d()), |p| 1.0 + 0.25 * (p.x - 0.5));
        assert!(tilted.p_value < 1e-6, "{tilted}");
    }

    /// Losing samples the density claims is caught by the "elsewhere" cell,
    /// and so is a density that does not integrate to the sample's mass.
    #[test]
    fn lost_samples_and_unnormalised_densities_are_rejected() {
        let test = ChiSquareTest {
            samples: 20_000,
            seed: 2,
            bins: (8, 8),
        };
        let lossy = test.planar(
            (0.0, 1.0),
            (0.0, 1.0),
            |s| {
                let p = s.next_2d();
                (s.next_1d() > 0.02).then_some(p)
            },
            |_| 1.0,
        );
        assert!(lossy.p_value < 1e-6, "{lossy}");
        let scaled = test.planar((0.0, 1.0), (0.0, 1.0), |s| Some(s.next_2d()), |_| 0.97);
        assert!(scaled.p_value < 1e-6, "{scaled}");
    }

    /// Directions: a uniform sphere sampled in a frame tilted off +z is still
    /// uniform about any axis; about a cap, the rest goes to "elsewhere".
    #[test]
    fn direction_binning_is_equal_area_about_any_axis() {
        let test = ChiSquareTest {
            samples: 40_000,
            seed: 3,
            bins: (8, 16),
        };
        let uniform = |s: &mut Sampler| Some(super::super::warp::square_to_uniform_sphere(s.next_2d()));
        let pdf = |_| 1.0 / (4.0 * std::f64::consts::PI);
        let cap = SphericalCap {
            axis: DVec3::new(0.3, -0.5, 0.8).normalize(),
            cos_theta_min: 0.2,
        };
        let outcome = test.directions(cap, uniform, pdf);
        assert!(outcome.accepts(SIGNIFICANCE), "{outcome}");
        // The same samples against a density crowding the cap's pole.
        let wrong = test.directions(cap, uniform, |w: DVec3| {
            1.5 * w.dot(cap.axis).max(0.0).powi(2) / std::f64::consts::PI
        });
        assert!(wrong.p_value < 1e-6, "{wrong}");
    }
}
