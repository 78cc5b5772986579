//! Soft shadows are unbiased. A floor point p under a 1 × 1 light is half hidden by a small
//! sphere (a penumbra). Its exact value is 0.2·kd + Lc⊙kd·I, where I is the light-averaged
//! n·l over the visible part of the light; this file computes I independently on a fine grid
//! with its own segment–sphere test. Then, for each sampler, the mean over many seeds of the
//! reference's N = 4 estimate must match I, and the f64 oracle's high-N estimate
//! (tests/oracle/mod.rs), within ~5 standard errors of the mean taken from the sample variance. A pentagonal light checks the fan sampler the same way.

use crate::common;
use crate::oracle;

use common::{PENTAGON, SQUARE};

use glam::{DVec3, Vec3};
use oracle::Oracle;
use raywave::render::per_kind::RayCounts;
use raywave::render::reference::Reference;
use raywave::render::sampling::LightSampler;
use raywave::render::scene::{Scene, parse_scene_str};
use raywave::render::settings::{RenderSettings, ShadowMode};

const KD: f64 = 0.5;
const KE: f64 = 1.0;
const P: DVec3 = DVec3::new(0.3, 0.0, 0.2);
const BLOCKER: DVec3 = DVec3::new(0.2, 1.0, 0.1);
const BLOCKER_R: f64 = 0.15;

/// Floor (kd 0.5), a light at y = 2 with the given x, z corners, a blocker sphere, and a
/// camera whose single centre ray hits p.
fn scene(light_corners: &[(f64, f64)]) -> Scene {
    let mut text = format!(
        "material\ndiffuse 0 0 0\nemitted {KE} {KE} {KE}\nmaterial\ndiffuse {KD} {KD} {KD}\n"
    );
    for (x, z) in light_corners {
        text += &format!("v {x} 2 {z}\n");
    }
    text += "m 0\nf";
    for k in 1..=light_corners.len() {
        text += &format!(" {k}");
    }
    let n = light_corners.len();
    text += &format!(
        "\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\nm 1\nf {} {} {} {}\n",
        n + 1,
        n + 2,
        n + 3,
        n + 4
    );
    text += &format!("s {} {} {} {BLOCKER_R}\n", BLOCKER.x, BLOCKER.y, BLOCKER.z);
    text += &format!(
        "PerspectiveCamera {{\ncamera_position {} 0.5 2\npoint_of_interest {} {} {}\nangle 20\n}}\n",
        P.x, P.x, P.y, P.z
    );
    parse_scene_str(&text, "penumbra.obj").unwrap()
}

