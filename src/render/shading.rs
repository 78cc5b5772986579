//! The lab's shading model, written once and used by every engine.
//!
//! Shade(l) = 0.2·ke + Lc⊙kd·max(0, n·l) + Lc⊙(0.8·kr)·max(0, e·r)^(5/(g+0.01))·max(0, n·l),
//! with r = normalize(2(n·l)n − l), e = −ray direction and Lc = 0.2·ke(light)·area(light).
//! docs/SHADING.md derives it and lists the choices.

use crate::render::scene::Material;
use glam::Vec3;

/// The lab's 0.2: its fixed ambient light (every hit gets 0.2·kd unless `-ambient_light` says
/// otherwise, `RenderSettings::ambient`) and the factor on a surface's own emission in Shade.
pub const AMBIENT: f32 = 0.2;

/// The lab's Shade for one light direction `l` (unit) with `n·l = n_dot_l > 0`, already known
/// to be unoccluded. `e` is the unit direction back to the viewer.
#[inline]
pub fn shade(
    material: &Material,
    n: Vec3,
    e: Vec3,
    l: Vec3,
    n_dot_l: f32,
    light_color: Vec3,
) -> Vec3 {
    let r = (2.0 * n_dot_l * n - l).normalize();
    let spec = e.dot(r).max(0.0).powf(material.shininess());
    AMBIENT * material.emitted
        + light_color * material.diffuse * n_dot_l
        + light_color * (0.8 * material.reflective) * (spec * n_dot_l)
}

/// Mirror direction d − 2(d·n)n, renormalised so long paths do not drift.
#[inline]
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    (d - 2.0 * d.dot(n) * n).normalize()
}
