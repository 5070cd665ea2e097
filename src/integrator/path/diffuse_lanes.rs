//! The shading of a bounce's diffuse hits four at a time, one path per
//! lane of an AVX register ([`F64x4`]) (for [`super::diffuse_rows`]): the shading frame,
//! the cosine-weighted BSDF sample, the light sample on the scene's one
//! quad light, its MIS weight (the power heuristic), and the origins and
//! directions of the shadow ray and of the ray that continues the path.
//!
//! Every lane repeats the path tracer's own operations in the same order
//! (`math::Frame::from_normal`, `math::warp::square_to_cosine_hemisphere`
//! with `math::trig`'s sine and cosine series, `geometry::sampling::by_area`,
//! `math::ray::offset_ray_origin`, `Ray::spawn`), and Rust never fuses a
//! product and a sum, so each lane's numbers are the scalar tracer's bit
//! for bit (tested in `diffuse_rows`).

use crate::accel::Avx2;
use crate::color::Color;
use crate::math::avx_lanes::F64x4;
use crate::math::ray::{gamma, offset_ray_origin};
use crate::math::trig::INVERSE_FACTORIALS;
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_1_PI, FRAC_PI_4};

/// The scene's one light, a one-sided quad of uniform radiance.
#[derive(Clone, Copy, Debug)]
pub(super) struct QuadLight {
    pub corner: DVec3,
    pub edge_u: DVec3,
    pub edge_v: DVec3,
    /// Unit normal of the emitting side.
    pub normal: DVec3,
    pub area: f64,
    pub radiance: Color,
}

/// The diffuse hits of one bounce, side by side (structure of arrays),
/// written by index and padded to a multiple of four.
#[derive(Default)]
pub(super) struct Hits {
    pub len: usize,
    pub slot: Vec<u32>,
    pub primitive: Vec<u32>,
    pub point: [Vec<f64>; 3],
    error: [Vec<f64>; 3],
    normal: [Vec<f64>; 3],
    incoming: [Vec<f64>; 3],
    albedo: [Vec<f64>; 3],
    throughput: [Vec<f64>; 3],
    light_u: [Vec<f64>; 2],
    direction_u: [Vec<f64>; 2],
}

/// What the lanes give back per hit.
#[derive(Default)]
pub(super) struct Shaded {
    pub contribution: [Vec<f64>; 3],
    pub lit: Vec<f64>,
    pub shadow_origin: [Vec<f64>; 3],
    pub shadow_direction: [Vec<f64>; 3],
    pub shadow_end: Vec<f64>,
    pub next_origin: [Vec<f64>; 3],
    pub next_direction: [Vec<f64>; 3],
    pub next_throughput: [Vec<f64>; 3],
    pub pdf: Vec<f64>,
    pub continues: Vec<f64>,
}

fn sized(capacity: usize) -> Vec<f64> {
    vec![0.0; capacity]
}

fn sized3(capacity: usize) -> [Vec<f64>; 3] {
    [sized(capacity), sized(capacity), sized(capacity)]
}

impl Hits {
    pub(super) fn new(capacity: usize) -> Self {
        Self {
            len: 0,
            slot: vec![0; capacity],
            primitive: vec![0; capacity],
            point: sized3(capacity),
            error: sized3(capacity),
            normal: sized3(capacity),
            incoming: sized3(capacity),
            albedo: sized3(capacity),
            throughput: sized3(capacity),
            light_u: [sized(capacity), sized(capacity)],
            direction_u: [sized(capacity), sized(capacity)],
        }
    }

    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn push(
        &mut self,
        slot: u32,
        primitive: u32,
        point: DVec3,
        error: DVec3,
        normal: DVec3,
        incoming: DVec3,
        albedo: Color,
        throughput: Color,
        light_u: DVec2,
        direction_u: DVec2,
    ) {
        let i = self.len;
        self.slot[i] = slot;
        self.primitive[i] = primitive;
        for (field, value) in [
            (&mut self.point, point),
            (&mut self.error, error),
            (&mut self.normal, normal),
            (&mut self.incoming, incoming),
            (&mut self.albedo, albedo),
            (&mut self.throughput, throughput),
        ] {
            field[0][i] = value.x;
            field[1][i] = value.y;
            field[2][i] = value.z;
        }
        self.light_u[0][i] = light_u.x;
        self.light_u[1][i] = light_u.y;
        self.direction_u[0][i] = direction_u.x;
        self.direction_u[1][i] = direction_u.y;
        self.len += 1;
    }

