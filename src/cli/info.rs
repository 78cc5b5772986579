//! `raywave info`: the version, the build (commit, profile, target, features, RUSTFLAGS), the
//! CPU beside the x86 features the build needs, the build's SIMD path and default lane width,
//! and the default thread count.

use anyhow::Result;

/// Prints the lines.
pub fn run() -> Result<()> {
    let b = raywave::output::build_info::current();
    raywave::output::terminal::print(&format!(
        "raywave {}\ncommit  {}\nbuild   {} · {}\nrustflags {}\nfeatures {}\n{}simd    {}\nlanes   {} by default, 8 for hard shadows and for 8 or fewer points per light (--lanes 8 or 16 forces a width; the same image either way)\nthreads {} (rayon default; --threads N to change)\n",
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
        cpu_lines(),
        raywave::simd_path(),
        raywave::render::wavefront::lanes::LaneWidth::NATIVE.lanes(),
        rayon::current_num_threads()
    ))
}

/// The CPU, the x86 features this build needs with whether the CPU has each, and the CPU's
/// features the build leaves unused (a build on this machine could use them).
fn cpu_lines() -> String {
    use raywave::output::cpu::{self, Cpuid, FEATURES};
    let here = Cpuid::read();
    let has = |f: &cpu::Feature| here.has(f);
    let needed: Vec<&cpu::Feature> = FEATURES.iter().filter(|f| f.compiled).collect();
    let lacks = cpu::missing(FEATURES, has);
    let listed: Vec<String> = (needed.iter())
        .map(|f| format!("{}{}", f.name, if has(f) { "" } else { " (absent)" }))
        .collect();
    let verdict = if lacks.is_empty() {
        "this CPU has every one".to_string()
    } else {
        format!("this CPU lacks {}", lacks.join(", "))
    };
    let unused = cpu::unused(FEATURES, has);
    format!(
        "cpu     {}\nneeds   {} ({} x86 features; {verdict})\nunused  {}\n",
        raywave::output::machine::cpu_model(),
        if listed.is_empty() {
            "none".to_string()
        } else {
            listed.join(" ")
        },
        needed.len(),
        if unused.is_empty() {
            "none: the build uses every x86 feature of this CPU that raywave checks".to_string()
        } else {
            format!(
                "{} (this CPU has them, the build does not use them)",
                unused.join(" ")
            )
        }
    )
}
