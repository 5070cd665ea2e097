//! Does shading paths side by side in SIMD lanes pay? A measurement of
//! the wavefront plan in docs/performance.md ("A wavefront prototype on
//! Mitsuba's box") on the scenes it names first: diffuse surfaces of one
//! colour, one quad light, a black background, a pinhole camera.
//!
//! Renders the scene twice on one thread: by the path tracer (one path at
//! a time), and by a wavefront over each row's paths (Laine, Karras & Aila
//! 2013): every live path's draws and closest hit (scalar), then the
//! shading of four paths per instruction (`wide::f64x4`: frame, BSDF
//! sample, light sample, MIS weight, spawned rays), then the shadow rays
//! (scalar), then throughput, roulette and compaction. The lanes repeat
//! the path tracer's own operations in the same order (its frame, disk
//! map, sine and cosine series, area density, origin offset), and each
//! path draws the same sampler dimensions, so the two images must agree
//! bit for bit: the example counts the pixels that do, and prints both
//! rates and where the wavefront's time goes.
//!
//! ```sh
//! RUSTFLAGS="-C target-cpu=x86-64-v3" cargo run --release --example wavefront_box -- \
//!     benches/peers/cornell_box_mitsuba.toml 256 256 8 3
//! ```
//! (scene, width, height, samples per pixel, repetitions; the AVX2 build
//! gives `f64x4` its four lanes).

use glam::{DVec2, DVec3};
use prism::accel::{Portable, Traversal};
use prism::color::Color;
use prism::geometry::Shape;
use prism::integrator::path::{PathTracer, camera_ray};
use prism::light::{Emitter, EmitterSource};
use prism::material::Material;
use prism::material::texture::Texture;
use prism::math::Ray;
use prism::math::ray::{gamma, offset_ray_origin};
use prism::math::trig::INVERSE_FACTORIALS;
use prism::math::warp::power_heuristic;
use prism::sampler::Sampler;
use prism::scene::{Leaving, Scene, load_scene_file};
use std::f64::consts::{FRAC_1_PI, FRAC_PI_4};
use std::time::Instant;
use wide::{CmpEq, CmpGt, CmpLt, CmpNe, f64x4, u64x4};

/// Bounces before Russian roulette (the path tracer's).
const ROULETTE_START: u32 = 3;

/// The scene's one light, a quad.
struct QuadLight {
    corner: DVec3,
    edge_u: DVec3,
    edge_v: DVec3,
    normal: DVec3,
    area: f64,
    radiance: Color,
    leaving: Leaving,
}

/// Per-row path state, one slot per pixel of the row.
struct Paths {
    sampler: Vec<Sampler>,
    ray: Vec<Ray>,
    throughput: Vec<Color>,
    radiance: Vec<Color>,
    previous_pdf: Vec<f64>,
    previous_point: Vec<DVec3>,
    leaving: Vec<Leaving>,
    /// Seconds and rays per stage, over every row rendered.
    stages: Stages,
}

/// A row's paths and the stages' buffers, reused from row to row.
struct Wavefront {
    paths: Paths,
    hits: Hits,
    shaded: Shaded,
    /// The slots of the paths still going.
    active: Vec<u32>,
}

/// Where the wavefront's time goes.
#[derive(Clone, Copy, Debug, Default)]
struct Stages {
    /// The bounce's draws, closest hits and the hits' records written side by side.
    closest_hits: f64,
    /// The lanes: BSDF and light samples, MIS weights, spawned rays.
    shading: f64,
    shadow_rays: f64,
    /// Throughput, roulette and the surviving paths compacted.
    continuation: f64,
    closest_hit_rays: u64,
    shadow_ray_count: u64,
}

