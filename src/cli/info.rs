//! `raywave info`: the version, the build (commit, profile, target, features, RUSTFLAGS), the
//! build's SIMD path and default lane width, and the default thread count.

use anyhow::Result;

/// Prints the lines.
pub fn run() -> Result<()> {
    let b = raywave::output::build_info::current();
    raywave::output::terminal::print(&format!(
        "raywave {}\ncommit  {}\nbuild   {} · {}\nrustflags {}\nfeatures {}\nsimd    {}\nlanes   {} by default, 8 for hard shadows and for 8 or fewer points per light (--lanes 8 or 16 forces a width; the same image either way)\nthreads {} (rayon default; --threads N to change)\n",
        env!("CARGO_PKG_VERSION"),
        match b.dirty {
            Some(true) => format!("{} (dirty)", b.commit),
            _ => b.commit.clone(),
        },
        b.profile,
        b.target,
        if b.rustflags.is_empty() {
            "(none)"
        } else {
            &b.rustflags
        },
        b.target_features,
        raywave::simd_path(),
        raywave::render::wavefront::lanes::LaneWidth::NATIVE.lanes(),
        rayon::current_num_threads()
    ))
}
