use super::*;
use crate::spectrum::cie::GRID_POINTS;

/// Every RGB triple given as a material's `albedo`, `tint` or `radiance` in
/// the shipped scenes (textures are skipped), with where it came from.
fn shipped_scene_colours() -> Vec<(String, Color)> {
    let mut colours = Vec::new();
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut files: Vec<_> = std::fs::read_dir(&scenes)
        .map(|dir| dir.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    files.retain(|p| p.extension().is_some_and(|e| e == "toml"));
    files.sort();
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap_or_default();
        let Ok(document) = text.parse::<toml::Table>() else { continue };
        let Some(materials) = document.get("materials").and_then(|m| m.as_table()) else {
            continue;
        };
        for (name, material) in materials {
            for key in ["albedo", "tint", "radiance"] {
                let Some(values) = material.get(key).and_then(|v| v.as_array()) else {
                    continue;
                };
                let numbers: Vec<f64> = values
                    .iter()
                    .filter_map(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
                    .collect();
                if let [r, g, b] = numbers[..] {
                    let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
                    colours.push((format!("{stem}.{name}.{key}"), Color::new(r, g, b)));
                }
            }
        }
    }
    colours
}

/// Largest channel error of the round trip, relative to the largest channel.
fn round_trip_error(rgb: Color, tables: &[[f64; GRID_POINTS]; 6]) -> f64 {
    let back = Sensor::get().rgb_of_table(&spectrum_table_of_rgb(rgb, tables));
    (back - rgb).abs().max_element() / rgb.max_element().max(1e-300)
}

#[test]
fn shipped_scene_colours_round_trip() {
    // The corrected basis round-trips exactly by construction (module doc);
    // what is left is f64 rounding in the grid integrals and the 3 × 3
    // solve, far below 1e-9. Smits' own table is printed for comparison: its
    // residual is what the correction removes.
    let colours = shipped_scene_colours();
    assert!(colours.len() >= 20, "found only {} colours in scenes/", colours.len());
    let smits: [[f64; GRID_POINTS]; 6] = std::array::from_fn(smits_on_grid);
    let corrected = &Basis::get().tables;
    let (mut worst_smits, mut worst_corrected) = (0.0f64, 0.0f64);
    for (name, rgb) in &colours {
        let (before, after) = (round_trip_error(*rgb, &smits), round_trip_error(*rgb, corrected));
        println!(
            "{name:40} {rgb:>24}  Smits' table {:7.4}%   corrected {after:.1e}",
            100.0 * before
        );
        worst_smits = worst_smits.max(before);
        worst_corrected = worst_corrected.max(after);
    }
    println!(
        "worst over {} colours: Smits' table {:.4}%, corrected {worst_corrected:.1e}",
        colours.len(),
        100.0 * worst_smits
    );
    assert!(worst_corrected < 1e-9, "{worst_corrected}");
}

#[test]
fn the_corrected_basis_stays_a_reflectance() {
    // The correction adds a small multiple of x̄, ȳ, z̄; it must leave each
    // basis spectrum within [0, 1] up to a small excursion, or an albedo of
    // 1 would reflect more than it receives at some wavelength. Smits' own
    // table reaches 1.0149 (his red); we allow 3% either side.
    for (k, table) in Basis::get().tables.iter().enumerate() {
        let (low, high) = table.iter().fold((f64::MAX, f64::MIN), |(l, h), &v| (l.min(v), h.max(v)));
        println!("basis {k}: [{low:.4}, {high:.4}]");
        assert!(low > -0.03 && high < 1.03, "basis {k}: [{low}, {high}]");
    }
}

#[test]
fn white_and_greys_are_constant_and_sampled_lanes_match_the_table() {
    let w = SampledWavelengths::sample_uniform(0.37);
    assert_eq!(spectrum_of_rgb(Color::splat(0.73), &w), SampledSpectrum::splat(0.73));
    // Scaling the RGB scales the spectrum: the property the path tracer's
    // uplift of BSDF values relies on.
    let red = Color::new(0.65, 0.05, 0.05);
    let a = spectrum_of_rgb(red, &w) * 0.25;
    let b = spectrum_of_rgb(red * 0.25, &w);
    assert!((a - b).abs().max_element() < 1e-15);
    // At a grid wavelength, the sampled value is the table's.
    let at_grid = SampledWavelengths::fixed(600.0);
    let table = spectrum_table_of_rgb(red, &Basis::get().tables);
    assert!((spectrum_of_rgb(red, &at_grid).x - table[48]).abs() < 1e-12);
}
