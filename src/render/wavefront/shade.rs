//! The lab's Shade in the wavefront engine: each material's terms computed once, the scalar
//! Shade over them ([`shade_terms`], twin of `shading::shade`) and its SIMD twin
//! ([`shade_lanes`], 8 or 16 lanes), side by side so that the twins read
//! alike.
//!
//! These live here rather than in `crate::render::shading`: the terms are the wavefront engine's
//! per-render table (the reference shades from `Material` directly), and the SIMD twin names
//! lane types, which stay inside the wavefront engine's kernels.

use super::lanes::Lanes;
use crate::render::scene::Material;
use crate::render::shading::AMBIENT;
use glam::Vec3;

/// A material's terms of the lab's Shade, computed once with the reference's operations.
#[derive(Clone, Copy, Debug)]
pub struct MaterialTerms {
    /// kd.
    pub diffuse: Vec3,
    /// kr.
    pub reflective: Vec3,
    /// ambient ⊙ kd: what every hit gets.
    pub ambient: Vec3,
    /// AMBIENT · ke: Shade's first term.
    pub ambient_emitted: Vec3,
    /// 0.8 · kr: the specular colour.
    pub specular: Vec3,
    /// 5 / (g + 0.01).
    pub shininess: f32,
    /// kr ≠ 0: spawns mirror rays and has a highlight.
    pub is_reflective: bool,
    /// The texture kd comes from, point by point (`Material::texture`): `diffuse` and `ambient`
    /// above then hold the average, and each hit takes [`MaterialTerms::with_diffuse`].
    pub texture: Option<u32>,
}

impl MaterialTerms {
    /// The terms of `m` under the ambient light `ambient`.
    pub fn new(m: &Material, ambient: Vec3) -> MaterialTerms {
        MaterialTerms {
            diffuse: m.diffuse,
            reflective: m.reflective,
            ambient: ambient * m.diffuse,
            ambient_emitted: AMBIENT * m.emitted,
            specular: 0.8 * m.reflective,
            shininess: m.shininess(),
            is_reflective: m.is_reflective(),
            texture: m.texture,
        }
    }

    /// The terms with kd = `diffuse` under the ambient light `ambient`: a textured material at
    /// one hit, computed as [`MaterialTerms::new`] computes them.
    #[inline]
    pub fn with_diffuse(&self, diffuse: Vec3, ambient: Vec3) -> MaterialTerms {
        MaterialTerms {
            diffuse,
            ambient: ambient * diffuse,
            ..*self
        }
    }
}

/// The lab's Shade, twin of `shading::shade` with the same operations in the same order, minus
/// the work whose result is exactly zero: no highlight (and no `powf`) when kr = 0 or when
/// e·r ≤ 0 (with a positive exponent), since the reference then adds `±0.0`, which changes
/// nothing. Tested bit-equal.
#[inline]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x > 0.0)` is on purpose: true for NaN
pub fn shade_terms(
    m: &MaterialTerms,
    n: Vec3,
    e: Vec3,
    l: Vec3,
    n_dot_l: f32,
    light_color: Vec3,
) -> Vec3 {
    let c = m.ambient_emitted + light_color * m.diffuse * n_dot_l;
    // With a positive exponent, base^s is finite, so kr = 0 makes the highlight ±0 ...
    let positive = m.shininess > 0.0;
    if positive && !m.is_reflective {
        return c;
    }
    let r = (2.0 * n_dot_l * n - l).normalize();
    let base = e.dot(r).max(0.0);
    // ... and so does base = 0 (0^s = 0).
    if positive && !(base > 0.0) {
        return c;
    }
    c + light_color * m.specular * (base.powf(m.shininess) * n_dot_l)
}

/// What one hit and one light bring to the Shade of their shadow rays.
#[derive(Clone, Copy, Debug)]
pub struct HitLight<'a> {
    /// The hit's material.
    pub material: &'a MaterialTerms,
    /// n: the hit's normal.
    pub normal: Vec3,
    /// e: the unit direction back to the viewer.
    pub to_eye: Vec3,
    /// Lc: the light's colour (before any fall-off).
    pub light_color: Vec3,
    /// 1 / N: the weight of each of the light's points.
    pub weight: f32,
}

/// 8 (or 16) shadow rays from one hit towards one light, as the queue holds them.
#[derive(Clone, Copy, Debug)]
pub struct ShadowLanes<'a> {
    /// l: x, y, z of each ray's unit direction (one entry per lane each).
    pub l: [&'a [f32]; 3],
    /// n·l of each ray; ≤ 0 for a dead lane.
    pub n_dot_l: &'a [f32],
    /// Whether each ray is blocked.
    pub blocked: &'a [bool],
    /// Each ray's light fall-off (`spawn::falloff`), or `None` in the lab's model (exactly 1).
    pub falloff: Option<&'a [f32]>,
}

