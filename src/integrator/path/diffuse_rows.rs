//! Path tracing for scenes of a few diffuse quads lit by one quad light
//! (a Cornell box of walls, blocks and a lamp): a row's paths traced side
//! by side, bounce by bounce (Laine, Karras & Aila, "Megakernels
//! Considered Harmful: Wavefront Path Tracing on GPUs", 2013, on the CPU).
//! Each bounce has four stages:
//!
//! 1. every live path's closest hit, four rays per query against all the
//!    quads ([`crate::accel::quad_packets`]), and its draws;
//! 2. the shading of the diffuse hits, four paths per instruction
//!    ([`super::diffuse_lanes`]);
//! 3. the shadow rays, four per query;
//! 4. throughput, Russian roulette, and the surviving paths gathered to
//!    the front.
//!
//! On Mitsuba's Cornell box this ran at 1.3–1.4 times the path-by-path
//! loop's paths per second (docs/performance.md, "Rays four at a time on a
//! scene of quads"). Neither half pays alone: with the rays four at a time
//! but each path shaded by the path tracer's scalar code, the row ran at
//! 0.88–0.93 of the path-by-path loop, whose traversals hide that code's
//! latency; with the shading in lanes but the rays traced one at a time, at
//! 0.98–1.01.
//!
//! **The same image as the path tracer.** Each path draws the same sampler
//! dimensions in the same order as [`PathTracer`] does, the lanes repeat
//! its arithmetic, the queries give the tree's answers, and each path adds
//! to its radiance in the same order (a hit light's emission, then the
//! light sample's contribution, bounce after bounce). So every pixel is
//! the same bit for bit (tested below), whatever order the paths are
//! traced in.

use super::PathTracer;
use super::diffuse_lanes::{Hits, QuadLight, Shaded, at3, shade};
use super::tracer::{ROULETTE_START, survival_probability};
use crate::accel::quad_packets::QuadHit;
use crate::accel::{Avx2, QuadPackets, RayLanes};
use crate::color::Color;
use crate::geometry::Shape;
use crate::light::{Emitter, EmitterSource};
use crate::material::{Material, Texture};
use crate::math::Ray;
use crate::math::warp::power_heuristic;
use crate::sampler::Sampler;
use crate::scene::{Intersection, Leaving, Scene};
use glam::DVec3;

/// What the rows need of a scene this kernel renders: its one light, and
/// each primitive's albedo (`None`: an emitter, which scatters nothing).
#[derive(Clone, Debug)]
pub(super) struct DiffuseQuads {
    light: QuadLight,
    /// The light's primitive.
    light_primitive: u32,
    albedos: Vec<Option<Color>>,
    max_depth: u32,
    /// The scene's four-ray queries.
    packets: QuadPackets,
}

