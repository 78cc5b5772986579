//! Render settings, with presets that say what they are for.

pub mod options;

use crate::render::sampling::{self, LightSampler, PointSet, SamplerLimit};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// How shadows are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "tools", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum ShadowMode {
    /// The lab's starting point: every light counts as visible (no shadow rays).
    Off,
    /// One shadow ray per light, to its centroid.
    Hard,
    /// `shadow_samples` shadow rays per light, to points chosen by `sampler`.
    Soft,
}

impl ShadowMode {
    /// The mode's name, as flags, records and summaries spell it ("off", "hard", "soft").
    pub fn name(self) -> &'static str {
        match self {
            ShadowMode::Off => "off",
            ShadowMode::Hard => "hard",
            ShadowMode::Soft => "soft",
        }
    }
}

/// How a light's colour reaches a shaded point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "tools", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum LightModel {
    /// The lab's: Lc = 0.2·ke·area, with no fall-off with distance.
    #[default]
    Lab,
    /// RPI's framework (`RayTracer::TraceRay`): Lc = ke·area / (π·d²), with no 0.2 factor, d
    /// the distance to the light point (docs/SHADING.md).
    Rpi,
}

impl LightModel {
    /// Every model, in declaration order.
    pub const ALL: [LightModel; 2] = [LightModel::Lab, LightModel::Rpi];

    /// The model's name, as flags, records and summaries spell it ("lab", "rpi").
    pub fn name(self) -> &'static str {
        match self {
            LightModel::Lab => "lab",
            LightModel::Rpi => "rpi",
        }
    }
}

/// Everything that decides the image, apart from the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "tools", derive(schemars::JsonSchema))]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Maximum number of mirror bounces after the camera hit.
    pub bounces: u32,
    /// Shadow mode.
    pub shadows: ShadowMode,
    /// Points per light in `Soft` mode (N).
    pub shadow_samples: u32,
    /// How those points are placed.
    pub sampler: LightSampler,
    /// Camera rays per pixel (1 = through the centre; more = jittered strata).
    pub aa_samples: u32,
    /// Colour of rays that hit nothing.
    pub background: [f32; 3],
    /// Seed of every random number.
    pub seed: u32,
    /// Let faces be hit from behind too (normals then face the ray).
    pub two_sided: bool,
    /// How light falls off with distance (records saved before it existed read as the lab's).
    #[serde(default)]
    pub light_model: LightModel,
    /// The ambient light: every hit gets ambient ⊙ kd (the lab fixes it at 0.2 grey; RPI's
    /// `-ambient_light r g b` sets it).
    #[serde(default = "lab_ambient")]
    pub ambient: [f32; 3],
}

/// The lab's fixed ambient light, 0.2 grey.
fn lab_ambient() -> [f32; 3] {
    [crate::render::shading::AMBIENT; 3]
}

impl Default for RenderSettings {
    /// The lab's third run line at 512×512: soft shadows (16 stratified points), 5 bounces.
    fn default() -> Self {
        RenderSettings {
            width: 512,
            height: 512,
            bounces: 5,
            shadows: ShadowMode::Soft,
            shadow_samples: 16,
            sampler: LightSampler::Stratified,
            aa_samples: 1,
            background: [1.0, 1.0, 1.0],
            seed: 0,
            two_sided: false,
            light_model: LightModel::Lab,
            ambient: lab_ambient(),
        }
    }
}

impl RenderSettings {
    /// Small and quick, for tests and a first look: 64×64, hard shadows, 2 bounces.
    pub fn preview() -> Self {
        RenderSettings {
            width: 64,
            height: 64,
            bounces: 2,
            shadows: ShadowMode::Hard,
            shadow_samples: 1,
            ..Self::default()
        }
    }

    /// The lab benchmark of docs/PERFORMANCE.md at `size`²: 5 bounces, soft shadows with 64
    /// stratified points per light (the benches' frame; at 1024² the headline figure).
    pub fn lab_benchmark(size: u32) -> Self {
        RenderSettings {
            width: size,
            height: size,
            bounces: 5,
            shadows: ShadowMode::Soft,
            shadow_samples: 64,
            sampler: LightSampler::Stratified,
            ..Self::default()
        }
    }

    /// The background as a vector.
    pub fn background(&self) -> Vec3 {
        Vec3::from_array(self.background)
    }

    /// Whether these settings ask their sampler for no more than it holds, and for at least one
    /// point (whatever the shadows: 0 points per light is never a setting). Only soft shadows
    /// sample points; hard shadows count as one point per light.
    pub fn check_sampler(&self) -> Result<(), SamplerLimit> {
        if self.shadow_samples == 0 {
            return Err(SamplerLimit::NoPoints(self.sampler));
        }
        let size = (self.width, self.height);
        sampling::check(self.sampler, self.points_per_light(), self.aa_samples, size)
    }

    /// The point set of a render with these settings.
    pub fn point_set(&self) -> PointSet {
        PointSet::with(
            self.sampler,
            self.points_per_light(),
            (self.width, self.height),
            self.aa_samples,
        )
    }

    /// Shadow rays (points) per light per shading point: 1 unless soft.
    pub fn points_per_light(&self) -> u32 {
        match self.shadows {
            ShadowMode::Soft => self.shadow_samples.max(1),
            _ => 1,
        }
    }
}

#[cfg(all(test, feature = "tools"))]
mod tests {
    use super::{LightModel, ShadowMode};

    /// The names are the serialised spellings, so records and summaries say the same word.
    #[test]
    fn names_are_the_serialised_spellings() {
        for m in [ShadowMode::Off, ShadowMode::Hard, ShadowMode::Soft] {
            assert_eq!(serde_json::to_value(m).unwrap(), m.name());
        }
        for m in LightModel::ALL {
            assert_eq!(serde_json::to_value(m).unwrap(), m.name());
        }
    }
}
