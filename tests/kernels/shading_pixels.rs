//! Pixels computed by hand from the lab's Shade formulas (docs/SHADING.md), compared with the
//! reference renderer to 1e-5. Every expected value is built here from the formula, with this
//! file's own vector arithmetic, never through `raywave::render::shading`.
//!
//! The scenes are small: a floor (y = 0, facing up), a 1 × 1 light at y = 2 facing down, and
//! whatever the test adds. A 1 × 1 image sends its only ray from the camera position straight
//! at the point of interest (x = y = 0.5), so the camera block picks the hit point.

use glam::Vec3;
use raywave::render::camera::CameraRays;
use raywave::render::per_kind::RayCounts;
use raywave::render::reference::Reference;
use raywave::render::sampling::LightSampler;
use raywave::render::scene::{Camera, Scene, parse_scene_str};
use raywave::render::settings::{RenderSettings, ShadowMode};

const FLOOR_KD: Vec3 = Vec3::new(0.5, 0.6, 0.7);
const LIGHT_KE: Vec3 = Vec3::new(1.0, 2.0, 3.0);
/// Lc = 0.2 · ke · area, with area 1.
const LC: Vec3 = Vec3::new(0.2, 0.4, 0.6);
const CENTROID: Vec3 = Vec3::new(0.0, 2.0, 0.0);

/// Materials: 0 light, 1 floor (kd FLOOR_KD, kr `floor_kr`, glossiness `g`), then `extra`.
/// Geometry: the light quad, the floor quad x, z ∈ [-1, 1], then `geometry`, then the camera.
fn scene(floor_kr: Vec3, g: f32, extra: &str, geometry: &str, eye: Vec3, poi: Vec3) -> Scene {
    let text = format!(
        "\
material
diffuse 0 0 0
reflective 0 0 0
emitted {} {} {}
material
diffuse {} {} {}
reflective {} {} {}
emitted 0 0 0
glossiness {g}
{extra}
v -0.5 2 -0.5
v 0.5 2 -0.5
v 0.5 2 0.5
v -0.5 2 0.5
m 0
f 1 2 3 4
v -1 0 1
v 1 0 1
v 1 0 -1
v -1 0 -1
m 1
f 5 6 7 8
{geometry}
PerspectiveCamera {{
  camera_position {} {} {}
  point_of_interest {} {} {}
  up 0 1 0
  angle 20
}}
",
        LIGHT_KE.x,
        LIGHT_KE.y,
        LIGHT_KE.z,
        FLOOR_KD.x,
        FLOOR_KD.y,
        FLOOR_KD.z,
        floor_kr.x,
        floor_kr.y,
        floor_kr.z,
        eye.x,
        eye.y,
        eye.z,
        poi.x,
        poi.y,
        poi.z,
    );
    parse_scene_str(&text, "pixel.obj").unwrap()
}

fn settings(shadows: ShadowMode, bounces: u32) -> RenderSettings {
    RenderSettings {
        width: 1,
        height: 1,
        bounces,
        shadows,
        shadow_samples: 16,
        sampler: LightSampler::Stratified,
        aa_samples: 1,
        background: [0.25, 0.5, 0.75],
        seed: 0,
        two_sided: false,
        ..RenderSettings::default()
    }
}

fn render_pixel(scene: &Scene, settings: &RenderSettings, pixel: u32) -> Vec3 {
    Reference::new(scene, settings).pixel(pixel, &mut RayCounts::default(), &mut ())
}

fn assert_close(got: Vec3, want: Vec3, what: &str) {
    let err = (got - want).abs().max_element();
    assert!(
        err <= 1e-5,
        "{what}: got {got}, expected {want} (error {err})"
    );
}

/// A surface's material terms as Shade reads them.
struct Surface {
    kd: Vec3,
    kr: Vec3,
    ke: Vec3,
    g: f32,
}