    /// Pads with copies of the last hit to a multiple of four (their
    /// results are not read).
    pub(super) fn pad(&mut self) {
        let last = self.len.wrapping_sub(1);
        for i in self.len..self.len.next_multiple_of(4) {
            self.slot[i] = u32::MAX;
            self.primitive[i] = self.primitive[last];
            for v in self
                .point
                .iter_mut()
                .chain(&mut self.error)
                .chain(&mut self.normal)
                .chain(&mut self.incoming)
                .chain(&mut self.albedo)
                .chain(&mut self.throughput)
                .chain(&mut self.light_u)
                .chain(&mut self.direction_u)
            {
                v[i] = v[last];
            }
        }
    }
}

impl Shaded {
    pub(super) fn new(capacity: usize) -> Self {
        Self {
            contribution: sized3(capacity),
            lit: sized(capacity),
            shadow_origin: sized3(capacity),
            shadow_direction: sized3(capacity),
            shadow_end: sized(capacity),
            next_origin: sized3(capacity),
            next_direction: sized3(capacity),
            next_throughput: sized3(capacity),
            pdf: sized(capacity),
            continues: sized(capacity),
        }
    }
}

#[inline(always)]
fn lanes(avx2: Avx2, v: &[f64], k: usize) -> F64x4 {
    F64x4::new(avx2, [v[k], v[k + 1], v[k + 2], v[k + 3]])
}

#[inline(always)]
fn lanes3(avx2: Avx2, v: &[Vec<f64>; 3], k: usize) -> [F64x4; 3] {
    [lanes(avx2, &v[0], k), lanes(avx2, &v[1], k), lanes(avx2, &v[2], k)]
}

#[inline(always)]
fn store(v: &mut [f64], k: usize, x: F64x4) {
    v[k..k + 4].copy_from_slice(&x.to_array());
}

#[inline(always)]
fn store3(v: &mut [Vec<f64>; 3], k: usize, x: [F64x4; 3]) {
    for c in 0..3 {
        store(&mut v[c], k, x[c]);
    }
}

#[inline(always)]
fn dot(a: [F64x4; 3], b: [F64x4; 3]) -> F64x4 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn select(mask: F64x4, a: F64x4, b: F64x4) -> F64x4 {
    mask.blend(a, b)
}

/// `math::trig::cos_sin_eighth` in four lanes (the same operations).
#[inline(always)]
fn cos_sin_eighth(x: F64x4) -> (F64x4, F64x4) {
    let f = INVERSE_FACTORIALS.map(|c| x.splat_like(c));
    let (x2, x4) = (x * x, x * x * (x * x));
    let x8 = x4 * x4;
    let sin_tail = ((-f[3] + x2 * f[5]) + x4 * (-f[7] + x2 * f[9])) + x8 * ((-f[11] + x2 * f[13]) + x4 * (-f[15] + x2 * f[17]));
    let cos_tail = ((-f[2] + x2 * f[4]) + x4 * (-f[6] + x2 * f[8])) + x8 * ((-f[10] + x2 * f[12]) + x4 * (-f[14] + x2 * f[16]));
    (f[0] + x2 * cos_tail, x + x * (x2 * sin_tail))
}

/// `math::warp::square_to_cosine_hemisphere` in four lanes.
#[inline(always)]
fn cosine_hemisphere(u: [F64x4; 2]) -> [F64x4; 3] {
    let (zero, one, two) = (u[0].splat_like(0.0), u[0].splat_like(1.0), u[0].splat_like(2.0));
    let (ox, oy) = (two * u[0] - one, two * u[1] - one);
    let centre = ox.cmp_eq(zero) & oy.cmp_eq(zero);
    let x_major = ox.abs().cmp_gt(oy.abs());
    let (radius, other) = (select(x_major, ox, oy), select(x_major, oy, ox));
    let (cos, sin) = cos_sin_eighth(u[0].splat_like(FRAC_PI_4) * (other / radius));
    let x = select(centre, zero, radius * select(x_major, cos, sin));
    let y = select(centre, zero, radius * select(x_major, sin, cos));
    let z = (one - (x * x + y * y)).max(zero).sqrt();
    [x, y, z]
}