/// Does the segment p -> q pass through the blocker? (Both ends are outside it.)
fn blocked(q: DVec3) -> bool {
    let d = q - P;
    let t = ((BLOCKER - P).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (P + t * d).distance(BLOCKER) < BLOCKER_R
}

/// (I, visible fraction) by the midpoint rule on a fine grid over the light's bounding square,
/// keeping the points for which `inside` holds.
// Alike in shape to oracle_bias.rs's `closed_form` on purpose: each file computes its truth
// its own way (here a segment–sphere test, there the blocker's half-plane), so they stay apart.
fn exact(inside: impl Fn(f64, f64) -> bool) -> (f64, f64) {
    let n = 1200;
    let (mut sum, mut visible, mut total) = (0.0, 0usize, 0usize);
    for a in 0..n {
        for b in 0..n {
            let x = -0.5 + (a as f64 + 0.5) / n as f64;
            let z = -0.5 + (b as f64 + 0.5) / n as f64;
            if !inside(x, z) {
                continue;
            }
            total += 1;
            let q = DVec3::new(x, 2.0, z);
            if !blocked(q) {
                visible += 1;
                sum += (q - P).normalize().y; // n·l with n = +y
            }
        }
    }
    (sum / total as f64, visible as f64 / total as f64)
}

fn settings(sampler: LightSampler, n: u32, seed: u32) -> RenderSettings {
    RenderSettings {
        width: 1,
        height: 1,
        bounces: 0,
        shadows: ShadowMode::Soft,
        shadow_samples: n,
        sampler,
        aa_samples: 1,
        background: [0.0; 3],
        seed,
        two_sided: false,
        ..RenderSettings::default()
    }
}

/// The reference's estimate of I for one seed: (pixel − 0.2·kd) / (Lc·kd).
fn estimate(scene: &Scene, sampler: LightSampler, n: u32, seed: u32) -> f64 {
    let s = settings(sampler, n, seed);
    let c: Vec3 = Reference::new(scene, &s).pixel(0, &mut RayCounts::default(), &mut ());
    let lc = 0.2 * KE * scene.lights[0].area as f64;
    assert!(
        c.x == c.y && c.y == c.z,
        "a grey scene gives a grey pixel: {c}"
    );
    (c.x as f64 - 0.2 * KD) / (lc * KD)
}

/// (mean, standard error of the mean) over `seeds` seeds.
fn mean_and_se(scene: &Scene, sampler: LightSampler, n: u32, seeds: u32) -> (f64, f64) {
    let xs: Vec<f64> = (0..seeds)
        .map(|seed| estimate(scene, sampler, n, seed))
        .collect();
    let m = xs.iter().sum::<f64>() / xs.len() as f64;
    let var = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (xs.len() - 1) as f64;
    (m, (var / xs.len() as f64).sqrt())
}

/// The f64 oracle's estimate of I for `n` stratified points, as (mean, standard error of the
/// mean) over `seeds` seeds: the converged value, from an evaluator independent of the engines.
fn oracle_mean_and_se(scene: &Scene, n: u32, seeds: u32) -> (f64, f64) {
    let lc = 0.2 * KE * scene.lights[0].area as f64;
    let xs: Vec<f64> = (0..seeds)
        .map(|seed| {
            let s = settings(LightSampler::Stratified, n, seed);
            (Oracle::new(scene, &s).pixel(0).x - 0.2 * KD) / (lc * KD)
        })
        .collect();
    let m = xs.iter().sum::<f64>() / xs.len() as f64;
    let var = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (xs.len() - 1) as f64;
    (m, (var / xs.len() as f64).sqrt())
}

/// |a − b| within `k` combined standard errors, with a float-rounding floor of 1e-5.
fn agree(what: &str, (a, se_a): (f64, f64), (b, se_b): (f64, f64), k: f64) {
    let bound = k * (se_a * se_a + se_b * se_b).sqrt() + 1e-5;
    assert!(
        (a - b).abs() <= bound,
        "{what}: {a:.6} ± {se_a:.6} vs {b:.6} ± {se_b:.6}: differ by {:.6} > {bound:.6}",
        (a - b).abs()
    );
}

/// `max_se_ratio`: how far below random's standard error stratified's must be at N = 16.
fn check_unbiased(scene: &Scene, exact: (f64, f64), max_se_ratio: f64) {
    let (i_exact, fraction) = exact;
    assert!(
        (0.2..0.8).contains(&fraction),
        "p must be in the penumbra: {fraction} of the light visible"
    );
    // The grid's own error is far below the bounds used here (1200² points); treat it as 0.
    let truth = (i_exact, 0.0);
    let seeds = 3000;
    let random = mean_and_se(scene, LightSampler::Random, 4, seeds);
    let stratified = mean_and_se(scene, LightSampler::Stratified, 4, seeds);
    assert!(
        random.1 > 0.0 && stratified.1 > 0.0,
        "no noise at all: not a penumbra"
    );
    agree("random N=4 vs exact", random, truth, 5.0);
    agree("stratified N=4 vs exact", stratified, truth, 5.0);
    agree("random vs stratified", random, stratified, 5.0);
    // Non-square N: strips of strata are still unbiased.
    let odd = mean_and_se(scene, LightSampler::Stratified, 6, seeds);
    agree("stratified N=6 vs exact", odd, truth, 5.0);
    let prime = mean_and_se(scene, LightSampler::Stratified, 7, seeds);
    agree("stratified N=7 vs exact", prime, truth, 5.0);
    // A high-N estimate from the f64 oracle: stratified N = 1024 over a few seeds.
    let high = oracle_mean_and_se(scene, 1024, 16);
    agree("stratified N=4 vs N=1024", stratified, high, 5.0);
    agree("N=1024 vs exact", high, truth, 5.0);
    eprintln!(
        "exact {i_exact:.5} (visible {fraction:.3}); N=4 random {random:?}, stratified {stratified:?}; N=1024 {high:?}"
    );
    // Stratification must reduce the noise once the strata are finer than the penumbra's
    // shadow disk (at N = 4 every 2 × 2 stratum is partly shadowed and it barely helps). On a
    // parallelogram the strata are rectangles and help a lot (measured: se ratio 0.64); on a
    // fan light Shirley's map makes them radial slivers and they help less (0.85).
    let random16 = mean_and_se(scene, LightSampler::Random, 16, 600);
    let stratified16 = mean_and_se(scene, LightSampler::Stratified, 16, 600);
    eprintln!("N=16 random {random16:?}, stratified {stratified16:?}");
    agree("random vs stratified N=16", random16, stratified16, 5.0);
    assert!(
        stratified16.1 < max_se_ratio * random16.1,
        "stratified se {} is not below {max_se_ratio} × random se {} at N = 16",
        stratified16.1,
        random16.1
    );
}

#[test]
fn penumbra_under_a_square_light_is_unbiased() {
    let s = scene(SQUARE);
    check_unbiased(&s, exact(|_, _| true), 0.8);
}

#[test]
fn penumbra_under_a_pentagonal_light_is_unbiased() {
    let s = scene(PENTAGON);
    assert!((s.lights[0].area - 0.955).abs() < 1e-5);
    check_unbiased(&s, exact(|x, z| x + z <= 0.7), 1.0);
}

#[test]
fn hard_shadow_uses_the_centroid_only() {
    // Hard shadows see the light from p towards its centroid only: here the centroid is not
    // hidden by the blocker, so p is fully lit with n·l to the centroid.
    let s = scene(SQUARE);
    let c = DVec3::new(0.0, 2.0, 0.0);
    let hidden = blocked(c);
    let mut st = settings(LightSampler::Random, 4, 0);
    st.shadows = ShadowMode::Hard;
    let got = Reference::new(&s, &st).pixel(0, &mut RayCounts::default(), &mut ());
    let want = 0.2 * KD
        + if hidden {
            0.0
        } else {
            0.2 * KE * KD * (c - P).normalize().y
        };
    assert!(
        (got.x as f64 - want).abs() < 1e-5,
        "got {got}, expected {want} (centroid hidden: {hidden})"
    );
}