impl DiffuseQuads {
    /// The kernel for `scene` traced by `tracer`, if the scene is one it
    /// renders as the tracer would: every primitive a quad (so the scene
    /// has four-ray queries), every material diffuse of one colour or
    /// emissive, one light (a one-sided quad of uniform RGB radiance), a
    /// black background, and light sampling on.
    pub(super) fn of(scene: &Scene, tracer: &PathTracer) -> Option<Self> {
        if !tracer.light_sampling || scene.background != Color::ZERO {
            return None;
        }
        // Primitive i is quad i of the packets.
        let quads = (0..scene.primitive_count() as u32)
            .map(|primitive| match scene.emitter(primitive) {
                Emitter::Shape(Shape::Quad(quad)) => Some(*quad),
                _ => None,
            })
            .collect::<Option<Vec<_>>>()?;
        let packets = QuadPackets::new(quads)?;
        let [light] = scene.lights.lights.as_slice() else {
            return None;
        };
        let Emitter::Shape(Shape::Quad(quad)) = scene.emitter(light.primitive) else {
            return None;
        };
        if light.two_sided || light.spectrum.is_some() {
            return None;
        }
        let albedos = (0..scene.primitive_count() as u32)
            .map(|primitive| match scene.material_of(primitive) {
                Material::Diffuse {
                    albedo: Texture::Constant(albedo),
                } => Some(Some(*albedo)),
                Material::Emissive { .. } => Some(None),
                _ => None,
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Self {
            light: QuadLight {
                corner: quad.corner,
                edge_u: quad.edge_u,
                edge_v: quad.edge_v,
                normal: quad.normal,
                area: quad.area(),
                radiance: light.radiance,
            },
            light_primitive: light.primitive,
            albedos,
            max_depth: tracer.max_depth,
            packets,
        })
    }
}

/// A row's paths and the stages' buffers, kept by each thread from row to
/// row ([`RowPaths::with`]).
#[derive(Default)]
pub(super) struct RowPaths {
    samplers: Vec<Sampler>,
    rays: Vec<Ray>,
    leaving: Vec<Leaving>,
    throughput: Vec<Color>,
    radiance: Vec<Color>,
    previous_pdf: Vec<f64>,
    previous_point: Vec<DVec3>,
    /// The paths still going (indices into the above), in column order.
    active: Vec<u32>,
    hits: Hits,
    shaded: Shaded,
    /// The hits whose light sample needs a shadow ray.
    lit: Vec<u32>,
}

impl DiffuseQuads {
    /// One sample of the radiance arriving at each of `columns`' pixels,
    /// written to `values` in the same order; `start(x)` gives the sampler
    /// of column `x`'s pixel sample and its camera ray. The four-ray
    /// queries run in AVX instructions (`avx2` proves the CPU has them).
    #[inline(always)]
    pub(super) fn radiance_of_row(
        &self,
        avx2: Avx2,
        scene: &Scene,
        columns: &[u32],
        start: impl Fn(u32) -> (Sampler, Ray),
        paths: &mut RowPaths,
        values: &mut Vec<Color>,
    ) {
        paths.start(columns, start);
        let capacity = columns.len().next_multiple_of(4);
        if paths.hits.slot.len() < capacity {
            (paths.hits, paths.shaded) = (Hits::new(capacity), Shaded::new(capacity));
        }
        for bounce in 0..=self.max_depth {
            if paths.active.is_empty() {
                break;
            }
            self.closest_hits(avx2, scene, bounce, paths);
            paths.hits.pad();
            shade(avx2, &paths.hits, &self.light, &mut paths.shaded);
            self.shadow_rays(avx2, paths);
            paths.go_on(bounce);
        }
        values.clear();
        values.extend_from_slice(&paths.radiance);
    }

