//! Numeric controls that never change a value silently. A slider's drag
//! range is only the convenient part of a parameter's range: a value typed
//! into its number field (or read from the scene file) may lie beyond it and
//! is kept as it is, up to the limits the scene format and the CLI accept. A
//! typed value outside those limits is refused, the old value stays, and the
//! reason is shown.

use egui::emath::Numeric;
use egui::{DragValue, Response, Slider, SliderClamping, Ui};
use std::ops::RangeInclusive;

/// A slider over `drag_range` whose value may be typed beyond it; `check`
/// says whether a value is valid (and why not). Returns the response and the
/// refusal, if the user entered an invalid value this frame.
pub fn slider<T: Numeric>(
    ui: &mut Ui,
    value: &mut T,
    drag_range: RangeInclusive<T>,
    label: &str,
    logarithmic: bool,
    check: impl Fn(T) -> Result<(), String>,
) -> (Response, Option<String>) {
    let mut edited = *value;
    let response = ui.add(
        Slider::new(&mut edited, drag_range)
            .clamping(SliderClamping::Never)
            .logarithmic(logarithmic)
            .text(label),
    );
    (response, accept(value, edited, check))
}

/// A number field (no slider) with the same rule.
pub fn number<T: Numeric>(
    ui: &mut Ui,
    value: &mut T,
    speed: f64,
    suffix: &str,
    enabled: bool,
    check: impl Fn(T) -> Result<(), String>,
) -> (Response, Option<String>) {
    let mut edited = *value;
    let response = ui.add_enabled(enabled, DragValue::new(&mut edited).speed(speed).suffix(suffix));
    (response, accept(value, edited, check))
}

fn accept<T: Numeric>(value: &mut T, edited: T, check: impl Fn(T) -> Result<(), String>) -> Option<String> {
    if edited == *value {
        return None;
    }
    match check(edited) {
        Ok(()) => {
            *value = edited;
            None
        }
        Err(reason) => Some(reason),
    }
}

/// A whole number of at least 1 (the scene format's `spp`, `max_depth`, `photons_per_iteration`).
pub fn at_least_one(field: &'static str) -> impl Fn(u32) -> Result<(), String> {
    move |v| {
        if v >= 1 {
            Ok(())
        } else {
            Err(format!("{field} must be at least 1"))
        }
    }
}

/// A positive finite number (the scene format's `initial_radius`, `--time`).
pub fn positive(field: &'static str) -> impl Fn(f64) -> Result<(), String> {
    move |v| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(format!("{field} must be a positive finite number (got {v})"))
        }
    }
}

/// A finite number that is not negative (an aperture radius).
pub fn not_negative(field: &'static str) -> impl Fn(f64) -> Result<(), String> {
    move |v| {
        if v.is_finite() && v >= 0.0 {
            Ok(())
        } else {
            Err(format!("{field} must be a finite number of at least 0 (got {v})"))
        }
    }
}

/// Strictly between 0 and 1 (SPPM's alpha, as `--alpha` checks it).
pub fn open_unit_interval(field: &'static str) -> impl Fn(f64) -> Result<(), String> {
    move |v| {
        if v > 0.0 && v < 1.0 {
            Ok(())
        } else {
            Err(format!("{field} must be strictly between 0 and 1 (got {v})"))
        }
    }
}

/// Any finite number (the exposure in stops).
pub fn finite(field: &'static str) -> impl Fn(f64) -> Result<(), String> {
    move |v| {
        if v.is_finite() {
            Ok(())
        } else {
            Err(format!("{field} must be a finite number"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn valid_values_are_taken_and_invalid_ones_refused() {
        let mut depth = 64u32;
        assert_eq!(accept(&mut depth, 2_147_483_647, at_least_one("max depth")), None);
        assert_eq!(depth, 2_147_483_647, "beyond the slider, within the format's limit: kept");
        let refusal = accept(&mut depth, 0, at_least_one("max depth"));
        assert!(refusal.is_some_and(|r| r.contains("at least 1")));
        assert_eq!(depth, 2_147_483_647, "the old value stays");
        let mut radius = 0.5;
        assert!(accept(&mut radius, -5.0, positive("initial radius")).is_some());
        assert_eq!(radius, 0.5);
        assert!(accept(&mut radius, 1.0, open_unit_interval("alpha")).is_some());
    }
}
