//! Flags that the other flags make meaningless: the run goes ahead, with one warning line
//! each, so that a typo in a script (`--shadows off --shadow-samples 64`) does not pass
//! unnoticed. Flags are named as the user typed them (the lab's and RPI's spellings too).

use super::Command;
use super::image::ImageArgs;
use super::values::{EngineArg, ToneMapArg};
use raywave::output::image_file::{OutputFormat, output_format};
use raywave::render::sampling::LightSampler;
use raywave::render::settings::ShadowMode;

/// One line per meaningless flag in `command`; `typed` names a raywave flag as the user
/// spelled it.
pub fn meaningless(command: &Command, typed: &dyn Fn(&str) -> String) -> Vec<String> {
    let mut out = Vec::new();
    match command {
        Command::TracePixel(args) => {
            image(&args.image, typed, &mut out);
            out.extend(super::trace_pixel::meaningless(args));
        }
        Command::Render(args) => {
            image(&args.image, typed, &mut out);
            if args.tonemap == ToneMapArg::Exp
                && matches!(output_format(&args.output), Ok(OutputFormat::Linear(_)))
            {
                out.push(format!(
                    "--tonemap exp has no effect: {} {} is a linear float image, not tone mapped",
                    typed("--output"),
                    raywave::render::quote::quote(&args.output.display().to_string())
                ));
            }
            if args.engine == EngineArg::Reference
                && args.batch_size != raywave::render::wavefront::DEFAULT_BATCH_SIZE as u32
            {
                out.push(
                    "--batch-size has no effect with --engine reference (it renders by rows)"
                        .into(),
                );
            }
        }
        Command::Bench(args) => image(&args.image, typed, &mut out),
        Command::View(args) => image(&args.image, typed, &mut out),
        _ => {}
    }
    out
}

fn image(args: &ImageArgs, typed: &dyn Fn(&str) -> String, out: &mut Vec<String>) {
    let options = args.options();
    if options.shadow_samples == Some(0) {
        // An error (`sampling::check`), not a combination to warn about.
        return;
    }
    let shadows = options.resolve(None).settings.shadows;
    if let (Some(given @ (ShadowMode::Off | ShadowMode::Hard)), Some(n)) =
        (options.shadows, options.shadow_samples)
    {
        out.push(format!(
            "{} {n} has no effect with {} {}: only soft shadows sample points on the lights",
            typed("--shadow-samples"),
            typed("--shadows"),
            given.name()
        ));
    }
    if shadows != ShadowMode::Soft && options.sampler != LightSampler::Stratified {
        out.push(format!(
            "--sampler has no effect with {} shadows: only soft shadows sample points on the lights",
            shadows.name()
        ));
    }
}