/// Shade · weight of N shadow rays (8 or 16) cast from one hit towards one light: lane k
/// equals `shade_terms(m, n, e, l_k, n·l_k, light_color · falloff_k) * weight` bit for bit
/// (`powf` runs per lane, in scalar, only where the scalar twin calls it); `rays` holds N
/// entries per column. Lanes that add nothing (dead, n·l ≤ 0, or `blocked`) come back as
/// −0.0, the exact identity of IEEE addition (x + −0 = x for every x, −0 included), so the
/// caller adds all N lanes in order without a branch.
#[inline]
pub fn shade_lanes<V: Lanes>(at: &HitLight, rays: &ShadowLanes) -> [V::Array; 3] {
    let ShadowLanes {
        l,
        n_dot_l,
        blocked,
        falloff,
    } = *rays;
    let lanes = ShadowRegisters {
        l: [
            V::load(l[0], 0, 0.0),
            V::load(l[1], 0, 0.0),
            V::load(l[2], 0, 0.0),
        ],
        n_dot_l: V::load(n_dot_l, 0, 0.0),
        open: V::from_fn(|k| if blocked[k] { 0.0 } else { 1.0 }),
        falloff: falloff.map(|f| V::load(f, 0, 1.0)),
    };
    shade_registers(at, &lanes)
}

/// N shadow rays from one hit towards one light, in registers: [`ShadowLanes`] loaded, or a
/// block the fused shadow stage has just spawned and tested.
#[derive(Clone, Copy, Debug)]
pub struct ShadowRegisters<V> {
    /// l: each ray's unit direction.
    pub l: [V; 3],
    /// n·l of each ray; ≤ 0 for a dead lane.
    pub n_dot_l: V,
    /// 1.0 where the ray is not blocked, 0.0 where it is.
    pub open: V,
    /// Each ray's light fall-off, or `None` in the lab's model (exactly 1).
    pub falloff: Option<V>,
}

/// [`shade_lanes`] on rays already in registers: the same lanes, bit for bit.
#[inline(always)]
pub fn shade_registers<V: Lanes>(at: &HitLight, rays: &ShadowRegisters<V>) -> [V::Array; 3] {
    let HitLight {
        material: m,
        normal: n,
        to_eye: e,
        light_color,
        weight,
    } = *at;
    let ShadowRegisters {
        l: [lx, ly, lz],
        n_dot_l: ndl,
        open,
        falloff,
    } = *rays;
    // Each lane's light colour: Lc · falloff (`spawn::falloff`), or Lc itself in the lab's
    // model, whose fall-off is exactly 1 (x · 1 = x, so both give the twin's bits).
    let lc = {
        let splat = |c: f32| V::splat(c);
        let (r, g, b) = (
            splat(light_color.x),
            splat(light_color.y),
            splat(light_color.z),
        );
        match falloff {
            None => [r, g, b],
            Some(f) => [r * f, g * f, b * f],
        }
    };
    let adds = ndl.simd_gt(V::ZERO) & open.simd_gt(V::ZERO);
    let nothing = V::splat(-0.0);
    let cr = V::splat(m.ambient_emitted.x) + lc[0] * V::splat(m.diffuse.x) * ndl;
    let cg = V::splat(m.ambient_emitted.y) + lc[1] * V::splat(m.diffuse.y) * ndl;
    let cb = V::splat(m.ambient_emitted.z) + lc[2] * V::splat(m.diffuse.z) * ndl;
    let positive = m.shininess > 0.0;
    let w = V::splat(weight);
    if positive && !m.is_reflective {
        let out = |c: V| adds.select(c * w, nothing).to_array();
        return [out(cr), out(cg), out(cb)];
    }
    // r = normalize(2(n·l) n − l), glam's normalize: v · (1 / |v|).
    let k = V::splat(2.0) * ndl;
    let rx = k * V::splat(n.x) - lx;
    let ry = k * V::splat(n.y) - ly;
    let rz = k * V::splat(n.z) - lz;
    let recip = V::ONE / (rx * rx + ry * ry + rz * rz).sqrt();
    let (rx, ry, rz) = (rx * recip, ry * recip, rz * recip);
    let e_dot_r = (V::splat(e.x) * rx + V::splat(e.y) * ry + V::splat(e.z) * rz).to_array();
    let mut spec = V::Array::default();
    let mut with_highlight = V::Array::default();
    for k in 0..V::N {
        let base = e_dot_r[k].max(0.0);
        if !positive || base > 0.0 {
            spec[k] = base.powf(m.shininess);
            with_highlight[k] = 1.0;
        }
    }
    let on = V::from_array(with_highlight).simd_gt(V::ZERO);
    let s = V::from_array(spec) * ndl;
    let sc = m.specular;
    let add =
        |c: V, lc: V, sc: f32| adds.select(on.select(c + lc * V::splat(sc) * s, c) * w, nothing);
    [
        add(cr, lc[0], sc.x).to_array(),
        add(cg, lc[1], sc.y).to_array(),
        add(cb, lc[2], sc.z).to_array(),
    ]
}
