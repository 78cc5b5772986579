//! The command line, which belongs to the binary: clap's types, one file per command, each
//! turning its flags into the library's plain options (`ImageOptions`, `BenchOptions`,
//! `VarianceOptions`) and running the command; `main` owns the exit code. What each file holds
//! is in the module map of docs/ARCHITECTURE.md (`cli/`).

pub mod bench;
pub mod combos;
pub mod diff;
pub mod foreign;
pub mod image;
pub mod info;
pub mod meshgen;
pub mod render;
pub mod trace_pixel;
pub mod values;
pub mod variance;
pub mod view;

use clap::{ArgMatches, CommandFactory, FromArgMatches, Parser, Subcommand};

/// raywave: a SIMD wavefront ray tracer for the lab's Cornell-box scenes.
#[derive(Parser, Debug)]
#[command(name = "raywave", version, about, long_about = None)]
pub(crate) struct Cli {
    /// What to do (default: render).
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
// Parsed once per run: the size of the `Render` variant does not matter.
#[allow(clippy::large_enum_variant)]
pub enum Command {
    /// Render a scene to an image (the default command; the lab's flags work too).
    Render(render::RenderArgs),
    /// Print the build's SIMD path, thread count and version.
    Info,
    /// Write a generated mesh scene: the lab's Cornell box with its three mirror spheres
    /// tessellated (for the BVH benchmarks: about 12k or 1M triangles).
    Meshgen(meshgen::MeshgenArgs),
    /// Compare light samplers: MSE, bias, variance and slopes against a converged reference.
    Variance(variance::VarianceArgs),
    /// Time both engines on a scene (rays/s per kind and stage); save and compare records
    /// (exit 3 when a figure regresses past --threshold; 4 when --until-decided runs out
    /// undecided).
    Bench(bench::BenchArgs),
    /// The lab's debug window in the browser: the render, coarse to fine, the scene in 3D, a
    /// pixel's ray tree, two samplers side by side (a local server on 127.0.0.1).
    View(view::ViewArgs),
    /// Trace one pixel as its render does and show its ray tree: a summary, or JSON, OBJ/PLY
    /// and a PNG from a debug camera (checked against both engines' render of that pixel).
    TracePixel(trace_pixel::TracePixelArgs),
    /// Compare two images (PNG, PPM, PFM, EXR): MSE, relative MSE, largest difference, PSNR
    /// and FLIP, per channel, over the image or a mask; a false-colour map of the error
    /// (exit 3 past --fail-above).
    Diff(diff::DiffArgs),
}

/// Parses the command line, keeping clap's matches: `bench --compare` asks them which flags
/// were given (`ArgMatches::value_source`).
pub fn parse(args: &[std::ffi::OsString]) -> Result<(Cli, ArgMatches), clap::Error> {
    let matches = Cli::command().try_get_matches_from(args)?;
    let cli = Cli::from_arg_matches(&matches)?;
    Ok((cli, matches))
}
