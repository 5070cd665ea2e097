//! A perfect mirror: reflects everything about the normal, tinted.

use super::{BsdfSample, reflect};
use crate::color::Color;
use glam::DVec3;

/// The mirror direction with weight `tint` and discrete probability 1;
/// `None` for grazing `wo`.
pub fn sample(tint: Color, wo: DVec3) -> Option<BsdfSample> {
    (wo.z != 0.0).then(|| BsdfSample {
        wi: reflect(wo),
        weight: tint,
        pdf: 1.0,
        eta: 1.0,
        specular: true,
    })
}
