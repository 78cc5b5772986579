//! The tree's sum against the pixel as each engine renders it.
//!
//! Each engine renders the one pixel through its own per-pixel loop: the reference's
//! `Reference::pixel` (what its `render` runs for every pixel), the wavefront engine's
//! `render_tile` on a tile of that one pixel (a pixel's value does not depend on the tile it is
//! in: every lane is bit-equal to the scalar twins and each pixel is summed in sample order).

use super::tree::{PixelCheck, RayCountCheck, RayTree, Segment, SegmentKind};
use crate::render::engine::Engine;
use crate::render::per_kind::RayCounts;
use crate::render::reference::Reference;
use crate::render::scene::Scene;
use crate::render::settings::RenderSettings;
use crate::render::wavefront::stats::RenderStats;
use crate::render::wavefront::{Wavefront, Workspace};
use glam::Vec3;

/// The accepted difference between the tree's sum and a rendered pixel, relative to
/// max(1, the pixel's largest channel): the engines add the same f32 terms in other orders
/// (nested kr ⊙ (...) instead of distributed over the path), a few ulps per term; 1e-5 is
/// about 80 ulps at 1.
pub(crate) const TOLERANCE: f64 = 1e-5;

/// Pixel `index` (row-major) as `engine` renders it, in linear RGB (`Reference::pixel`, or
/// `Wavefront::render_tile` on a one-pixel tile), and the rays the engine counts for it.
pub fn render_pixel_counted(
    engine: Engine,
    scene: &Scene,
    settings: &RenderSettings,
    index: u32,
) -> (Vec3, RayCounts) {
    match engine {
        Engine::Reference => {
            let mut counts = RayCounts::default();
            let colour = Reference::new(scene, settings).pixel(index, &mut counts, &mut ());
            (colour, counts)
        }
        Engine::Wavefront => {
            let batch = settings.aa_samples.max(1) as usize;
            let wavefront = Wavefront::new(scene, settings, batch);
            let mut out = [Vec3::ZERO];
            let mut stats = RenderStats::default();
            wavefront.render_tile(index, &mut out, &mut Workspace::default(), &mut stats);
            (out[0], stats.counts)
        }
    }
}

/// The tree's rays by kind, shadow rays counted where the occlusion test ran (as the engines
/// count them).
pub fn tree_counts(tree: &RayTree) -> RayCounts {
    let of = |k: SegmentKind| tree.segments.iter().filter(|s| s.kind == k).count() as u64;
    RayCounts {
        camera: of(SegmentKind::Camera),
        reflection: of(SegmentKind::Reflection),
        shadow: tree
            .segments
            .iter()
            .filter(|s| s.shadow.as_ref().is_some_and(|i| i.blocked.is_some()))
            .count() as u64,
    }
}

/// The sum of the segments' contributions, in f64, in tree order: the tree's `sum`.
pub fn contribution_sum(segments: &[Segment]) -> [f64; 3] {
    segments.iter().fold([0.0f64; 3], |sum, s| {
        [0, 1, 2].map(|c| sum[c] + f64::from(s.contribution[c]))
    })
}

/// Renders the tree's pixel with both engines and compares them with the sum of the tree's
/// contributions (summed again here from the segments, not read from `tree.sum`) and their ray
/// counters with the tree's segments.
pub fn check_pixel(scene: &Scene, settings: &RenderSettings, tree: &RayTree) -> PixelCheck {
    let index = tree.pixel.index;
    let sum = contribution_sum(&tree.segments);
    let (reference, reference_rays) =
        render_pixel_counted(Engine::Reference, scene, settings, index);
    let (wavefront, wavefront_rays) =
        render_pixel_counted(Engine::Wavefront, scene, settings, index);
    let rays = RayCountCheck {
        tree: tree_counts(tree),
        reference: reference_rays,
        wavefront: wavefront_rays,
    };
    let difference = |p: Vec3| {
        (0..3)
            .map(|c| (sum[c] - f64::from(p[c])).abs())
            .fold(0.0f64, f64::max)
    };
    let magnitude = f64::from(reference.max_element().max(wavefront.max_element())).max(1.0);
    let tolerance = TOLERANCE * magnitude;
    let (rd, wd) = (difference(reference), difference(wavefront));
    PixelCheck {
        sum,
        reference: reference.to_array(),
        wavefront: wavefront.to_array(),
        reference_difference: rd,
        wavefront_difference: wd,
        tolerance,
        agrees: rd <= tolerance
            && wd <= tolerance
            && rays.tree == rays.reference
            && rays.tree == rays.wavefront,
        rays,
    }
}
