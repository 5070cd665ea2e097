//! Numeric controls that never change a value silently. A slider's drag
//! range is only the convenient part of a parameter's range: a value typed
//! into its number field (or read from the scene file) may lie beyond it and
//! is kept as it is, up to the limits the scene format and the CLI accept. A
//! typed value outside those limits is refused, the old value stays, and the
//! reason is shown.

use crate::settings::RenderSettings;
use crate::settings::validate::{self, SettingError, SettingsPatch};
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

/// The render settings' own validation (`settings::validate`, the one the
/// scene file's `[render]` table and `prism render` go through): `patch`
/// turns the typed value into the field it sets.
pub fn setting<T>(patch: impl Fn(T) -> SettingsPatch) -> impl Fn(T) -> Result<(), String> {
    move |value| {
        patch(value)
            .apply_to(&mut RenderSettings::default())
            .map_err(|error| describe(&error))
    }
}

/// A render-time limit, checked as `--time` is.
pub fn time_limit(seconds: f64) -> Result<(), String> {
    validate::time_limit(seconds).map(|_| ()).map_err(|error| describe(&error))
}

/// An exposure, checked as `--exposure` is.
pub fn exposure(stops: f64) -> Result<(), String> {
    validate::exposure(stops).map(|_| ()).map_err(|error| describe(&error))
}

/// A setting's error as the scene file names it (`max_depth: must be …`), or
/// as the command line does for settings only it has.
fn describe(error: &SettingError) -> String {
    format!("{}: {}", error.setting.key().unwrap_or(error.setting.flag()), error.message)
}

/// A positive finite number (a focal distance).
pub fn positive(field: &'static str) -> impl Fn(f64) -> Result<(), String> {
    move |v| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(format!("{field} must be a positive finite number (found {v})"))
        }
    }
}

/// A finite number that is not negative (an aperture radius).
pub fn not_negative(field: &'static str) -> impl Fn(f64) -> Result<(), String> {
    move |v| {
        if v.is_finite() && v >= 0.0 {
            Ok(())
        } else {
            Err(format!("{field} must be a finite number of at least 0 (found {v})"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn valid_values_are_taken_and_invalid_ones_refused() {
        let depth_check = || {
            setting(|depth| SettingsPatch {
                max_depth: Some(depth),
                ..Default::default()
            })
        };
        let mut depth = 64u32;
        assert_eq!(accept(&mut depth, 1000, depth_check()), None);
        assert_eq!(depth, 1000, "beyond the slider, within the format's limit: kept");
        let refusal = accept(&mut depth, 0, depth_check());
        assert!(refusal.is_some_and(|r| r.starts_with("max_depth: must be at least 1")));
        assert_eq!(depth, 1000, "the old value stays");
        assert!(accept(&mut depth, 5000, depth_check()).is_some_and(|r| r.contains("at most")));
        let radius_check = || {
            setting(|radius| SettingsPatch {
                initial_radius: Some(radius),
                ..Default::default()
            })
        };
        let mut radius = 0.5;
        assert!(accept(&mut radius, -5.0, radius_check()).is_some_and(|r| r.starts_with("initial_radius")));
        assert_eq!(radius, 0.5);
        assert!(
            accept(
                &mut 0.5,
                1.0,
                setting(|alpha| SettingsPatch {
                    alpha: Some(alpha),
                    ..Default::default()
                })
            )
            .is_some()
        );
        assert!(accept(&mut 60.0, -1.0, time_limit).is_some());
    }
}