/// The diffuse hits of one bounce, side by side (structure of arrays),
/// written by index and padded to a multiple of four.
#[derive(Default)]
struct Hits {
    len: usize,
    slot: Vec<u32>,
    primitive: Vec<u32>,
    point: [Vec<f64>; 3],
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
struct Shaded {
    contribution: [Vec<f64>; 3],
    lit: Vec<f64>,
    shadow_origin: [Vec<f64>; 3],
    shadow_direction: [Vec<f64>; 3],
    shadow_end: Vec<f64>,
    next_origin: [Vec<f64>; 3],
    next_direction: [Vec<f64>; 3],
    next_throughput: [Vec<f64>; 3],
    pdf: Vec<f64>,
    continues: Vec<f64>,
}

fn sized(capacity: usize) -> Vec<f64> {
    vec![0.0; capacity]
}

fn sized3(capacity: usize) -> [Vec<f64>; 3] {
    [sized(capacity), sized(capacity), sized(capacity)]
}

impl Hits {
    fn new(capacity: usize) -> Self {
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
    fn push(
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
    fn pad(&mut self) {
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
    fn new(capacity: usize) -> Self {
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
fn lanes(v: &[f64], k: usize) -> f64x4 {
    f64x4::new([v[k], v[k + 1], v[k + 2], v[k + 3]])
}

#[inline(always)]
fn lanes3(v: &[Vec<f64>; 3], k: usize) -> [f64x4; 3] {
    [lanes(&v[0], k), lanes(&v[1], k), lanes(&v[2], k)]
}

#[inline(always)]
fn store(v: &mut [f64], k: usize, x: f64x4) {
    v[k..k + 4].copy_from_slice(&x.to_array());
}

#[inline(always)]
fn store3(v: &mut [Vec<f64>; 3], k: usize, x: [f64x4; 3]) {
    for c in 0..3 {
        store(&mut v[c], k, x[c]);
    }
}

#[inline(always)]
fn dot(a: [f64x4; 3], b: [f64x4; 3]) -> f64x4 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn select(mask: f64x4, a: f64x4, b: f64x4) -> f64x4 {
    mask.blend(a, b)
}

/// `math::trig::cos_sin_eighth` in four lanes (the same operations).
#[inline(always)]
fn cos_sin_eighth(x: f64x4) -> (f64x4, f64x4) {
    let f = INVERSE_FACTORIALS.map(f64x4::splat);
    let (x2, x4) = (x * x, x * x * (x * x));
    let x8 = x4 * x4;
    let sin_tail = ((-f[3] + x2 * f[5]) + x4 * (-f[7] + x2 * f[9])) + x8 * ((-f[11] + x2 * f[13]) + x4 * (-f[15] + x2 * f[17]));
    let cos_tail = ((-f[2] + x2 * f[4]) + x4 * (-f[6] + x2 * f[8])) + x8 * ((-f[10] + x2 * f[12]) + x4 * (-f[14] + x2 * f[16]));
    (f64x4::ONE + x2 * cos_tail, x + x * (x2 * sin_tail))
}

/// `math::warp::square_to_cosine_hemisphere` in four lanes.
#[inline(always)]
fn cosine_hemisphere(u: [f64x4; 2]) -> [f64x4; 3] {
    let two = f64x4::splat(2.0);
    let (ox, oy) = (two * u[0] - f64x4::ONE, two * u[1] - f64x4::ONE);
    let centre = ox.cmp_eq(f64x4::ZERO) & oy.cmp_eq(f64x4::ZERO);
    let x_major = ox.abs().cmp_gt(oy.abs());
    let (radius, other) = (select(x_major, ox, oy), select(x_major, oy, ox));
    let (cos, sin) = cos_sin_eighth(f64x4::splat(FRAC_PI_4) * (other / radius));
    let x = select(centre, f64x4::ZERO, radius * select(x_major, cos, sin));
    let y = select(centre, f64x4::ZERO, radius * select(x_major, sin, cos));
    let z = (f64x4::ONE - (x * x + y * y)).max(f64x4::ZERO).sqrt();
    [x, y, z]
}

/// `math::ray::offset_ray_origin` in four lanes; `None` where a lane needs
/// the library's step (a zero or non-finite coordinate that moves).
#[inline(always)]
fn offset_origins(p: [f64x4; 3], error: [f64x4; 3], n: [f64x4; 3], direction: [f64x4; 3]) -> Option<[f64x4; 3]> {
    let distance = n[0].abs() * error[0] + n[1].abs() * error[1] + n[2].abs() * error[2];
    let negate: u64x4 = bytemuck::cast(dot(direction, n).cmp_lt(f64x4::ZERO));
    let sign_bit = u64x4::splat(1 << 63);
    let mut out = [f64x4::ZERO; 3];
    let mut special = f64x4::ZERO;
    for c in 0..3 {
        let offset = distance * n[c];
        let offset: f64x4 = bytemuck::cast(bytemuck::cast::<f64x4, u64x4>(offset) ^ (negate & sign_bit));
        let origin = p[c] + offset;
        let (origin_bits, offset_bits) = (bytemuck::cast::<f64x4, u64x4>(origin), bytemuck::cast::<f64x4, u64x4>(offset));
        let sign_differs = (origin_bits ^ offset_bits) >> 63;
        let step = u64x4::splat(1) - (sign_differs << 1);
        let moving = offset.abs().cmp_gt(f64x4::ZERO);
        let moves: u64x4 = bytemuck::cast(moving);
        out[c] = bytemuck::cast(origin_bits + (step & moves));
        let magnitude = origin.abs();
        let ordinary = magnitude.cmp_gt(f64x4::ZERO) & magnitude.cmp_lt(f64x4::splat(f64::INFINITY));
        special |= moving & !ordinary;
    }
    (!special.any()).then_some(out)
}

/// The same origins one lane at a time, by the library (the rare groups
/// with a special lane).
fn offset_origins_by_library(p: [f64x4; 3], error: [f64x4; 3], n: [f64x4; 3], direction: [f64x4; 3]) -> [f64x4; 3] {
    let unpack = |v: [f64x4; 3]| v.map(|x| x.to_array());
    let (p, error, n, direction) = (unpack(p), unpack(error), unpack(n), unpack(direction));
    let mut out = [[0.0; 4]; 3];
    for lane in 0..4 {
        let at = |v: &[[f64; 4]; 3]| DVec3::new(v[0][lane], v[1][lane], v[2][lane]);
        let o = offset_ray_origin(at(&p), at(&error), at(&n), at(&direction));
        (out[0][lane], out[1][lane], out[2][lane]) = (o.x, o.y, o.z);
    }
    out.map(f64x4::new)
}

/// One bounce's shading of every diffuse hit, four at a time.
#[inline(always)]
fn shade(hits: &Hits, light: &QuadLight, shaded: &mut Shaded) {
    let splat3 = |v: DVec3| [f64x4::splat(v.x), f64x4::splat(v.y), f64x4::splat(v.z)];
    let (corner, edge_u, edge_v, light_normal) = (
        splat3(light.corner),
        splat3(light.edge_u),
        splat3(light.edge_v),
        splat3(light.normal),
    );
    let (area, gamma6, one_over_pi) = (f64x4::splat(light.area), f64x4::splat(gamma(6)), f64x4::splat(FRAC_1_PI));
    let radiance = splat3(light.radiance);
    for k in (0..hits.len).step_by(4) {
        let p = lanes3(&hits.point, k);
        let n = lanes3(&hits.normal, k);
        let error = lanes3(&hits.error, k);
        let incoming = lanes3(&hits.incoming, k);
        let wo = [-incoming[0], -incoming[1], -incoming[2]];
        // The frame (Duff et al. 2017), as `math::Frame::from_normal`.
        let sign = f64x4::ONE.copysign(n[2]);
        let a = -f64x4::ONE / (sign + n[2]);
        let b = n[0] * n[1] * a;
        let s = [f64x4::ONE + sign * n[0] * n[0] * a, sign * b, -sign * n[0]];
        let t = [b, sign + n[1] * n[1] * a, -n[1]];
        let wo_z = dot(wo, n);
        // The BSDF sample: cosine-weighted on wo's side.
        let mut local = cosine_hemisphere([lanes(&hits.direction_u[0], k), lanes(&hits.direction_u[1], k)]);
        local[2] = select(wo_z.cmp_lt(f64x4::ZERO), -local[2], local[2]);
        let bsdf_pdf = local[2].abs().max(f64x4::ZERO) * one_over_pi;
        let world = [0, 1, 2].map(|c| s[c] * local[0] + t[c] * local[1] + n[c] * local[2]);
        // The light sample, by area (`geometry::sampling::by_area`).
        let (lu, lv) = (lanes(&hits.light_u[0], k), lanes(&hits.light_u[1], k));
        let q = [0, 1, 2].map(|c| corner[c] + lu * edge_u[c] + lv * edge_v[c]);
        let q_error = [0, 1, 2].map(|c| gamma6 * (corner[c].abs() + (lu * edge_u[c]).abs() + (lv * edge_v[c]).abs()));
        let to = [0, 1, 2].map(|c| q[c] - p[c]);
        let distance_squared = dot(to, to);
        let distance = distance_squared.sqrt();
        let projected = dot(light_normal, to).abs();
        let light_pdf = distance_squared * distance / (projected * area);
        let wi = [0, 1, 2].map(|c| to[c] / distance);
        let facing = dot(light_normal, [-wi[0], -wi[1], -wi[2]]).cmp_gt(f64x4::ZERO);
        let wi_z = dot(wi, n);
        let same_side = (wo_z * wi_z).cmp_gt(f64x4::ZERO);
        let cos = wi_z.abs();
        let pdf_b = wi_z.abs().max(f64x4::ZERO) * one_over_pi;
        let (a2, b2) = (light_pdf * light_pdf, pdf_b * pdf_b);
        let weight = a2 / (a2 + b2);
        let usable = facing
            & same_side
            & projected.cmp_gt(f64x4::ZERO)
            & distance_squared.cmp_gt(f64x4::ZERO)
            & light_pdf.cmp_lt(f64x4::splat(f64::INFINITY));
        let scale = weight / light_pdf;
        let albedo = lanes3(&hits.albedo, k);
        let throughput = lanes3(&hits.throughput, k);
        let contribution = [0, 1, 2].map(|c| throughput[c] * (albedo[c] * one_over_pi * cos) * radiance[c] * scale);
        let nonzero =
            contribution[0].cmp_ne(f64x4::ZERO) | contribution[1].cmp_ne(f64x4::ZERO) | contribution[2].cmp_ne(f64x4::ZERO);
        let err_sum = q_error[0].abs() + q_error[1].abs() + q_error[2].abs();
        let shadow_origin = offset_origins(p, error, n, wi).unwrap_or_else(|| offset_origins_by_library(p, error, n, wi));
        let offset = (shadow_origin[0] - p[0]).abs() + (shadow_origin[1] - p[1]).abs() + (shadow_origin[2] - p[2]).abs();
        let t_end = distance * f64x4::splat(1.0 - 1e-9) - err_sum - offset;
        store3(&mut shaded.contribution, k, contribution);
        store(&mut shaded.lit, k, usable & nonzero);
        store3(&mut shaded.shadow_origin, k, shadow_origin);
        store3(&mut shaded.shadow_direction, k, wi);
        store(&mut shaded.shadow_end, k, t_end);
        // The continuation: throughput, the spawned ray (`Ray::spawn`).
        let next_throughput = [0, 1, 2].map(|c| throughput[c] * albedo[c]);
        let alive = bsdf_pdf.cmp_gt(f64x4::ZERO)
            & (next_throughput[0].cmp_ne(f64x4::ZERO)
                | next_throughput[1].cmp_ne(f64x4::ZERO)
                | next_throughput[2].cmp_ne(f64x4::ZERO));
        let next_origin = offset_origins(p, error, n, world).unwrap_or_else(|| offset_origins_by_library(p, error, n, world));
        let inverse_length = f64x4::ONE / dot(world, world).sqrt();
        store3(&mut shaded.next_origin, k, next_origin);
        store3(&mut shaded.next_direction, k, world.map(|w| w * inverse_length));
        store3(&mut shaded.next_throughput, k, next_throughput);
        store(&mut shaded.pdf, k, bsdf_pdf);
        store(&mut shaded.continues, k, alive);
    }
}

#[inline(always)]
fn at3(v: &[Vec<f64>; 3], i: usize) -> DVec3 {
    DVec3::new(v[0][i], v[1][i], v[2][i])
}

/// One row by the wavefront.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn wavefront_row(
    traversal: impl Traversal,
    scene: &Scene,
    light: &QuadLight,
    albedos: &[Option<Color>],
    camera: &prism::camera::Camera,
    settings: &prism::settings::RenderSettings,
    (y, sample): (u32, u32),
    state: &mut Wavefront,
) {
    let Wavefront {
        paths,
        hits,
        shaded,
        active,
    } = state;
    let size = (settings.width, settings.height);
    paths.sampler.clear();
    paths.ray.clear();
    active.clear();
    for x in 0..settings.width {
        let mut sampler = Sampler::new(settings.sampler, y as u64 * size.0 as u64 + x as u64, sample, settings.seed);
        paths.ray.push(camera_ray(camera, size, x, y, &mut sampler));
        paths.sampler.push(sampler);
        paths.throughput[x as usize] = Color::ONE;
        paths.radiance[x as usize] = Color::ZERO;
        paths.previous_pdf[x as usize] = 0.0;
        paths.leaving[x as usize] = Leaving::Nothing;
        active.push(x);
    }
    for bounce in 0..=settings.max_depth {
        if active.is_empty() {
            break;
        }
        hits.len = 0;
        paths.stages.closest_hit_rays += active.len() as u64;
        let clock = Instant::now();
        for &slot in active.iter() {
            let s = slot as usize;
            // The bounce's draws, in the path tracer's order (`BounceDraws`),
            // before the traversal so that their hashes overlap it.
            let sampler = &mut paths.sampler[s];
            sampler.skip(); // one light: no choice
            let light_u = sampler.next_2d();
            let direction_u = sampler.next_2d();
            sampler.skip(); // the lobe, unread by diffuse surfaces
            let ray = paths.ray[s];
            let Some(found) = scene.intersect_leaving_inlined(traversal, &ray, f64::INFINITY, paths.leaving[s]) else {
                continue;
            };
            let hit = found.hit;
            match albedos[found.primitive as usize] {
                None => {
                    // The light: emission, weighted against light sampling.
                    let material = scene.material_of(found.primitive);
                    if let Some(emitted) = material.emission_towards(hit.geometric_normal.dot(-ray.direction)) {
                        let weight = match scene.lights.light_of_primitive(found.primitive) {
                            Some(index) if bounce > 0 => {
                                let light_pdf =
                                    scene
                                        .lights
                                        .pdf(scene, index, paths.previous_point[s], hit.point, hit.geometric_normal);
                                power_heuristic(paths.previous_pdf[s], light_pdf)
                            }
                            _ => 1.0,
                        };
                        paths.radiance[s] += paths.throughput[s] * emitted.rgb * weight;
                    }
                }
                Some(_) if bounce >= settings.max_depth => {}
                Some(albedo) => hits.push(
                    slot,
                    found.primitive,
                    hit.point,
                    hit.point_error,
                    hit.shading_normal,
                    ray.direction,
                    albedo,
                    paths.throughput[s],
                    light_u,
                    direction_u,
                ),
            }
        }
        let count = hits.len;
        let hits_done = clock.elapsed();
        hits.pad();
        shade(hits, light, shaded);
        let shading_done = clock.elapsed();
        for i in 0..count {
            if shaded.lit[i] != 0.0 {
                paths.stages.shadow_ray_count += 1;
                let shadow = Ray {
                    origin: at3(&shaded.shadow_origin, i),
                    direction: at3(&shaded.shadow_direction, i),
                };
                let from = scene.leaving(hits.primitive[i]);
                if !scene.occluded_between_inlined(traversal, &shadow, shaded.shadow_end[i], from, light.leaving) {
                    paths.radiance[hits.slot[i] as usize] += at3(&shaded.contribution, i);
                }
            }
        }
        let shadows_done = clock.elapsed();
        let mut kept = 0;
        for i in 0..count {
            if shaded.continues[i] == 0.0 {
                continue;
            }
            let s = hits.slot[i] as usize;
            let mut throughput = at3(&shaded.next_throughput, i);
            paths.previous_pdf[s] = shaded.pdf[i];
            paths.previous_point[s] = at3(&hits.point, i);
            paths.ray[s] = Ray {
                origin: at3(&shaded.next_origin, i),
                direction: at3(&shaded.next_direction, i),
            };
            paths.leaving[s] = scene.leaving(hits.primitive[i]);
            let sampler = &mut paths.sampler[s];
            if bounce + 1 < ROULETTE_START {
                sampler.skip();
            } else {
                let survival = throughput.max_element().min(0.95);
                if sampler.next_1d_independent() >= survival {
                    continue;
                }
                throughput /= survival;
            }
            paths.throughput[s] = throughput;
            active[kept] = s as u32;
            kept += 1;
        }
        active.truncate(kept);
        let stages = &mut paths.stages;
        stages.closest_hits += hits_done.as_secs_f64();
        stages.shading += (shading_done - hits_done).as_secs_f64();
        stages.shadow_rays += (shadows_done - shading_done).as_secs_f64();
        stages.continuation += (clock.elapsed() - shadows_done).as_secs_f64();
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).map_or("benches/peers/cornell_box_mitsuba.toml", String::as_str);
    let number = |i: usize, default: u32| args.get(i).map_or(Ok(default), |a| a.parse::<u32>());
    let (width, height, spp, repetitions) = (number(2, 256)?, number(3, 256)?, number(4, 8)?, number(5, 3)?);
    let loaded = load_scene_file(std::path::Path::new(path))?;
    let (scene, camera) = (&loaded.scene, &loaded.camera);
    let mut settings = loaded.settings.clone();
    settings.width = width;
    settings.height = height;
    if scene.lights.len() != 1 || camera.has_lens() || scene.background != Color::ZERO {
        return Err("the prototype takes one light, a pinhole camera and a black background".into());
    }
    let light = &scene.lights.lights[0];
    let Emitter::Shape(Shape::Quad(quad)) = scene.emitter(light.primitive) else {
        return Err("the prototype's light is a quad".into());
    };
    let light = QuadLight {
        corner: quad.corner,
        edge_u: quad.edge_u,
        edge_v: quad.edge_v,
        normal: quad.normal,
        area: quad.area(),
        radiance: light.radiance,
        leaving: scene.leaving(light.primitive),
    };
    let mut albedos = Vec::new();
    for primitive in 0..scene.primitive_count() as u32 {
        albedos.push(match scene.material_of(primitive) {
            Material::Diffuse {
                albedo: Texture::Constant(albedo),
            } => Some(*albedo),
            Material::Emissive { .. } => None,
            _ => return Err("the prototype takes diffuse surfaces of one colour and emitters".into()),
        });
    }
    let tracer = PathTracer::from_settings(&settings);
    let pixels = (width * height) as usize;
    let scalar = |image: &mut Vec<Color>| {
        for sample in 0..spp {
            for y in 0..height {
                for x in 0..width {
                    let mut sampler = Sampler::new(settings.sampler, y as u64 * width as u64 + x as u64, sample, settings.seed);
                    let ray = camera_ray(camera, (width, height), x, y, &mut sampler);
                    image[(y * width + x) as usize] += tracer.radiance(scene, ray, &mut sampler);
                }
            }
        }
    };
    let w = width as usize;
    let paths = Paths {
        sampler: Vec::with_capacity(w),
        ray: Vec::with_capacity(w),
        throughput: vec![Color::ONE; w],
        radiance: vec![Color::ZERO; w],
        previous_pdf: vec![0.0; w],
        previous_point: vec![DVec3::ZERO; w],
        leaving: vec![Leaving::Nothing; w],
        stages: Stages::default(),
    };
    let mut state = Wavefront {
        paths,
        hits: Hits::new(w + 4),
        shaded: Shaded::new(w + 4),
        active: Vec::with_capacity(w),
    };
    let mut wavefront = |image: &mut Vec<Color>| {
        for sample in 0..spp {
            for y in 0..height {
                match scene.bvh().avx2() {
                    // The whole row compiled for AVX2, the traversals inside.
                    Some(avx2) => avx2.run(
                        #[inline(always)]
                        || wavefront_row(avx2, scene, &light, &albedos, camera, &settings, (y, sample), &mut state),
                    ),
                    None => wavefront_row(Portable, scene, &light, &albedos, camera, &settings, (y, sample), &mut state),
                }
                for x in 0..w {
                    image[y as usize * w + x] += state.paths.radiance[x];
                }
            }
        }
    };
    let (mut best_scalar, mut best_wavefront) = (f64::INFINITY, f64::INFINITY);
    let (mut scalar_image, mut wavefront_image) = (vec![Color::ZERO; pixels], vec![Color::ZERO; pixels]);
    for repetition in 0..repetitions {
        scalar_image.fill(Color::ZERO);
        let start = Instant::now();
        scalar(&mut scalar_image);
        let scalar_seconds = start.elapsed().as_secs_f64();
        wavefront_image.fill(Color::ZERO);
        let start = Instant::now();
        wavefront(&mut wavefront_image);
        let wavefront_seconds = start.elapsed().as_secs_f64();
        best_scalar = best_scalar.min(scalar_seconds);
        best_wavefront = best_wavefront.min(wavefront_seconds);
        let paths_count = (pixels as u64 * spp as u64) as f64;
        println!(
            "repetition {repetition}: scalar {:.3} M paths/s, wavefront {:.3} M paths/s, wavefront ÷ scalar {:.3}",
            paths_count / scalar_seconds / 1e6,
            paths_count / wavefront_seconds / 1e6,
            scalar_seconds / wavefront_seconds
        );
    }
    let stages = state.paths.stages;
    let total = stages.closest_hits + stages.shading + stages.shadow_rays + stages.continuation;
    let share = |seconds: f64| 100.0 * seconds / total;
    println!(
        "wavefront stages, share of their time: draws and closest hits {:.1}% ({:.1} ns per ray), shading in lanes {:.1}%, \
         shadow rays {:.1}% ({:.1} ns per ray), continuation {:.1}%",
        share(stages.closest_hits),
        1e9 * stages.closest_hits / stages.closest_hit_rays as f64,
        share(stages.shading),
        share(stages.shadow_rays),
        1e9 * stages.shadow_rays / stages.shadow_ray_count as f64,
        share(stages.continuation)
    );
    let largest = scalar_image
        .iter()
        .zip(&wavefront_image)
        .map(|(a, b)| (*a - *b).abs().max_element() / a.abs().max_element().max(1e-12))
        .fold(0.0, f64::max);
    let identical = scalar_image.iter().zip(&wavefront_image).filter(|(a, b)| a == b).count();
    let mean = |image: &[Color]| image.iter().copied().sum::<Color>() / (pixels as f64 * spp as f64);
    println!(
        "fastest ÷ fastest {:.3}; pixels bit for bit equal: {identical} of {pixels}; largest relative difference {largest:.3e}; means {} and {}",
        best_scalar / best_wavefront,
        mean(&scalar_image),
        mean(&wavefront_image)
    );
    Ok(())
}