    /// Stage 1: each live path's draws for the bounce, in the path tracer's
    /// order, and its closest hit; a light's emission is added at once, a
    /// diffuse hit written for the lanes.
    #[inline(always)]
    fn closest_hits(&self, avx2: Avx2, scene: &Scene, bounce: u32, paths: &mut RowPaths) {
        let packets = &self.packets;
        paths.hits.len = 0;
        let active = &paths.active;
        for group in active.chunks(4) {
            let path = |lane: usize| group[lane.min(group.len() - 1)] as usize;
            let rays = [0, 1, 2, 3].map(|lane| paths.rays[path(lane)]);
            let skipped = [0, 1, 2, 3].map(|lane| match paths.leaving[path(lane)] {
                Leaving::Quad(primitive) => primitive,
                Leaving::Nothing => u32::MAX,
            });
            let found = packets.nearest(avx2, &RayLanes::new(&rays), skipped);
            for (&slot, found) in group.iter().zip(found) {
                let s = slot as usize;
                // `BounceDraws`' dimensions: the light choice (none with
                // one light), the light point, the direction, the lobe
                // (which a diffuse surface does not read).
                let sampler = &mut paths.samplers[s];
                sampler.skip();
                let light_u = sampler.next_2d();
                let direction_u = sampler.next_2d();
                sampler.skip();
                let Some(QuadHit {
                    index: primitive,
                    t,
                    a,
                    b,
                }) = found
                else {
                    continue;
                };
                // Primitive i is quad i; a diffuse quad's hit record, as the
                // scene builds it, needs no texture coordinates but (a, b).
                let found = Intersection {
                    hit: packets.quad(primitive).surface_hit(t, a, b),
                    primitive,
                };
                let hit = found.hit;
                let ray = &paths.rays[s];
                match self.albedos[found.primitive as usize] {
                    None => {
                        // A light: its emission, weighted against light sampling
                        // after a diffuse bounce (the camera sees it whole).
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
                    Some(_) if bounce >= self.max_depth => {}
                    Some(albedo) => paths.hits.push(
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
        }
    }

    /// Stage 3: the shadow rays of the light samples that may add
    /// something, four per query; the unblocked ones add their contribution.
    #[inline(always)]
    fn shadow_rays(&self, avx2: Avx2, paths: &mut RowPaths) {
        let packets = &self.packets;
        let RowPaths {
            hits,
            shaded,
            lit,
            radiance,
            ..
        } = paths;
        lit.clear();
        lit.extend((0..hits.len as u32).filter(|&i| shaded.lit[i as usize] != 0.0));
        let to = [self.light_primitive; 4];
        for group in lit.chunks(4) {
            let hit = |lane: usize| group[lane.min(group.len() - 1)] as usize;
            let rays = [0, 1, 2, 3].map(|lane| Ray {
                origin: at3(&shaded.shadow_origin, hit(lane)),
                direction: at3(&shaded.shadow_direction, hit(lane)),
            });
            let t_max = [0, 1, 2, 3].map(|lane| shaded.shadow_end[hit(lane)]);
            // Neither the quad a shadow ray leaves nor the light can block it.
            let from = [0, 1, 2, 3].map(|lane| hits.primitive[hit(lane)]);
            let occluded = packets.occluded(avx2, &RayLanes::new(&rays), t_max, from, to);
            for (&i, occluded) in group.iter().zip(occluded) {
                if !occluded {
                    radiance[hits.slot[i as usize] as usize] += at3(&shaded.contribution, i as usize);
                }
            }
        }
    }
}

/// `buffer` as `n` copies of `value`, keeping its allocation.
#[inline(always)]
fn refill<T: Clone>(buffer: &mut Vec<T>, n: usize, value: T) {
    buffer.clear();
    buffer.resize(n, value);
}

thread_local! {
    static ROW_PATHS: std::cell::RefCell<RowPaths> = std::cell::RefCell::new(RowPaths::default());
}

impl RowPaths {
    /// Runs `body` with this thread's buffers (a rayon worker renders many
    /// rows; allocating them per row cost 2% of a render).
    pub(super) fn with<R>(body: impl FnOnce(&mut RowPaths) -> R) -> R {
        ROW_PATHS.with_borrow_mut(body)
    }

    /// The row's paths at their camera rays, all live.
    #[inline(always)]
    fn start(&mut self, columns: &[u32], start: impl Fn(u32) -> (Sampler, Ray)) {
        self.samplers.clear();
        self.rays.clear();
        self.active.clear();
        for (slot, &x) in columns.iter().enumerate() {
            let (sampler, ray) = start(x);
            self.samplers.push(sampler);
            self.rays.push(ray);
            self.active.push(slot as u32);
        }
        let n = columns.len();
        refill(&mut self.throughput, n, Color::ONE);
        refill(&mut self.radiance, n, Color::ZERO);
        refill(&mut self.previous_pdf, n, 0.0);
        refill(&mut self.previous_point, n, DVec3::ZERO);
        refill(&mut self.leaving, n, Leaving::Nothing);
    }

    /// Stage 4: each shaded path's throughput, next ray and Russian
    /// roulette, as the path tracer continues a path; the survivors are the
    /// next bounce's live paths.
    #[inline(always)]
    fn go_on(&mut self, bounce: u32) {
        let (hits, shaded) = (&self.hits, &self.shaded);
        self.active.clear();
        for i in 0..hits.len {
            if shaded.continues[i] == 0.0 {
                continue;
            }
            let s = hits.slot[i] as usize;
            let mut throughput = at3(&shaded.next_throughput, i);
            self.previous_pdf[s] = shaded.pdf[i];
            self.previous_point[s] = at3(&hits.point, i);
            self.rays[s] = Ray {
                origin: at3(&shaded.next_origin, i),
                direction: at3(&shaded.next_direction, i),
            };
            // Every primitive is a quad, which the next ray cannot hit again.
            self.leaving[s] = Leaving::Quad(hits.primitive[i]);
            let sampler = &mut self.samplers[s];
            if bounce + 1 < ROULETTE_START {
                sampler.skip();
            } else {
                let survival = survival_probability(throughput.max_element());
                if sampler.next_1d_independent() >= survival {
                    continue;
                }
                throughput /= survival;
            }
            self.throughput[s] = throughput;
            self.active.push(s as u32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::path::camera_ray;
    use crate::scene::{DEFAULT_SCENE, LoadedScene, load_scene_str};
    use std::path::Path;

    const MITSUBA_BOX: &str = include_str!("../../../benches/peers/cornell_box_mitsuba.toml");

    fn load(text: &str) -> LoadedScene {
        load_scene_str(text, Path::new("scene.toml"), Path::new(".")).expect("the scene loads")
    }

    /// Every pixel sample of the rows' kernel is the path tracer's bit for
    /// bit: at the full depth and at a depth that cuts paths short, over
    /// every column and over every third one (as adaptive sampling leaves
    /// them), across several sample indices.
    #[test]
    fn rows_give_the_path_tracers_samples_bit_for_bit() {
        let Some(avx2) = Avx2::detect() else {
            eprintln!("no AVX2 on this CPU: the kernel never runs here");
            return;
        };
        let loaded = load(MITSUBA_BOX);
        let (scene, camera) = (&loaded.scene, &loaded.camera);
        let size = (24, 18);
        let (mut compared, mut lit) = (0, 0);
        for max_depth in [7, 1] {
            let mut settings = loaded.settings.clone();
            settings.max_depth = max_depth;
            let tracer = PathTracer::from_settings(&settings);
            let kernel = DiffuseQuads::of(scene, &tracer).expect("Mitsuba's box is diffuse quads and one quad light");
            let mut paths = RowPaths::default();
            let mut values = Vec::new();
            for (sample, every) in [(0, 1), (1, 3), (5, 1)] {
                for y in 0..size.1 {
                    let columns: Vec<u32> = (0..size.0).step_by(every).collect();
                    let start = |x: u32| {
                        let mut sampler = Sampler::new(settings.sampler, (y * size.0 + x) as u64, sample, settings.seed);
                        let ray = camera_ray(camera, size, x, y, &mut sampler);
                        (sampler, ray)
                    };
                    kernel.radiance_of_row(avx2, scene, &columns, start, &mut paths, &mut values);
                    assert_eq!(values.len(), columns.len());
                    for (&x, &value) in columns.iter().zip(&values) {
                        let (mut sampler, ray) = start(x);
                        let expected = tracer.radiance(scene, ray, &mut sampler);
                        assert_eq!(value, expected, "pixel ({x}, {y}), sample {sample}, depth {max_depth}");
                        compared += 1;
                        lit += usize::from(value != Color::ZERO);
                    }
                }
            }
        }
        // Many samples carry light, so the equality says something.
        assert!(lit * 10 > compared * 4, "{lit} of {compared} samples lit");
    }

    /// The kernel takes only what it renders as the path tracer would.
    #[test]
    fn only_diffuse_quads_under_one_quad_light_take_the_kernel() {
        let tracer_of = |loaded: &LoadedScene| PathTracer::from_settings(&loaded.settings);
        let mitsuba = load(MITSUBA_BOX);
        assert!(DiffuseQuads::of(&mitsuba.scene, &tracer_of(&mitsuba)).is_some());
        // Without light sampling the tracer's estimator differs.
        let mut bsdf_only = tracer_of(&mitsuba);
        bsdf_only.light_sampling = false;
        assert!(DiffuseQuads::of(&mitsuba.scene, &bsdf_only).is_none());
        // A mirror wall, a background, a sphere (the default scene's balls).
        let mirror = MITSUBA_BOX.replace(
            "[materials.red]\ntype = \"diffuse\"\nalbedo",
            "[materials.red]\ntype = \"mirror\"\ntint",
        );
        let background = MITSUBA_BOX.replace("background = [0, 0, 0]", "background = [0.1, 0.1, 0.1]");
        for text in [mirror.as_str(), background.as_str(), DEFAULT_SCENE] {
            assert_ne!(text, MITSUBA_BOX);
            let loaded = load(text);
            assert!(DiffuseQuads::of(&loaded.scene, &tracer_of(&loaded)).is_none());
        }
    }
}