/// `math::ray::offset_ray_origin` in four lanes; `None` where a lane needs
/// the library's step (a zero or non-finite coordinate that moves).
#[inline(always)]
fn offset_origins(p: [F64x4; 3], error: [F64x4; 3], n: [F64x4; 3], direction: [F64x4; 3]) -> Option<[F64x4; 3]> {
    let (zero, infinity) = (p[0].splat_like(0.0), p[0].splat_like(f64::INFINITY));
    let distance = n[0].abs() * error[0] + n[1].abs() * error[1] + n[2].abs() * error[2];
    let negate = dot(direction, n).cmp_lt(zero);
    let mut out = [zero; 3];
    let mut special = zero;
    for c in 0..3 {
        let offset = (distance * n[c]).negate_where(negate);
        let origin = p[c] + offset;
        let moving = offset.abs().cmp_gt(zero);
        out[c] = origin.step_bits(offset, moving);
        let magnitude = origin.abs();
        let ordinary = magnitude.cmp_gt(zero) & magnitude.cmp_lt(infinity);
        special = special | (moving & !ordinary);
    }
    (!special.any()).then_some(out)
}

/// The same origins one lane at a time, by the library (the rare groups
/// with a special lane).
fn offset_origins_by_library(avx2: Avx2, p: [F64x4; 3], error: [F64x4; 3], n: [F64x4; 3], direction: [F64x4; 3]) -> [F64x4; 3] {
    let unpack = |v: [F64x4; 3]| v.map(|x| x.to_array());
    let (p, error, n, direction) = (unpack(p), unpack(error), unpack(n), unpack(direction));
    let mut out = [[0.0; 4]; 3];
    for lane in 0..4 {
        let at = |v: &[[f64; 4]; 3]| DVec3::new(v[0][lane], v[1][lane], v[2][lane]);
        let o = offset_ray_origin(at(&p), at(&error), at(&n), at(&direction));
        (out[0][lane], out[1][lane], out[2][lane]) = (o.x, o.y, o.z);
    }
    out.map(|lanes| F64x4::new(avx2, lanes))
}