/// Hand-written Shade for one light point, straight from the lab's formula: normal n, unit
/// vectors e to the eye and l to the light point, light colour lc.
fn shade_by_hand(m: Surface, n: Vec3, e: Vec3, l: Vec3, lc: Vec3) -> Vec3 {
    let ndl = n.dot(l).max(0.0);
    let r = (2.0 * n.dot(l) * n - l).normalize();
    let spec = e.dot(r).max(0.0).powf(5.0 / (m.g + 0.01));
    0.2 * m.ke + lc * m.kd * ndl + lc * (0.8 * m.kr) * spec * ndl
}

/// The floor's material with reflective `kr` and glossiness `g`.
fn glossy_floor(kr: Vec3, g: f32) -> Surface {
    Surface {
        kd: FLOOR_KD,
        kr,
        ke: Vec3::ZERO,
        g,
    }
}

/// The mirror floor (reflective `kr`, glossiness 0) at p, seen along d, lit by the light's
/// centroid.
fn mirror_floor_by_hand(kr: Vec3, p: Vec3, d: Vec3) -> Vec3 {
    shade_by_hand(
        glossy_floor(kr, 0.0),
        Vec3::Y,
        -d,
        (CENTROID - p).normalize(),
        LC,
    )
}

#[test]
fn floor_point_lit_by_the_light_centroid() {
    let p = Vec3::new(0.3, 0.0, 0.2);
    let eye = Vec3::new(0.3, 1.0, 2.0);
    let s = scene(Vec3::ZERO, 0.0, "", "", eye, p);
    // 0.2·kd + Lc⊙kd·(n·l), l towards the centroid (0, 2, 0): (-0.3, 2, -0.2)/√4.13.
    let ndl = 2.0 / 4.13f32.sqrt();
    let want = 0.2 * FLOOR_KD + LC * FLOOR_KD * ndl;
    for shadows in [ShadowMode::Hard, ShadowMode::Off] {
        let got = render_pixel(&s, &settings(shadows, 5), 0);
        assert_close(got, want, &format!("{shadows:?}"));
    }
}

#[test]
fn glossy_floor_highlight_without_bounces() {
    // A floor with a mirror colour but no bounces left: ambient + diffuse + the highlight.
    let kr = Vec3::new(0.4, 0.5, 0.6);
    let g = 0.5;
    let p = Vec3::new(0.3, 0.0, 0.2);
    let eye = Vec3::new(0.6, 1.5, 0.4);
    let s = scene(kr, g, "", "", eye, p);
    let n = Vec3::Y;
    let e = (eye - p).normalize();
    let l = (CENTROID - p).normalize();
    let want = 0.2 * FLOOR_KD + shade_by_hand(glossy_floor(kr, g), n, e, l, LC);
    // Make sure the highlight is a real part of the value being checked.
    let r = (2.0 * n.dot(l) * n - l).normalize();
    assert!(e.dot(r).powf(5.0 / (g + 0.01)) > 0.5);
    let got = render_pixel(&s, &settings(ShadowMode::Hard, 0), 0);
    assert_close(got, want, "glossy floor");
}

#[test]
fn point_in_full_shadow_gets_only_ambient() {
    // A blocker quad at y = 1, x, z ∈ [-0.9, 0.9], facing down (towards the floor): every
    // segment from p to the light crosses it. The camera sits below it.
    let blocker = "v -0.9 1 -0.9\nv 0.9 1 -0.9\nv 0.9 1 0.9\nv -0.9 1 0.9\nm 1\nf 9 10 11 12\n";
    let p = Vec3::new(0.3, 0.0, 0.2);
    let eye = Vec3::new(0.3, 0.5, 2.0);
    let s = scene(Vec3::ZERO, 0.0, "", blocker, eye, p);
    // The blocker's front faces down: its winding gives normal -y.
    let t = &s.triangles[4];
    assert!(t.normal.distance(Vec3::NEG_Y) < 1e-6);
    let ambient = 0.2 * FLOOR_KD;
    for shadows in [ShadowMode::Hard, ShadowMode::Soft] {
        let got = render_pixel(&s, &settings(shadows, 5), 0);
        assert_close(got, ambient, &format!("{shadows:?}"));
    }
    // Without the shadow test the light counts as visible: the lit value.
    let ndl = 2.0 / 4.13f32.sqrt();
    let got = render_pixel(&s, &settings(ShadowMode::Off, 5), 0);
    assert_close(got, ambient + LC * FLOOR_KD * ndl, "shadows off");
}

