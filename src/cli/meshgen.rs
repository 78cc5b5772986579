//! `raywave meshgen`: writes the Cornell box with tessellated mirror spheres.

use anyhow::Result;
use clap::Args;
use raywave::output::OutputPlan;
use raywave::render::scene::meshgen::{bands_for, cornell_box_mesh_spheres, triangle_count};
use std::io::Write;
use std::path::PathBuf;

/// `raywave meshgen` flags.
#[derive(Args, Debug, Clone)]
pub struct MeshgenArgs {
    /// Approximate number of triangles.
    #[arg(long, default_value_t = 12_000,
          value_parser = clap::value_parser!(u64).range(36..=50_000_000))]
    pub triangles: u64,
    /// Output scene file (.obj; `-` for standard output).
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Writes the scene, whole or not at all, and says so.
pub fn run(args: &MeshgenArgs) -> Result<()> {
    let plan = OutputPlan::new().output("-o", &args.output);
    plan.check()?;
    let bands = bands_for(args.triangles as usize);
    let text = cornell_box_mesh_spheres(bands);
    raywave::output::write_output(&args.output, |w| Ok(w.write_all(text.as_bytes())?))?;
    let text = format!(
        "wrote   {}: {} triangles ({bands} latitude bands per sphere)\n",
        args.output.display(),
        triangle_count(bands)
    );
    super::image::say(&plan, &text)
}