/// One bounce's shading of every diffuse hit, four at a time.
#[inline(always)]
pub(super) fn shade(avx2: Avx2, hits: &Hits, light: &QuadLight, shaded: &mut Shaded) {
    let splat = |value: f64| F64x4::splat(avx2, value);
    let splat3 = |v: DVec3| [splat(v.x), splat(v.y), splat(v.z)];
    let (zero, one) = (splat(0.0), splat(1.0));
    let (corner, edge_u, edge_v, light_normal) = (
        splat3(light.corner),
        splat3(light.edge_u),
        splat3(light.edge_v),
        splat3(light.normal),
    );
    let (area, gamma6, one_over_pi) = (splat(light.area), splat(gamma(6)), splat(FRAC_1_PI));
    let radiance = splat3(light.radiance);
    for k in (0..hits.len).step_by(4) {
        let p = lanes3(avx2, &hits.point, k);
        let n = lanes3(avx2, &hits.normal, k);
        let error = lanes3(avx2, &hits.error, k);
        let incoming = lanes3(avx2, &hits.incoming, k);
        let wo = [-incoming[0], -incoming[1], -incoming[2]];
        // The frame (Duff et al. 2017), as `math::Frame::from_normal`.
        let sign = one.copysign(n[2]);
        let a = -one / (sign + n[2]);
        let b = n[0] * n[1] * a;
        let s = [one + sign * n[0] * n[0] * a, sign * b, -sign * n[0]];
        let t = [b, sign + n[1] * n[1] * a, -n[1]];
        let wo_z = dot(wo, n);
        // The BSDF sample: cosine-weighted on wo's side.
        let mut local = cosine_hemisphere([lanes(avx2, &hits.direction_u[0], k), lanes(avx2, &hits.direction_u[1], k)]);
        local[2] = select(wo_z.cmp_lt(zero), -local[2], local[2]);
        let bsdf_pdf = local[2].abs().max(zero) * one_over_pi;
        let world = [0, 1, 2].map(|c| s[c] * local[0] + t[c] * local[1] + n[c] * local[2]);
        // The light sample, by area (`geometry::sampling::by_area`).
        let (lu, lv) = (lanes(avx2, &hits.light_u[0], k), lanes(avx2, &hits.light_u[1], k));
        let q = [0, 1, 2].map(|c| corner[c] + lu * edge_u[c] + lv * edge_v[c]);
        let q_error = [0, 1, 2].map(|c| gamma6 * (corner[c].abs() + (lu * edge_u[c]).abs() + (lv * edge_v[c]).abs()));
        let to = [0, 1, 2].map(|c| q[c] - p[c]);
        let distance_squared = dot(to, to);
        let distance = distance_squared.sqrt();
        let projected = dot(light_normal, to).abs();
        let light_pdf = distance_squared * distance / (projected * area);
        let wi = [0, 1, 2].map(|c| to[c] / distance);
        let facing = dot(light_normal, [-wi[0], -wi[1], -wi[2]]).cmp_gt(zero);
        let wi_z = dot(wi, n);
        let same_side = (wo_z * wi_z).cmp_gt(zero);
        let cos = wi_z.abs();
        let pdf_b = wi_z.abs().max(zero) * one_over_pi;
        let (a2, b2) = (light_pdf * light_pdf, pdf_b * pdf_b);
        let weight = a2 / (a2 + b2);
        let usable =
            facing & same_side & projected.cmp_gt(zero) & distance_squared.cmp_gt(zero) & light_pdf.cmp_lt(splat(f64::INFINITY));
        let scale = weight / light_pdf;
        let albedo = lanes3(avx2, &hits.albedo, k);
        let throughput = lanes3(avx2, &hits.throughput, k);
        let contribution = [0, 1, 2].map(|c| throughput[c] * (albedo[c] * one_over_pi * cos) * radiance[c] * scale);
        let nonzero = contribution[0].cmp_ne(zero) | contribution[1].cmp_ne(zero) | contribution[2].cmp_ne(zero);
        let err_sum = q_error[0].abs() + q_error[1].abs() + q_error[2].abs();
        let shadow_origin = offset_origins(p, error, n, wi).unwrap_or_else(|| offset_origins_by_library(avx2, p, error, n, wi));
        let offset = (shadow_origin[0] - p[0]).abs() + (shadow_origin[1] - p[1]).abs() + (shadow_origin[2] - p[2]).abs();
        let t_end = distance * splat(1.0 - 1e-9) - err_sum - offset;
        store3(&mut shaded.contribution, k, contribution);
        store(&mut shaded.lit, k, usable & nonzero);
        store3(&mut shaded.shadow_origin, k, shadow_origin);
        store3(&mut shaded.shadow_direction, k, wi);
        store(&mut shaded.shadow_end, k, t_end);
        // The continuation: throughput, the spawned ray (`Ray::spawn`).
        let next_throughput = [0, 1, 2].map(|c| throughput[c] * albedo[c]);
        let alive = bsdf_pdf.cmp_gt(zero)
            & (next_throughput[0].cmp_ne(zero) | next_throughput[1].cmp_ne(zero) | next_throughput[2].cmp_ne(zero));
        let next_origin =
            offset_origins(p, error, n, world).unwrap_or_else(|| offset_origins_by_library(avx2, p, error, n, world));
        let inverse_length = one / dot(world, world).sqrt();
        store3(&mut shaded.next_origin, k, next_origin);
        store3(&mut shaded.next_direction, k, world.map(|w| w * inverse_length));
        store3(&mut shaded.next_throughput, k, next_throughput);
        store(&mut shaded.pdf, k, bsdf_pdf);
        store(&mut shaded.continues, k, alive);
    }
}

#[inline(always)]
pub(super) fn at3(v: &[Vec<f64>; 3], i: usize) -> DVec3 {
    DVec3::new(v[0][i], v[1][i], v[2][i])
}