#[test]
fn blocker_seen_from_behind_casts_no_shadow() {
    // The same blocker wound the other way faces up: one-sided, so shadow rays pass through it
    // (the lab's convention). Two-sided faces block again.
    let blocker = "v -0.9 1 -0.9\nv -0.9 1 0.9\nv 0.9 1 0.9\nv 0.9 1 -0.9\nm 1\nf 9 10 11 12\n";
    let p = Vec3::new(0.3, 0.0, 0.2);
    let eye = Vec3::new(0.3, 0.5, 2.0);
    let s = scene(Vec3::ZERO, 0.0, "", blocker, eye, p);
    let ndl = 2.0 / 4.13f32.sqrt();
    let got = render_pixel(&s, &settings(ShadowMode::Hard, 5), 0);
    assert_close(got, 0.2 * FLOOR_KD + LC * FLOOR_KD * ndl, "one-sided");
    let mut two = settings(ShadowMode::Hard, 5);
    two.two_sided = true;
    let got = render_pixel(&s, &two, 0);
    assert_close(got, 0.2 * FLOOR_KD, "two-sided");
}

#[test]
fn mirror_floor_reflects_a_known_wall() {
    // Mirror floor (kd FLOOR_KD, kr 0.5, g 0). Wall z = -1, x ∈ [-1, 1], y ∈ [0, 2], facing +z, kd
    // WALL. Camera (0, 1, 2) looks at p = (0, 0, 0.5): d = (0, -1, -1.5)/√3.25, mirrored
    // (0, 1, -1.5)/√3.25, which reaches z = -1 at q = (0, 1, -1).
    let wall_kd = Vec3::new(0.2, 0.9, 0.4);
    let kr = Vec3::splat(0.5);
    let extra = format!(
        "material\ndiffuse {} {} {}\nreflective 0 0 0\nemitted 0 0 0\nglossiness 0\n",
        wall_kd.x, wall_kd.y, wall_kd.z
    );
    let wall = "v -1 0 -1\nv 1 0 -1\nv 1 2 -1\nv -1 2 -1\nm 2\nf 9 10 11 12\n";
    let p = Vec3::new(0.0, 0.0, 0.5);
    let eye = Vec3::new(0.0, 1.0, 2.0);
    // The mirror floor keeps its diffuse FLOOR_KD: ambient, diffuse and highlight at p count.
    let s = scene(kr, 0.0, &extra, wall, eye, p);
    let q = Vec3::new(0.0, 1.0, -1.0);
    let d = (p - eye).normalize();
    let reflected = Vec3::new(0.0, 1.0, -1.5).normalize();
    // The wall point, seen along `reflected`: ambient + diffuse from the centroid (0, 2, 0),
    // l = (0, 1, 1)/√2, n = +z: n·l = 1/√2.
    let at_q = 0.2 * wall_kd
        + shade_by_hand(
            Surface {
                kd: wall_kd,
                kr: Vec3::ZERO,
                ke: Vec3::ZERO,
                g: 0.0,
            },
            Vec3::Z,
            -reflected,
            (CENTROID - q).normalize(),
            LC,
        );
    assert!((Vec3::Z.dot((CENTROID - q).normalize()) - 0.5f32.sqrt()).abs() < 1e-6);
    let at_p = 0.2 * FLOOR_KD + kr * at_q + mirror_floor_by_hand(kr, p, d);
    let got = render_pixel(&s, &settings(ShadowMode::Hard, 1), 0);
    assert_close(got, at_p, "mirror with 1 bounce");
    // With no bounce, the wall's contribution disappears.
    let got = render_pixel(&s, &settings(ShadowMode::Hard, 0), 0);
    assert_close(got, at_p - kr * at_q, "mirror with 0 bounces");
}

