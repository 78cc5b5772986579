//! The command line's spellings of the library's choices, and its number parsers.
//!
//! Each enum mirrors one of the library's, variant for variant and with the same docs (clap
//! prints them as the possible values), so that the library's types need no clap; `From` maps
//! each to its twin, and a variant added to the library fails to compile here until it has a
//! spelling. Integers use clap's own ranged parsers (`value_parser!(u32).range(..)`); clap has
//! none for floats, so [`float`] is clap's string parser mapped through a check.

use clap::builder::{StringValueParser, TypedValueParser};
use raywave::bench::verdict::VerdictForm;
use raywave::diff::Metric;
use raywave::output::cost_map::{CostKind, CostMeasure};
use raywave::render::engine::Engine;
use raywave::render::film::ToneMap;
use raywave::render::sampling::LightSampler;
use raywave::render::settings::options::Defaults;
use raywave::render::settings::{LightModel, ShadowMode};
use raywave::render::wavefront::lanes::LaneWidth;

/// The float types of flags.
pub trait Float: std::str::FromStr + Copy + Into<f64> + Send + Sync + 'static {
    /// The type's name and its largest finite value, for messages.
    const RANGE: &'static str;
    /// Not an infinity nor NaN.
    fn finite(self) -> bool {
        self.into().is_finite()
    }
}

impl Float for f32 {
    const RANGE: &'static str = "the largest f32, 3.4e38";
}

impl Float for f64 {
    const RANGE: &'static str = "the largest f64, 1.8e308";
}

/// A float that `ok` accepts, refused otherwise with "expected {what}, found `text`" (clap
/// names the flag), and for a finite number too large for the type (`1e39` as an f32, which
/// Rust's parser rounds to an infinity) with the magnitude it is past.
pub fn float<T: Float>(what: &'static str, ok: fn(T) -> bool) -> impl TypedValueParser<Value = T> {
    StringValueParser::new().try_map(move |text| match text.parse::<T>() {
        Ok(x) if ok(x) => Ok(x),
        Ok(x) if !x.finite() && raywave::render::scene::beyond_range(&text) => Err(format!(
            "expected {what}, found `{text}`, of magnitude past {}",
            T::RANGE
        )),
        _ => Err(format!("expected {what}, found `{text}`")),
    })
}

/// A positive duration in humantime's spelling (`10m`, `90s`, `1h 30m`), refused otherwise
/// with what was expected (clap names the flag).
pub fn duration(text: &str) -> Result<std::time::Duration, String> {
    match humantime::parse_duration(text) {
        Ok(d) if !d.is_zero() => Ok(d),
        Ok(_) => Err(format!("expected a positive duration, found `{text}`")),
        Err(e) => Err(format!(
            "expected a duration such as 10m, 90s or 1h30m, found `{text}` ({e})"
        )),
    }
}

/// A colour component of `--background` and `--ambient`: finite and not negative.
pub fn colour_component() -> impl TypedValueParser<Value = f32> {
    float("a finite non-negative colour component", |x: f32| {
        x.is_finite() && x >= 0.0
    })
}

/// A value enum's spelling on the command line.
pub fn spelling(v: impl clap::ValueEnum) -> String {
    v.to_possible_value()
        .expect("no skipped variants")
        .get_name()
        .to_string()
}

