//! The camera pass of SPPM: one path per pixel, followed through mirror and
//! glass bounces to the first non-specular surface, where it leaves a
//! *visible point* (Hachisuka & Jensen 2009, §3: the "hit point" x with its
//! BSDF, outgoing direction and path weight) for photons to be gathered at.
//!
//! Emission met along the specular chain is returned separately; light that
//! reaches the visible point after any diffuse or glossy reflection is left
//! entirely to the photons (the classic, consistent split).
//!
//! In spectral mode the path carries its own wavelengths and its emitted
//! term is a spectral estimate. The visible point's weight, which multiplies
//! photon flux gathered at other wavelengths, is kept in RGB: the product of
//! the chain's RGB weights, exact for clear glass and white mirrors; or,
//! once a dispersive interface has narrowed the path to its hero wavelength,
//! the film RGB of the hero's throughput (pbrt-v4's SPPM likewise multiplies
//! the two sides in sensor RGB).

use crate::color::Color;
use crate::integrator::bsdf_inputs::bsdf_inputs;
use crate::material::{ShadingPoint, Transport};
use crate::math::{DVec3, Frame as ShadingFrame, Ray};
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::{Emission, Radiance};

/// Where one pixel's camera path met its first non-specular surface.
#[derive(Clone, Copy, Debug)]
pub struct VisiblePoint {
    /// Position of the visible point, world space.
    pub point: DVec3,
    /// Geometric normal as the shape defines it (not flipped towards `wo`).
    pub geometric_normal: DVec3,
    /// Shading frame at the point (the shading normal is +z); `wo` and BSDF
    /// queries are in its coordinates.
    pub frame: ShadingFrame,
    /// Direction back along the camera path, in the local shading frame.
    pub wo: DVec3,
    /// Texture coordinates for the material's lookups.
    pub at: ShadingPoint,
    /// Index into `scene.materials`.
    pub material: u32,
    /// Product of the specular bounces' weights from the camera.
    pub throughput: Color,
    /// Distance travelled from the camera: how large a pixel looks here.
    pub path_length: f64,
}

impl VisiblePoint {
    /// Which side of the surface the camera path arrived from (+1 or −1,
    /// relative to the geometric normal).
    pub fn side(&self) -> f64 {
        let wo_world = self.frame.to_world(self.wo);
        wo_world.dot(self.geometric_normal).signum()
    }
}

/// What one camera path found.
#[derive(Clone, Copy, Debug, Default)]
pub struct CameraPath {
    /// Emission seen directly or through specular bounces (already weighted).
    pub emitted: Color,
    /// The first non-specular surface met, if the path reached one within
    /// `max_depth` bounces.
    pub visible_point: Option<VisiblePoint>,
}

/// Traces `ray` through up to `max_depth` specular bounces, carrying RGB
/// or the wavelengths `C` draws from `sampler`'s side stream.
pub fn trace_camera_path<C: Radiance>(scene: &Scene, ray: Ray, sampler: &mut Sampler, max_depth: u32) -> CameraPath {
    trace::<C, true>(scene, ray, sampler, max_depth)
}

/// The emission [`trace_camera_path`] would find along the same path (the
/// same draws, the same sums), without building the visible point at its
/// end: the extra emission-only paths of a pixel need no shading frame there.
pub fn trace_emission_path<C: Radiance>(scene: &Scene, ray: Ray, sampler: &mut Sampler, max_depth: u32) -> Color {
    trace::<C, false>(scene, ray, sampler, max_depth).emitted
}

/// Both of the above; `VISIBLE_POINT` says whether to record where the path
/// ends (a constant, so each caller gets its own loop without the other's work).
#[inline(always)]
fn trace<C: Radiance, const VISIBLE_POINT: bool>(
    scene: &Scene,
    mut ray: Ray,
    sampler: &mut Sampler,
    max_depth: u32,
) -> CameraPath {
    let mut wavelengths = C::sample_wavelengths(sampler);
    let mut visible_point = None;
    let mut emitted = C::ZERO;
    let mut throughput = C::ONE;
    let mut rgb_throughput = Color::ONE;
    let mut path_length = 0.0;
    for _ in 0..=max_depth {
        let Some(intersection) = scene.intersect(&ray, f64::INFINITY) else {
            emitted += throughput * C::from_rgb(scene.background, &wavelengths);
            break;
        };
        let hit = intersection.hit;
        path_length += hit.t;
        let material_index = scene.material_index(intersection.primitive);
        let material = &scene.materials[material_index as usize];
        let wo_world = -ray.direction;
        // Every vertex here ends a purely specular chain, so emission counts in full.
        let emission = material
            .emission_towards(hit.geometric_normal.dot(wo_world))
            .unwrap_or(Emission::NONE);
        emitted += throughput * C::emission(emission, &wavelengths);
        if !material.scatters() || (!VISIBLE_POINT && !material.is_specular()) {
            break;
        }
        let frame = ShadingFrame::from_normal(hit.shading_normal);
        let wo = frame.to_local(wo_world);
        let at = ShadingPoint {
            uv: hit.uv,
            point: hit.point,
        };
        if !material.is_specular() {
            let throughput = match C::is_dispersed(&wavelengths) {
                true => throughput.to_rgb(&wavelengths),
                false => rgb_throughput,
            };
            visible_point = Some(VisiblePoint {
                point: hit.point,
                geometric_normal: hit.geometric_normal,
                frame,
                wo,
                at,
                material: material_index,
                throughput,
                path_length,
            });
            break;
        }
        // Mirror or glass: follow the one sampled direction. Both draws keep
        // their dimensions, but only those the BSDF reads are computed.
        let (u, u_lobe) = bsdf_inputs(material, sampler);
        let Some(sample) = C::sample_bsdf(material, wo, &at, u, u_lobe, Transport::Radiance, &mut wavelengths) else {
            break;
        };
        throughput *= C::from_rgb(sample.weight, &wavelengths);
        rgb_throughput *= sample.weight;
        if throughput == C::ZERO {
            break;
        }
        ray = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, frame.to_world(sample.wi));
    }
    CameraPath {
        emitted: emitted.to_rgb(&wavelengths),
        visible_point,
    }
}