#[test]
fn mirror_reflecting_the_sky_returns_kr_times_background() {
    // Camera (0, 1, 2) at p = (0, 0, 0.5): the mirrored ray (0, 1, -1.5) leaves the scene
    // (no wall), so it adds kr ⊙ background.
    let kr = Vec3::new(0.3, 0.6, 0.9);
    let p = Vec3::new(0.0, 0.0, 0.5);
    let eye = Vec3::new(0.0, 1.0, 2.0);
    let s = scene(kr, 0.0, "", "", eye, p);
    let d = (p - eye).normalize();
    let bg = Vec3::new(0.25, 0.5, 0.75);
    let want = 0.2 * FLOOR_KD + kr * bg + mirror_floor_by_hand(kr, p, d);
    let got = render_pixel(&s, &settings(ShadowMode::Hard, 3), 0);
    assert_close(got, want, "mirror to sky");
}

#[test]
fn a_ray_that_misses_everything_is_the_background() {
    let s = scene(
        Vec3::ZERO,
        0.0,
        "",
        "",
        Vec3::new(0.0, 1.0, 5.0),
        Vec3::new(0.0, 1.0, 10.0),
    );
    let got = render_pixel(&s, &settings(ShadowMode::Hard, 5), 0);
    assert_close(got, Vec3::new(0.25, 0.5, 0.75), "background");
}

#[test]
fn sphere_point_is_shaded_with_its_outward_normal() {
    // Diffuse sphere (material 2, kd SPHERE) at (0, 0.5, 0), r 0.5; camera (0, 3, 3) looks at
    // its centre and hits it at c + r·(0, 2.5, 3)/|(0, 2.5, 3)|, where n = (0, 2.5, 3)/|..|.
    let sphere_kd = Vec3::new(0.9, 0.3, 0.1);
    let extra = format!(
        "material\ndiffuse {} {} {}\nreflective 0 0 0\nemitted 0 0 0\nglossiness 0\n",
        sphere_kd.x, sphere_kd.y, sphere_kd.z
    );
    let c = Vec3::new(0.0, 0.5, 0.0);
    let eye = Vec3::new(0.0, 3.0, 3.0);
    let s = scene(Vec3::ZERO, 0.0, &extra, "m 2\ns 0 0.5 0 0.5\n", eye, c);
    let n = Vec3::new(0.0, 2.5, 3.0).normalize();
    let x = c + 0.5 * n;
    let l = (CENTROID - x).normalize();
    assert!(n.dot(l) > 0.1);
    let want = 0.2 * sphere_kd + LC * sphere_kd * n.dot(l);
    let got = render_pixel(&s, &settings(ShadowMode::Hard, 5), 0);
    assert_close(got, want, "sphere");
}

#[test]
fn two_lights_add_up_and_a_light_behind_the_surface_does_not_count() {
    // A second light, 2 × 2 at y = -1 (below the floor), facing up: n·l < 0 from the floor's
    // top, so it adds nothing. A third light at x = 3, y = 1, facing -x, 1 × 1, ke (0, 1, 0):
    // Lc = (0, 0.2, 0), centroid (3, 1.5, 0.5).
    let extra = "material\nemitted 0 1 0\n";
    let geometry = "\
v -1 -1 -1
v -1 -1 1
v 1 -1 1
v 1 -1 -1
m 0
f 9 10 11 12
v 3 1 0
v 3 2 0
v 3 2 1
v 3 1 1
m 2
f 13 14 15 16
";
    let p = Vec3::new(0.3, 0.0, 0.2);
    let eye = Vec3::new(0.3, 1.0, 2.0);
    let s = scene(Vec3::ZERO, 0.0, extra, geometry, eye, p);
    assert_eq!(s.lights.len(), 3);
    // In the lab's model only n·l at the receiver counts, not which way the light faces.
    let third = s.lights.iter().find(|l| l.face == 3).unwrap();
    assert!(third.centroid.distance(Vec3::new(3.0, 1.5, 0.5)) < 1e-6);
    let ndl1 = 2.0 / 4.13f32.sqrt();
    let l3 = (Vec3::new(3.0, 1.5, 0.5) - p).normalize();
    let want = 0.2 * FLOOR_KD + LC * FLOOR_KD * ndl1 + Vec3::new(0.0, 0.2, 0.0) * FLOOR_KD * l3.y;
    let got = render_pixel(&s, &settings(ShadowMode::Hard, 5), 0);
    assert_close(got, want, "two lights");
}

