//! The tree as readable text: counts by kind, then every segment indented by depth, then the
//! check against both engines. `raywave trace-pixel` prints it when no output is asked for,
//! and `raywave render --debug-pixel` prints it too.

use super::palette::Style;
use super::tree::{PrimitiveRef, PrimitiveShape, RayTree, SegmentKind};
use std::fmt::Write;

/// A point or vector with four decimals: `(x, y, z)`.
pub(super) fn v3(v: [f32; 3]) -> String {
    format!("({:.4}, {:.4}, {:.4})", v[0], v[1], v[2])
}

fn rgb(v: [f32; 3]) -> String {
    format!("({:.5}, {:.5}, {:.5})", v[0], v[1], v[2])
}

fn primitive(p: &PrimitiveRef) -> String {
    match (p.shape, p.face) {
        (PrimitiveShape::Triangle, Some(face)) => format!(
            "face {face} (triangle {}, material {})",
            p.index, p.material
        ),
        _ => format!("sphere {} (material {})", p.index, p.material),
    }
}

/// Counts of segments: (camera, reflection, shadow, blocked shadow).
pub fn counts(tree: &RayTree) -> (usize, usize, usize, usize) {
    let of = |k: SegmentKind| tree.segments.iter().filter(|s| s.kind == k).count();
    let blocked = tree
        .segments
        .iter()
        .filter(|s| s.shadow.as_ref().and_then(|i| i.blocked) == Some(true))
        .count();
    (
        of(SegmentKind::Camera),
        of(SegmentKind::Reflection),
        of(SegmentKind::Shadow),
        blocked,
    )
}

/// The readable tree.
pub fn summary(tree: &RayTree) -> String {
    let mut s = String::new();
    let st = &tree.settings;
    let shadows = match st.shadows.as_str() {
        "soft" => format!(
            "soft, {} {} points per light",
            st.points_per_light, st.sampler
        ),
        other => other.to_string(),
    };
    let _ = writeln!(
        s,
        "pixel ({}, {}) of {} at {}×{}: {} bounces, shadows {shadows}, {} aa sample(s), seed {}",
        tree.pixel.x,
        tree.pixel.y,
        tree.scene,
        st.width,
        st.height,
        st.bounces,
        st.aa_samples,
        st.seed
    );
    let (camera, reflection, shadow, blocked) = counts(tree);
    let _ = writeln!(
        s,
        "segments {}: {camera} camera, {reflection} reflection, {shadow} shadow ({blocked} blocked)",
        tree.segments.len()
    );
    for seg in &tree.segments {
        let indent = "  ".repeat(seg.depth as usize + 1);
        let adds = rgb(seg.contribution);
        match seg.kind {
            SegmentKind::Camera | SegmentKind::Reflection => {
                if seg.kind == SegmentKind::Camera && st.aa_samples > 1 {
                    let _ = writeln!(s, "sample {}", seg.sample);
                }
                let what = match &seg.hit {
                    Some(h) => format!(
                        "hits {} at {} (t {:.4}), adds ambient {adds}",
                        primitive(&h.primitive),
                        v3(h.point),
                        h.t
                    ),
                    None => format!("misses: background, adds {adds}"),
                };
                let _ = writeln!(
                    s,
                    "{indent}{} ray #{} from {} {what}",
                    Style::of(seg).name(),
                    seg.id,
                    v3(seg.origin)
                );
                if let Some(h) = &seg.hit {
                    if let Some(lookup) = &h.texture {
                        let _ = writeln!(
                            s,
                            "{indent}  (texture {} at s {:.4}, t {:.4}: kd {})",
                            lookup.name,
                            lookup.st[0],
                            lookup.st[1],
                            rgb(h.diffuse)
                        );
                    }
                    if h.shadow_points_not_cast > 0 {
                        let _ = writeln!(
                            s,
                            "{indent}  ({} light point(s) below the surface: no ray cast)",
                            h.shadow_points_not_cast
                        );
                    }
                }
            }
            SegmentKind::Shadow => {
                let Some(info) = &seg.shadow else { continue };
                let outcome = match (info.blocked, &info.blocker) {
                    (Some(true), Some(b)) => {
                        format!("blocked by {} at {}", primitive(&b.primitive), v3(b.point))
                    }
                    (Some(true), None) => "blocked".to_string(),
                    (Some(false), _) => format!("visible, adds {adds}"),
                    (None, _) => format!("not tested (shadows off), adds {adds}"),
                };
                let _ = writeln!(
                    s,
                    "{indent}  shadow ray #{} to light {} point {} at {}: {outcome}",
                    seg.id,
                    info.light,
                    info.sample_index,
                    v3(info.light_point)
                );
            }
        }
    }
    let _ = writeln!(
        s,
        "sum of contributions ({:.6}, {:.6}, {:.6})",
        tree.sum[0], tree.sum[1], tree.sum[2]
    );
    if let Some(c) = &tree.check {
        let _ = writeln!(
            s,
            "check   reference {} (|difference| {:.2e}), wavefront {} (|difference| {:.2e}); tolerance {:.1e}: {}",
            rgb(c.reference),
            c.reference_difference,
            rgb(c.wavefront),
            c.wavefront_difference,
            c.tolerance,
            if c.reference_difference <= c.tolerance && c.wavefront_difference <= c.tolerance {
                "the tree adds up to the rendered pixel"
            } else {
                "MISMATCH: the tree does not add up to the rendered pixel"
            }
        );
        let k = |n: &crate::render::per_kind::RayCounts| {
            format!(
                "{} camera, {} reflection, {} shadow",
                n.camera, n.reflection, n.shadow
            )
        };
        let r = &c.rays;
        let same = r.tree == r.reference && r.tree == r.wavefront;
        let _ = writeln!(
            s,
            "rays    tree {}; reference {}; wavefront {}: {}",
            k(&r.tree),
            k(&r.reference),
            k(&r.wavefront),
            if same {
                "the same rays"
            } else {
                "MISMATCH: the engines count other rays"
            }
        );
    }
    s
}
