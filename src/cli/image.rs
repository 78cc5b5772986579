//! The flags several commands share (the image's, the seed's, the threads'), and [`say`].

use super::values::{
    DefaultsArg, LightModelArg, SamplerArg, ShadowArg, colour_component, spelling,
};
use clap::Args;
use raywave::output::OutputPlan;
use raywave::render::settings::options::ImageOptions;

/// The flags that shape the image: shared so that every command defaults alike (a bench record
/// measures what the same flags render), with or without a scene file.
#[derive(Args, Debug, Clone)]
pub struct ImageArgs {
    /// Image size in pixels [default: 512 512; the lab's 100 100; RPI's 500 500].
    #[arg(long, num_args = 2, value_names = ["W", "H"], value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub size: Option<Vec<u32>>,
    /// Maximum mirror bounces [default: 5; the lab's and RPI's 0].
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=64))]
    pub bounces: Option<u32>,
    /// Shadows: off (every light visible), hard (centroid), soft (N points per light).
    /// Without it: soft when --shadow-samples > 1, hard when it is 1, else the defaults'
    /// [soft; the lab's hard; RPI's off].
    #[arg(long, value_enum)]
    pub shadows: Option<ShadowArg>,
    /// Points per light with soft shadows [default: 16]; each sampler's limits are checked
    /// with the rest of the settings, so that the error can name the sampler.
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=65536))]
    pub shadow_samples: Option<u32>,
    /// How the points on a light are chosen.
    #[arg(long, value_enum, default_value = "stratified")]
    pub sampler: SamplerArg,
    /// Camera rays per pixel (1 = pixel centre, more = jittered strata) [default: 1].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub aa: Option<u32>,
    /// Background colour for rays that hit nothing [default: the scene's, else white].
    #[arg(long, num_args = 3, value_names = ["R", "G", "B"], value_parser = colour_component())]
    pub background: Option<Vec<f32>>,
    /// Ambient light: every hit gets ambient ⊙ kd [default: 0.2 grey; RPI's 0.1].
    #[arg(long, num_args = 3, value_names = ["R", "G", "B"], value_parser = colour_component())]
    pub ambient: Option<Vec<f32>>,
    /// How a light's colour reaches a point: lab (no fall-off) or rpi (divided by π·d², as
    /// RPI's framework does) [default: lab; RPI's rpi].
    #[arg(long, value_enum)]
    pub light_model: Option<LightModelArg>,
    /// Quads around each RPI cylinder ring (`r` line) of the scene [default: 20, RPI's].
    #[arg(long, value_parser = clap::value_parser!(u32).range(3..=65536))]
    pub ring_segments: Option<u32>,
    /// Whose defaults fill what no flag sets [default: raywave; lab when the lab's
    /// single-dash flags are used, rpi with RPI 2023's double-dash ones].
    #[arg(long, value_enum)]
    pub defaults: Option<DefaultsArg>,
}

impl ImageArgs {
    /// The flags, with the seed and the facing, as the library's options.
    pub fn with_seed(&self, seed: &SeedArgs) -> ImageOptions {
        ImageOptions {
            seed: seed.seed,
            two_sided: seed.two_sided,
            ..self.options()
        }
    }

    /// The flags as the library's options.
    pub fn options(&self) -> ImageOptions {
        ImageOptions {
            size: self.size.as_ref().map(|s| [s[0], s[1]]),
            bounces: self.bounces,
            shadows: self.shadows.map(Into::into),
            shadow_samples: self.shadow_samples,
            sampler: self.sampler.into(),
            aa: self.aa,
            background: self.background.as_ref().map(|c| [c[0], c[1], c[2]]),
            ambient: self.ambient.as_ref().map(|c| [c[0], c[1], c[2]]),
            light_model: self.light_model.map(Into::into),
            ring_segments: self.ring_segments,
            defaults: self.defaults.map(Into::into),
            seed: 0,
            two_sided: false,
        }
    }

    /// The flags as given, spelled for another build's `raywave render` (`bench --against`):
    /// only what was set, so each build fills the rest with its own defaults, as a user running
    /// both with the same command line would see.
    pub fn flags(&self) -> Vec<String> {
        fn all<T: ToString>(values: &Option<Vec<T>>) -> Option<Vec<String>> {
            Some(values.as_ref()?.iter().map(T::to_string).collect())
        }
        fn one(value: Option<impl ToString>) -> Option<Vec<String>> {
            value.map(|v| vec![v.to_string()])
        }
        [
            ("--size", all(&self.size)),
            ("--bounces", one(self.bounces)),
            ("--shadows", one(self.shadows.map(spelling))),
            ("--shadow-samples", one(self.shadow_samples)),
            ("--sampler", one(Some(spelling(self.sampler)))),
            ("--aa", one(self.aa)),
            ("--background", all(&self.background)),
            ("--ambient", all(&self.ambient)),
            ("--light-model", one(self.light_model.map(spelling))),
            ("--ring-segments", one(self.ring_segments)),
            ("--defaults", one(self.defaults.map(spelling))),
        ]
        .into_iter()
        .filter_map(|(flag, values)| Some([vec![flag.to_string()], values?].concat()))
        .flatten()
        .collect()
    }
}

/// The seed and the facing: what shapes a render besides the image flags (`render`,
/// `trace-pixel` and `view` take them; `bench` renders with their defaults).
#[derive(Args, Debug, Clone)]
pub struct SeedArgs {
    /// Seed of every random number.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Let faces be hit from behind too.
    #[arg(long)]
    pub two_sided: bool,
}

/// The worker threads of every command that renders on one pool.
#[derive(Args, Debug, Clone)]
pub struct ThreadsArg {
    /// Worker threads [default: all cores]; 1 runs serially.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
}

/// Prints text meant for the terminal: on stdout, or on stderr when one of `plan`'s outputs
/// goes to stdout (so the text does not mix into it).
pub fn say(plan: &OutputPlan, text: &str) -> anyhow::Result<()> {
    if plan.uses_stdout() {
        eprint!("{text}");
        Ok(())
    } else {
        raywave::output::terminal::print(text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Wrapper {
        #[command(flatten)]
        image: ImageArgs,
    }

    fn flags(line: &str) -> String {
        let parsed = Wrapper::parse_from(std::iter::once("x").chain(line.split_whitespace()));
        parsed.image.flags().join(" ")
    }

    #[test]
    fn flags_spell_only_what_was_set_in_declaration_order() {
        assert_eq!(flags(""), "--sampler stratified");
        let all = "--size 3 4 --bounces 2 --shadows hard --shadow-samples 4 --sampler sobol --aa 2 \
                   --background 0.5 1 0 --ambient 0.1 0.25 3 --light-model rpi \
                   --ring-segments 8 --defaults lab";
        assert_eq!(
            flags(all),
            all.split_whitespace().collect::<Vec<_>>().join(" ")
        );
        assert_eq!(
            flags("--defaults rpi --aa 3 --size 1 2"),
            "--size 1 2 --sampler stratified --aa 3 --defaults rpi"
        );
    }
}
