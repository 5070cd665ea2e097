//! A hash of what a scene *is*, for telling parts of one image from parts of
//! another: every primitive with its material, every mesh's vertex data,
//! every material with its textures' texels, the background and the camera.
//! It is taken from the built scene, so a change of comments or layout in
//! the scene file does not change it, and neither does the folder the file
//! was loaded from (an image texture is hashed by its texels, not its path);
//! a changed mesh or texture file does.
//!
//! Values are hashed through their `Debug` forms (Rust prints every f64 so
//! that it reads back to the same bits) and raw bits for the bulk data,
//! into 64-bit FNV-1a (Fowler, Noll and Vo): a fixed, documented function, so
//! machines with different Rust versions agree, unlike `std`'s hasher. It
//! guards against accidents, not adversaries.

use crate::camera::Camera;
use crate::light::EmitterSource;
use crate::material::{Material, Texture};
use crate::scene::Scene;
use std::fmt::Write;

/// 64-bit FNV-1a.
struct Fnv1a(u64);

impl Fnv1a {
    const OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;

    fn bytes(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.0 = (self.0 ^ byte as u64).wrapping_mul(Self::PRIME);
        }
    }

    fn floats(&mut self, values: impl IntoIterator<Item = f64>) {
        for value in values {
            self.bytes(&value.to_bits().to_le_bytes());
        }
    }

    /// Hashes `value`'s `Debug` form, streamed (never held as one string).
    fn debug(&mut self, value: &impl std::fmt::Debug) {
        // Writing into the hasher cannot fail.
        let _ = write!(self, "{value:?};");
    }
}

impl Write for Fnv1a {
    fn write_str(&mut self, text: &str) -> std::fmt::Result {
        self.bytes(text.as_bytes());
        Ok(())
    }
}

/// The hash of `scene` seen through `camera`, as `fnv1a64:` and 16 hex digits.
pub fn scene_hash(scene: &Scene, camera: &Camera) -> String {
    let mut hash = Fnv1a(Fnv1a::OFFSET_BASIS);
    hash.debug(camera);
    hash.debug(&scene.background);
    for mesh in &scene.meshes {
        hash.bytes(b"mesh");
        hash.floats(mesh.positions.iter().flat_map(|p| p.to_array()));
        hash.floats(mesh.normals.iter().flat_map(|n| n.to_array()));
        hash.floats(mesh.uvs.iter().flat_map(|uv| uv.to_array()));
        for face in &mesh.faces {
            for index in face {
                hash.bytes(&index.to_le_bytes());
            }
        }
    }
    for primitive in 0..scene.primitive_count() as u32 {
        match scene.triangle_source(primitive) {
            // A triangle is a face of a mesh hashed above (the scene keeps
            // mesh positions in the form its triangles are stored in):
            // which face, and its material, say all.
            Some(source) => {
                for number in [source.mesh, source.face, source.material] {
                    hash.bytes(&number.to_le_bytes());
                }
            }
            None => {
                hash.debug(&scene.emitter(primitive));
                hash.bytes(&scene.material_index(primitive).to_le_bytes());
            }
        }
    }
    for material in &scene.materials {
        hash_material(&mut hash, material);
    }
    format!("fnv1a64:{:016x}", hash.0)
}