#[test]
fn camera_rays_follow_the_lab_pixel_mapping() {
    // x = (i + 0.5 − w/2)/max(w, h) + 0.5, y likewise with j counted from the bottom; the
    // square [0,1]² spans the full field of view.
    let camera = Camera {
        position: Vec3::new(1.0, 2.0, 3.0),
        point_of_interest: Vec3::new(1.0, 2.0, -1.0),
        up: Vec3::Y,
        fov: 40f32.to_radians(),
    };
    let half = 20f32.to_radians().tan();
    for (w, h) in [(1u32, 1u32), (4, 4), (5, 3), (3, 7)] {
        let rays = CameraRays::new(&camera, w, h);
        for row in 0..h {
            for i in 0..w {
                let j = h - 1 - row;
                let m = w.max(h) as f32;
                let x = (i as f32 + 0.5 - w as f32 / 2.0) / m + 0.5;
                let y = (j as f32 + 0.5 - h as f32 / 2.0) / m + 0.5;
                // Looking down -z with up +y: right is +x.
                let want =
                    Vec3::new((2.0 * x - 1.0) * half, (2.0 * y - 1.0) * half, -1.0).normalize();
                let (sx, sy) = rays.screen(row * w + i, 0.5, 0.5);
                let r = rays.ray(sx, sy);
                assert_eq!(r.origin, camera.position);
                assert!(
                    r.direction.distance(want) < 1e-6,
                    "{w}x{h} pixel ({i}, row {row}): {} vs {want}",
                    r.direction
                );
            }
        }
    }
}

/// The row walk the wavefront engine generates camera rays with (`CameraRays::rays_of`) gives
/// `sample_ray`'s rays to the bit, in (pixel, sample) order, for ranges that start and end
/// mid-row, on square, wide and tall images, with one and several antialiasing samples.
#[test]
fn the_row_walk_gives_sample_ray_s_rays() {
    let camera = Camera::default();
    for (w, h) in [(1u32, 1u32), (5, 3), (3, 7), (64, 48)] {
        let rays = CameraRays::new(&camera, w, h);
        for samples in [1, 4] {
            for (first, count) in [(0, w * h), (w / 2, w + 1), (w * h - 1, 1), (1, 0)] {
                let mut walked = Vec::new();
                rays.rays_of(first, count, samples, 9, |pixel, sample, d| {
                    walked.push((pixel, sample, d.to_array().map(f32::to_bits)))
                });
                let expected: Vec<_> = (first..first + count)
                    .flat_map(|p| (0..samples).map(move |s| (p, s)))
                    .map(|(p, s)| {
                        let d = rays.sample_ray(p, s, samples, 9).direction;
                        (p, s, d.to_array().map(f32::to_bits))
                    })
                    .collect();
                assert_eq!(walked, expected, "{w}x{h}, {samples} samples, from {first}");
            }
        }
    }
}

