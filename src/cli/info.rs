//! `raywave info`: the version, the build's SIMD path and the default thread count.

use anyhow::Result;

/// Prints the three lines.
pub fn run() -> Result<()> {
    raywave::terminal::print(&format!(
        "raywave {}\nsimd    {}\nthreads {} (rayon default; --threads N to change)\n",
        env!("CARGO_PKG_VERSION"),
        raywave::simd_path(),
        rayon::current_num_threads()
    ))
}