/// Declares clap value enums, each with its conversion into the library's enum of the same
/// variants.
macro_rules! mirror {
    ($(
        $(#[$doc:meta])* $name:ident => $lib:ident { $($(#[$vdoc:meta])* $variant:ident,)+ }
    )+) => {$(
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
        pub enum $name {
            $($(#[$vdoc])* $variant,)+
        }

        impl From<$name> for $lib {
            fn from(value: $name) -> $lib {
                match value {
                    $($name::$variant => $lib::$variant,)+
                }
            }
        }
    )+};
}

mirror! {
    /// The renderers.
    EngineArg => Engine {
        /// Structure-of-arrays batches through 8-wide SIMD stages (the default).
        Wavefront,
        /// The scalar recursive renderer, one ray at a time: the whole-image twin.
        Reference,
    }

    /// Which verdicts `bench --against` can reach.
    VerdictArg => VerdictForm {
        /// One-sided, a pull request's gate: slower by more than --threshold (a regression,
        /// exit 3), or not slower by more than it (exit 0).
        Regression,
        /// Slower by more than --threshold (exit 3), faster by more than it, or no change
        /// beyond it (exit 0).
        ThreeWay,
    }

    /// How many lanes the wavefront engine's brute-force, light and shading kernels run
    /// (speed only: every width gives the same image; the mesh BVH is 8-wide either way).
    LanesArg => LaneWidth {
        /// 16 on a build for AVX-512 (one 512-bit register), else 8.
        Auto,
        /// f32x8.
        #[value(name = "8")]
        Eight,
        /// f32x16 (two 256-bit halves without AVX-512).
        #[value(name = "16")]
        Sixteen,
    }

    /// `--metric` of `raywave diff`.
    MetricArg => Metric {
        /// Mean squared error.
        Mse,
        /// Relative MSE: mean (a−b)²/(b+0.01)² (pbrt-v4's MRSE).
        Relmse,
        /// Largest |a − b|.
        Max,
        /// PSNR in dB against a peak of 1 (--fail-above fails when it is BELOW the value).
        Psnr,
        /// FLIP's mean (needs the `flip` feature).
        Flip,
    }

    /// Which rays a cost map counts.
    CostKindArg => CostKind {
        /// Camera rays' closest hits.
        Camera,
        /// Shadow rays' occlusion tests.
        Shadow,
        /// Mirror rays' closest hits.
        Reflection,
        /// Every ray.
        All,
    }

    /// What a cost map shows.
    CostMeasureArg => CostMeasure {
        /// BVH nodes visited (each an 8-wide test of child boxes).
        Nodes,
        /// Primitives tested (triangles of the leaves visited, spheres, brute force's every one).
        Tests,
        /// Both figures, side by side.
        Both,
    }

    /// How linear values become 8-bit pixels.
    ToneMapArg => ToneMap {
        /// The lab's look: clamp to [0, 1], no gamma.
        Clamp,
        /// The lab's key 'h': 1 − exp(−3x).
        Exp,
    }

    /// How shadows are computed.
    ShadowArg => ShadowMode {
        /// The lab's starting point: every light counts as visible (no shadow rays).
        Off,
        /// One shadow ray per light, to its centroid.
        Hard,
        /// `shadow_samples` shadow rays per light, to points chosen by `sampler`.
        Soft,
    }

    /// How a light's colour reaches a shaded point.
    LightModelArg => LightModel {
        /// The lab's: Lc = 0.2·ke·area, with no fall-off with distance.
        Lab,
        /// RPI's framework (`RayTracer::TraceRay`): Lc = ke·area / (π·d²), with no 0.2 factor, d
        /// the distance to the light point (docs/SHADING.md).
        Rpi,
    }

    /// How points are chosen on an area light.
    SamplerArg => LightSampler {
        /// N independent uniform points on the light.
        Random,
        /// Jittered: the light's (u, v) square split into N strata (nx × ny, see `strata_grid`),
        /// one uniform point in each.
        Stratified,
        /// Owen-scrambled Sobol points (Burley 2020), scrambled independently for every
        /// (pixel, sample, bounce, light): low discrepancy for any N, best at powers of two.
        Sobol,
        /// The lab's own strategy: the centre of the light's (u, v) square (its centroid, for a
        /// parallelogram) when N = 1, independent random points otherwise.
        Lab,
        /// Halton points (bases 2 and 3), Owen-scrambled for every (pixel, sample, bounce,
        /// light).
        Halton,
        /// Progressive multi-jittered (0,2) points (Christensen et al. 2018): 1 to 4096 points.
        Pmj02,
        /// Sobol points in the pixels' Morton order (Ahmed and Wonka 2020, pbrt-v4's
        /// ZSobolSampler): the error as blue noise in screen space.
        Zsobol,
        /// Heitz et al.'s 2019 blue-noise tables: aa samples × points ≤ 256.
        Bluenoise,
    }

    /// Whose defaults fill the settings that no flag sets.
    DefaultsArg => Defaults {
        /// raywave's own, the lab's third run line: 512×512, 5 bounces, soft shadows (16 points).
        Raywave,
        /// The lab's ArgParser: 100×100, 0 bounces, hard shadows, white background.
        Lab,
        /// RPI's 2023 ArgParser: 500×500, 0 bounces, no shadow test, ambient 0.1, RPI's light model.
        Rpi,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ValueEnum;

    #[test]
    fn sampler_spellings_list_every_sampler_in_the_library_order() {
        let ours: Vec<LightSampler> = SamplerArg::value_variants()
            .iter()
            .map(|&s| s.into())
            .collect();
        assert_eq!(ours, LightSampler::ALL);
    }
}
