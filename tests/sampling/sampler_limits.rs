//! Each sampler's limits (`RenderSettings::check_sampler`, `sampling::check`): the points per light and the image a render may
//! ask of it, and a message that names the sampler, its limit and why past them. What the
//! points themselves promise is in `point_statistics/promises.rs`.

use raywave::render::sampling::LightSampler;
use raywave::render::settings::{RenderSettings, ShadowMode};

fn soft(sampler: LightSampler, n: u32, size: (u32, u32), aa: u32) -> RenderSettings {
    RenderSettings {
        width: size.0,
        height: size.1,
        shadows: ShadowMode::Soft,
        shadow_samples: n,
        sampler,
        aa_samples: aa,
        ..RenderSettings::default()
    }
}

#[test]
fn every_sampler_s_limits_are_checked_and_named() {
    let ok = |s: RenderSettings| s.check_sampler().expect("within the limits");
    let err = |s: RenderSettings| s.check_sampler().expect_err("past a limit").to_string();
    for sampler in LightSampler::ALL {
        ok(soft(sampler, 1, (512, 512), 1));
        ok(soft(sampler, 256, (512, 512), 1));
        let e = err(soft(sampler, 0, (512, 512), 1));
        assert!(
            e.contains("--shadow-samples 0") && e.contains(sampler.name()),
            "{e}"
        );
        // No points is an error with any shadows: it is never a setting.
        let hard = RenderSettings {
            shadows: ShadowMode::Hard,
            ..soft(sampler, 0, (64, 64), 1)
        };
        assert!(hard.check_sampler().is_err());
    }
    for sampler in [
        LightSampler::Random,
        LightSampler::Stratified,
        LightSampler::Sobol,
        LightSampler::Lab,
        LightSampler::Halton,
    ] {
        ok(soft(sampler, 65536, (512, 512), 4));
    }
    ok(soft(LightSampler::Pmj02, 4096, (512, 512), 1));
    let e = err(soft(LightSampler::Pmj02, 4097, (512, 512), 1));
    assert!(e.contains("pmj02") && e.contains("4096"), "{e}");
    ok(soft(LightSampler::Bluenoise, 64, (512, 512), 4));
    let e = err(soft(LightSampler::Bluenoise, 257, (512, 512), 1));
    assert!(e.contains("bluenoise") && e.contains("256"), "{e}");
    let e = err(soft(LightSampler::Bluenoise, 64, (512, 512), 8));
    assert!(e.contains("512 per pixel") && e.contains("256"), "{e}");
    // 16384² is 28 index bits, 16 samples 4 more: 32, the most.
    ok(soft(LightSampler::Zsobol, 16, (16384, 16384), 1));
    let e = err(soft(LightSampler::Zsobol, 17, (16384, 16384), 1));
    assert!(
        e.contains("zsobol") && e.contains("33-bit") && e.contains("32"),
        "{e}"
    );
    // Hard shadows count one point per light.
    let hard = RenderSettings {
        shadows: ShadowMode::Hard,
        ..soft(LightSampler::Bluenoise, 4096, (512, 512), 1)
    };
    ok(hard);
}
