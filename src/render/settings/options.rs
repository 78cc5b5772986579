//! The image options `raywave render` and `raywave bench` share, as plain values (the command
//! line's flags convert into them), and how whose defaults fill what no option sets.

use crate::render::sampling::LightSampler;
use crate::render::scene::{ParseOptions, RPI_RING_SEGMENTS};
use crate::render::settings::{LightModel, RenderSettings, ShadowMode};

/// Size, bounces, shadows, lighting and sampling: `None` where no flag gave a value (the
/// `Default`: no flag at all).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImageOptions {
    /// Image width and height.
    pub size: Option<[u32; 2]>,
    /// Mirror bounces.
    pub bounces: Option<u32>,
    /// Shadow mode.
    pub shadows: Option<ShadowMode>,
    /// Points per light with soft shadows.
    pub shadow_samples: Option<u32>,
    /// How the points on a light are chosen.
    pub sampler: LightSampler,
    /// Camera rays per pixel.
    pub aa: Option<u32>,
    /// Background colour for rays that hit nothing.
    pub background: Option<[f32; 3]>,
    /// Ambient light.
    pub ambient: Option<[f32; 3]>,
    /// How a light's colour reaches a point.
    pub light_model: Option<LightModel>,
    /// Quads around each RPI cylinder ring.
    pub ring_segments: Option<u32>,
    /// Whose defaults fill what no option sets.
    pub defaults: Option<Defaults>,
    /// Seed of every random number (`--seed`; 0 unless given).
    pub seed: u32,
    /// Whether faces are hit and lit from both sides (`--two-sided`).
    pub two_sided: bool,
}

/// Whose defaults fill the settings that no flag sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Defaults {
    /// raywave's own, the lab's third run line: 512×512, 5 bounces, soft shadows (16 points).
    Raywave,
    /// The lab's ArgParser: 100×100, 0 bounces, hard shadows, white background.
    Lab,
    /// RPI's 2023 ArgParser: 500×500, 0 bounces, no shadow test, ambient 0.1, RPI's light model.
    Rpi,
}

impl Defaults {
    /// The settings these defaults give (seed 0, one-sided faces); raywave's are
    /// `RenderSettings::default()`.
    ///
    /// The lab's and RPI's come from their ArgParsers' `DefaultValues`: `-size` 100 100 (the
    /// lab) and 500 500 (RPI 2023), `-num_bounces` 0, `-num_shadow_samples` 0,
    /// `-num_antialias_samples` 1, `-background_color` 1 1 1 (the lab), `ambient_light` 0.2
    /// grey (the lab) and 0.1 grey (RPI). A shadow-sample count of 0 means no count at all:
    /// the lab's finished program casts one shadow ray to each light's centroid unless
    /// `-soft_shadow` is given, and RPI's casts none; soft shadows without a count use
    /// raywave's 16 points.
    pub fn settings(self) -> RenderSettings {
        let raywave = RenderSettings::default();
        match self {
            Defaults::Raywave => raywave,
            Defaults::Lab => RenderSettings {
                width: 100,
                height: 100,
                bounces: 0,
                shadows: ShadowMode::Hard,
                ..raywave
            },
            Defaults::Rpi => RenderSettings {
                width: 500,
                height: 500,
                bounces: 0,
                shadows: ShadowMode::Off,
                ambient: [0.1; 3],
                light_model: LightModel::Rpi,
                ..raywave
            },
        }
    }

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Defaults::Raywave => "raywave",
            Defaults::Lab => "lab",
            Defaults::Rpi => "rpi",
        }
    }

    /// Whose defaults these are, for the summary.
    pub fn owner(self) -> &'static str {
        match self {
            Defaults::Raywave => "raywave's",
            Defaults::Lab => "the lab's ArgParser's",
            Defaults::Rpi => "RPI's 2023 ArgParser's",
        }
    }
}

/// Where the background colour came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackgroundSource {
    /// `--background` / `-background_color`.
    Flag,
    /// The scene file's `background_color`.
    Scene,
    /// The defaults.
    Defaults,
}

/// The settings a command line gives, and which of them came from the defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct Effective {
    /// The settings.
    pub settings: RenderSettings,
    /// Whose defaults filled the gaps.
    pub defaults: Defaults,
    /// The settings no flag set, as printed in the summary ("size", "bounces", ...).
    pub defaulted: Vec<&'static str>,
    /// Where the background came from.
    pub background: BackgroundSource,
}

impl ImageOptions {
    /// What the scene parser needs from these flags.
    pub fn parse_options(&self) -> ParseOptions {
        ParseOptions {
            ring_segments: self.ring_segments.unwrap_or(RPI_RING_SEGMENTS),
        }
    }

    /// Settings from these flags; `scene_background` is the file's
    /// `background_color`. What no flag sets comes from `--defaults`.
    pub fn resolve(&self, scene_background: Option<[f32; 3]>) -> Effective {
        let defaults = self.defaults.unwrap_or(Defaults::Raywave);
        let mut s = RenderSettings {
            sampler: self.sampler,
            seed: self.seed,
            two_sided: self.two_sided,
            ..defaults.settings()
        };
        let mut defaulted = Vec::new();
        // The given value, or the default (noting the setting's name).
        fn pick<T>(given: Option<T>, default: T, name: &'static str, out: &mut Vec<&str>) -> T {
            given.unwrap_or_else(|| {
                out.push(name);
                default
            })
        }
        [s.width, s.height] = pick(self.size, [s.width, s.height], "size", &mut defaulted);
        s.bounces = pick(self.bounces, s.bounces, "bounces", &mut defaulted);
        let implied = match self.shadow_samples {
            Some(n) if n > 1 => Some(ShadowMode::Soft),
            Some(_) => Some(ShadowMode::Hard),
            None => None,
        };
        s.shadows = pick(
            self.shadows.or(implied),
            s.shadows,
            "shadows",
            &mut defaulted,
        );
        match (self.shadow_samples, s.shadows) {
            (Some(n), _) => s.shadow_samples = n,
            // The lab's and RPI's count, 0, is no count: theirs is raywave's too.
            (None, ShadowMode::Soft) => defaulted.push(match defaults {
                Defaults::Raywave => "shadow samples",
                _ => "shadow samples (raywave's 16)",
            }),
            (None, _) => {}
        }
        s.aa_samples = pick(self.aa, s.aa_samples, "aa", &mut defaulted);
        s.ambient = pick(self.ambient, s.ambient, "ambient", &mut defaulted);
        s.light_model = pick(
            self.light_model,
            s.light_model,
            "light model",
            &mut defaulted,
        );
        let (background, source) = match (self.background, scene_background) {
            (Some(c), _) => (c, BackgroundSource::Flag),
            (None, Some(c)) => (c, BackgroundSource::Scene),
            (None, None) => {
                defaulted.push("background");
                (s.background, BackgroundSource::Defaults)
            }
        };
        s.background = background;
        Effective {
            settings: s,
            defaults,
            defaulted,
            background: source,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// No flag and raywave's defaults: `RenderSettings::default()`, every setting noted as
    /// defaulted.
    #[test]
    fn raywave_defaults_are_render_settings_default() {
        let e = ImageOptions::default().resolve(None);
        assert_eq!(e.settings, RenderSettings::default());
        assert_eq!(e.background, BackgroundSource::Defaults);
        assert_eq!(
            e.defaulted,
            [
                "size",
                "bounces",
                "shadows",
                "shadow samples",
                "aa",
                "ambient",
                "light model",
                "background"
            ]
        );
    }
}