/// A material's parameters, with image textures by their texels.
fn hash_material(hash: &mut Fnv1a, material: &Material) {
    let texture = match material {
        Material::Diffuse { albedo } => Some(albedo),
        Material::Mirror { tint } | Material::Glossy { tint, .. } => Some(tint),
        Material::Glass { .. } | Material::Emissive { .. } => None,
    };
    match texture {
        Some(Texture::Image { image, mapping, wrap }) => {
            // The variant and its scalar parameters, then the texture's content.
            if let Material::Glossy { roughness, .. } = material {
                hash.debug(roughness);
            }
            hash.debug(&std::mem::discriminant(material));
            hash.debug(mapping);
            hash.debug(wrap);
            hash.bytes(&(image.width() as u64).to_le_bytes());
            hash.bytes(&(image.height() as u64).to_le_bytes());
            for y in 0..image.height() {
                for x in 0..image.width() {
                    hash.floats(image.texel(x, y).to_array());
                }
            }
        }
        // A glass without dispersion, and an RGB light, hash as they did
        // before glasses could disperse and lights have spectra, so films
        // rendered earlier still merge.
        _ => match material {
            Material::Glass {
                ior,
                tint,
                dispersion: None,
            } => hash.debug(&format_args!("Glass {{ ior: {ior:?}, tint: {tint:?} }}")),
            Material::Emissive {
                radiance,
                two_sided,
                spectrum: None,
            } => hash.debug(&format_args!(
                "Emissive {{ radiance: {radiance:?}, two_sided: {two_sided:?} }}"
            )),
            _ => hash.debug(material),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Color;
    use crate::scene::{DEFAULT_SCENE, load_scene_str};
    use std::path::Path;

    #[test]
    fn fnv1a_matches_its_published_test_vectors() {
        // From the FNV reference test suite: "" and "a" and "foobar".
        for (text, expected) in [
            ("", 0xcbf2_9ce4_8422_2325),
            ("a", 0xaf63_dc4c_8601_ec8c),
            ("foobar", 0x8594_4171_f739_67e8),
        ] {
            let mut hash = Fnv1a(Fnv1a::OFFSET_BASIS);
            hash.bytes(text.as_bytes());
            assert_eq!(hash.0, expected, "{text:?}");
        }
    }

    /// The same text gives the same hash wherever it is loaded from; a
    /// moved light, a changed colour or camera gives another.
    #[test]
    fn the_hash_follows_the_content_not_the_file() {
        let load = |text: &str, base: &str| {
            let loaded = load_scene_str(text, Path::new("a.toml"), Path::new(base)).expect("scene loads");
            scene_hash(&loaded.scene, &loaded.camera)
        };
        let original = load(DEFAULT_SCENE, ".");
        assert_eq!(original, load(DEFAULT_SCENE, "/elsewhere"));
        assert_eq!(original, load(&format!("# a comment\n{DEFAULT_SCENE}"), "."));
        assert!(original.starts_with("fnv1a64:") && original.len() == 8 + 16);
        // A colour, the light's radiance and the camera: each changes the hash,
        // and each to another value (no two edits collide).
        let edits = [
            ("albedo = [0.65, 0.05, 0.05]", "albedo = [0.65, 0.05, 0.06]"),
            ("radiance = [17, 12, 4]", "radiance = [17, 12, 4.5]"),
            ("position = [278, 273, -800]", "position = [278, 273, -801]"),
            ("[render]\nwidth = 512", "[render]\nwidth = 256"),
        ];
        let hashes: Vec<String> = edits
            .iter()
            .map(|(from, to)| {
                assert!(DEFAULT_SCENE.contains(from), "{from} is not in the scene");
                load(&DEFAULT_SCENE.replacen(from, to, 1), ".")
            })
            .collect();
        for (hash, (from, _)) in hashes[..3].iter().zip(&edits) {
            assert_ne!(*hash, original, "{from}");
        }
        assert!(hashes[0] != hashes[1] && hashes[1] != hashes[2]);
        // The [render] table is not the scene: settings are compared apart.
        assert_eq!(hashes[3], original);
    }

    /// An RGB light hashes as the material did before lights could have a
    /// spectrum (a derived `Debug` of the old variant), so films rendered
    /// then still merge; a spectral light hashes by its spectrum.
    #[test]
    fn rgb_lights_hash_as_before_and_spectra_count() {
        // Read only through `Debug`, which is the point.
        #[allow(dead_code)]
        #[derive(Debug)]
        enum Before {
            Emissive { radiance: Color, two_sided: bool },
        }
        let hash_of = |material: &Material| {
            let mut hash = Fnv1a(Fnv1a::OFFSET_BASIS);
            hash_material(&mut hash, material);
            hash.0
        };
        let radiance = Color::new(17.0, 12.0, 4.0);
        let mut before = Fnv1a(Fnv1a::OFFSET_BASIS);
        before.debug(&Before::Emissive {
            radiance,
            two_sided: true,
        });
        let rgb = Material::Emissive {
            radiance,
            two_sided: true,
            spectrum: None,
        };
        assert_eq!(hash_of(&rgb), before.0);
        let spectral = |source, luminance| {
            let spectrum = crate::spectrum::EmissionSpectrum::new(source, luminance);
            hash_of(&Material::Emissive {
                radiance: spectrum.rgb(),
                two_sided: true,
                spectrum: Some(std::sync::Arc::new(spectrum)),
            })
        };
        use crate::spectrum::{SpectrumSource, StandardIlluminant};
        let d65 = spectral(SpectrumSource::Illuminant(StandardIlluminant::D65), 5.0);
        assert_ne!(d65, spectral(SpectrumSource::Illuminant(StandardIlluminant::A), 5.0));
        assert_ne!(d65, spectral(SpectrumSource::Illuminant(StandardIlluminant::D65), 6.0));
        assert_ne!(d65, hash_of(&rgb));
    }
}
