//! Rays and triangles for the kernel tests: constructors from arrays and the edge-case table.

use glam::Vec3;
use raywave::render::geometry::Ray;
use raywave::render::scene::Triangle;

const NAN: f32 = f32::NAN;
const INF: f32 = f32::INFINITY;

/// The triangle v0 v1 v2 (front side counter-clockwise), material 0; a degenerate one gets a
/// zero normal (the kernels never read it).
pub fn triangle(v0: Vec3, v1: Vec3, v2: Vec3) -> Triangle {
    let (e1, e2) = (v1 - v0, v2 - v0);
    Triangle {
        v0,
        e1,
        e2,
        normal: e1.cross(e2).normalize_or_zero(),
        material: 0,
        face: 0,
    }
}

/// A ray from arrays.
pub fn ray(origin: [f32; 3], direction: [f32; 3]) -> Ray {
    Ray {
        origin: Vec3::from_array(origin),
        direction: Vec3::from_array(direction),
    }
}

/// Rays chosen to sit on the kernels' edges for the unit triangle (0,0,0) (1,0,0) (0,1,0),
/// whose front faces +z, and the unit sphere at the origin: the one table for the 8-wide
/// kernels, the BVH's leaf kernels and the batch entry points.
pub fn edge_rays() -> Vec<Ray> {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    vec![
        ray([0.25, 0.25, 1.0], [0.0, 0.0, -1.0]), // axis-aligned, straight through
        ray([0.25, 0.25, -1.0], [0.0, 0.0, 1.0]), // from behind
        ray([0.25, 0.25, 0.0], [0.0, 0.0, -1.0]), // starting on the surface
        ray([0.25, 0.25, 5e-5], [0.0, 0.0, -1.0]), // close above the surface
        ray([0.25, 0.25, 2e-4], [0.0, 0.0, -1.0]), // just past the lab's 1e-4 offset
        ray([0.25, 0.25, 1e-30], [0.0, 0.0, -1.0]), // a tiny distance above
        ray([-1.0, 0.25, 0.0], [1.0, 0.0, 0.0]),  // grazing, in the plane
        ray([-1.0, 0.25, 1e-7], [1.0, 0.0, -1e-7]), // nearly grazing
        ray([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]),   // through a corner
        ray([0.5, 0.5, 1.0], [0.0, 0.0, -1.0]),   // through the hypotenuse
        ray([1.0, 0.0, 1.0], [0.0, 0.0, -1.0]),   // another corner
        ray([0.5, -0.0, 1.0], [-0.0, 0.0, -1.0]), // −0.0 on an edge
        ray([0.25, 0.25, 1.0], [-0.0, -0.0, -1.0]), // −0.0 direction components
        ray([NAN, 0.25, 1.0], [0.0, 0.0, -1.0]),  // NaN origin
        ray([0.25, 0.25, 1.0], [0.0, NAN, -1.0]), // NaN direction
        ray([INF, 0.25, 1.0], [0.0, 0.0, -1.0]),  // infinite origin
        ray([0.25, 0.25, 1.0], [0.0, 0.0, -INF]), // infinite direction
        ray([0.25, 0.25, 1.0], [0.0, 0.0, 0.0]),  // zero direction
        ray([0.0, 0.0, 3.0], [0.0, 0.0, -1.0]),   // sphere: through the centre
        ray([0.0, 0.0, 0.0], [s, s, 0.0]),        // sphere: from the centre
        ray([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),    // sphere: tangent, on the surface
        ray([1.0, 0.0, 0.0], [1.0, 0.0, 0.0]),    // sphere: leaving from the surface
        ray([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),   // sphere: entering from the surface
        ray([1.0, -2.0, 0.0], [0.0, 1.0, 0.0]),   // sphere: grazing
        ray([0.25, 0.25, 1e30], [0.0, 0.0, -1.0]), // far away
        ray([0.25, 0.25, 1.0], [0.0, 0.0, -1e-30]), // tiny direction
        ray([1.0, 1.0, 1.0], [-0.57735, -0.57735, -0.57735]), // diagonal, at the third vertex
    ]
}