/// The wavefront engine's camera kernel (`simd::camera_directions`, 8 and 16 lanes) gives the
/// row walk's directions to the bit at one sample per pixel: rows shorter and longer than a
/// block, ranges that start and end mid-row, and a camera off the axes.
#[test]
fn the_camera_kernel_equals_the_row_walk_at_8_and_16_lanes() {
    use raywave::render::wavefront::lanes::{f32x8, f32x16};
    use raywave::render::wavefront::simd::camera_directions;
    let cameras = [
        Camera::default(),
        Camera {
            position: Vec3::new(3.0, -2.0, 7.5),
            point_of_interest: Vec3::new(0.1, 0.3, -0.2),
            up: Vec3::new(0.2, 1.0, 0.1),
            fov: 55f32.to_radians(),
        },
    ];
    for camera in cameras {
        for (w, h) in [(1u32, 1u32), (5, 3), (7, 9), (8, 2), (17, 5), (64, 48)] {
            let rays = CameraRays::new(&camera, w, h);
            for (first, count) in [
                (0, w * h),
                (w / 2, w + 3),
                (w * h - 1, 1),
                (3.min(w * h), 0),
            ] {
                let count = count.min(w * h - first);
                let mut walked = Vec::new();
                rays.rays_of(first, count, 1, 0, |_, _, d| {
                    walked.push(d.to_array().map(f32::to_bits))
                });
                for lanes in [8, 16] {
                    let n = count as usize;
                    let mut cols = [vec![0.0f32; n], vec![0.0; n], vec![0.0; n]];
                    let [x, y, z] = &mut cols;
                    match lanes {
                        8 => camera_directions::<f32x8>(&rays, first, count, [x, y, z]),
                        _ => camera_directions::<f32x16>(&rays, first, count, [x, y, z]),
                    }
                    let got: Vec<_> = (0..n)
                        .map(|k| [cols[0][k], cols[1][k], cols[2][k]].map(f32::to_bits))
                        .collect();
                    assert_eq!(
                        got, walked,
                        "{w}x{h} from {first}, {count} pixels, {lanes} lanes"
                    );
                }
            }
        }
    }
}

#[test]
fn off_centre_pixel_of_a_larger_image() {
    // A 7 × 5 image; pixel (i = 5, row 1) is computed by the mapping above and intersected with
    // the floor by hand.
    let eye = Vec3::new(0.0, 1.2, 2.5);
    let poi = Vec3::new(0.0, 0.0, 0.0);
    let s = scene(Vec3::ZERO, 0.0, "", "", eye, poi);
    let (w, h) = (7u32, 5u32);
    let (i, row) = (5u32, 1u32);
    let j = h - 1 - row;
    let x = (i as f32 + 0.5 - 3.5) / 7.0 + 0.5;
    let y = (j as f32 + 0.5 - 2.5) / 7.0 + 0.5;
    let f = (poi - eye).normalize();
    let right = f.cross(Vec3::Y).normalize();
    let up = right.cross(f);
    let half = 10f32.to_radians().tan();
    let d = (f + (2.0 * x - 1.0) * half * right + (2.0 * y - 1.0) * half * up).normalize();
    let t = -eye.y / d.y;
    let p = eye + t * d;
    assert!(p.x.abs() < 1.0 && p.z.abs() < 1.0, "{p}");
    let l = (CENTROID - p).normalize();
    let want = 0.2 * FLOOR_KD + LC * FLOOR_KD * l.y;
    let mut st = settings(ShadowMode::Hard, 5);
    st.width = w;
    st.height = h;
    let got = render_pixel(&s, &st, row * w + i);
    assert_close(got, want, "pixel (5, row 1) of 7x5");
}

#[test]
fn floor_seen_from_below_is_invisible_unless_two_sided() {
    // Camera under the floor looking up at p: one-sided, the ray passes through the floor's
    // back and the light's back too, and reaches the background. Two-sided, the floor is hit
    // with its normal flipped towards the camera (-y): the light above is then behind it, so
    // only the ambient term remains.
    let p = Vec3::new(0.3, 0.0, 0.2);
    let eye = Vec3::new(0.3, -1.0, 2.0);
    let s = scene(Vec3::ZERO, 0.0, "", "", eye, p);
    let got = render_pixel(&s, &settings(ShadowMode::Hard, 5), 0);
    assert_close(got, Vec3::new(0.25, 0.5, 0.75), "one-sided from below");
    let mut two = settings(ShadowMode::Hard, 5);
    two.two_sided = true;
    let got = render_pixel(&s, &two, 0);
    assert_close(got, 0.2 * FLOOR_KD, "two-sided from below");
}

#[test]
fn a_light_seen_directly_is_uniform_not_speckled() {
    // Two coplanar lights at y = 1 facing down (like scenes/two_lights.obj), seen from below.
    // For every point on a light, its own sample points and the other light's lie in its plane:
    // n·l = 0 exactly, so Shade is never added and the light shows only its ambient 0.2·kd
    // (docs/SHADING.md: "from its own plane n·l = 0 for its own points").
    //
    // In float arithmetic the hit point is off the plane by a rounding error, n·l comes out as
    // ±1e-8, and whenever it is positive the sample adds Shade = 0.2·ke + (≈ 0) / N: bright
    // random dots on the lights (as scenes/two_lights.obj showed). Both engines now count a
    // light point only when it is more than T_MIN above the surface's tangent plane,
    // `n.dot(to_light) > T_MIN`, instead of `n.dot(l) > 0` (the same 1e-4 the shadow rays use).
    let text = "\
material
diffuse 0.5 0.5 0.5
emitted 20 20 20
v -0.6 1 -0.4
v -0.2 1 -0.4
v -0.2 1 0
v -0.6 1 0
v 0.2 1 0
v 0.6 1 0
v 0.6 1 0.4
v 0.2 1 0.4
m 0
f 1 2 3 4
f 5 6 7 8
PerspectiveCamera {
  camera_position -1.3 -1.7 0.9
  point_of_interest -0.41 1 -0.23
  up 0 0 1
  angle 0.05
}
";
    let s = parse_scene_str(text, "lights.obj").unwrap();
    assert_eq!(s.lights.len(), 2);
    let mut st = settings(ShadowMode::Soft, 5);
    st.width = 24;
    st.height = 24;
    let r = Reference::new(&s, &st);
    let mut speckled = 0;
    for p in 0..24 * 24 {
        let c = r.pixel(p, &mut RayCounts::default(), &mut ());
        // Every ray of this narrow oblique view hits light 0 (0.05 rad: ±0.1 around the poi).
        if (c - Vec3::splat(0.1)).abs().max_element() > 1e-6 {
            speckled += 1;
        }
    }
    assert_eq!(
        speckled, 0,
        "{speckled} of 576 pixels on the light are not 0.2·kd"
    );
}

#[test]
fn no_highlight_when_the_viewer_is_behind_the_mirror_direction() {
    // A glossy floor point near the corner, seen from low down on the light's side: e·r < 0, so
    // max(0, e·r) gives no highlight, where |e·r|^s would add a visible one. The twin tests
    // cannot tell: the wavefront engine's `shade_terms` would make the same mistake if it were
    // made in both.
    let kr = Vec3::new(0.4, 0.5, 0.6);
    let g = 1.0;
    let p = Vec3::new(0.9, 0.0, 0.9);
    let eye = p + 3.0 * Vec3::new(-1.0, 0.05, -1.0);
    let s = scene(kr, g, "", "", eye, p);
    let n = Vec3::Y;
    let e = (eye - p).normalize();
    let l = (CENTROID - p).normalize();
    let r = (2.0 * n.dot(l) * n - l).normalize();
    assert!(e.dot(r) < -0.4, "e·r = {}", e.dot(r));
    let lost_sign = LC * (0.8 * kr) * (-e.dot(r)).powf(5.0 / (g + 0.01)) * n.dot(l);
    assert!(lost_sign.min_element() > 1e-3, "{lost_sign}");
    let want = 0.2 * FLOOR_KD + LC * FLOOR_KD * n.dot(l);
    assert_close(
        want,
        0.2 * FLOOR_KD + shade_by_hand(glossy_floor(kr, g), n, e, l, LC),
        "by hand",
    );
    let got = render_pixel(&s, &settings(ShadowMode::Hard, 0), 0);
    assert_close(
        got,
        want,
        "glossy floor, viewer behind the mirror direction",
    );
}
