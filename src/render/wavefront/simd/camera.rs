//! Camera rays N at a time: the directions through pixel centres (one sample per pixel), lane k
//! of a block the direction `CameraRays::rays_of` gives pixel `i + k`, with the same operations
//! in the same order (the row's y and the column's x from `screen_at`'s formula, then `ray`'s
//! sum and glam's `normalize`: the dot product, one square root, one division, three products).

use crate::render::camera::CameraRays;
use crate::render::wavefront::lanes::Lanes;

/// Writes the directions of the camera rays through the centres of pixels
/// `first..first + count` into `out` (x, y, z columns, `count` long), N pixels at a time along
/// each row: bit-equal to `rays_of(first, count, 1, ..)`'s directions.
pub fn camera_directions<V: Lanes>(
    camera: &CameraRays,
    first: u32,
    count: u32,
    out: [&mut [f32]; 3],
) {
    let [ox, oy, oz] = out;
    let (width, height) = (camera.width, camera.height);
    let scale = camera.scale();
    let [fx, fy, fz] = camera.forward.to_array().map(V::splat);
    let [rx, ry, rz] = camera.right.to_array().map(V::splat);
    let [ux, uy, uz] = camera.up.to_array().map(V::splat);
    // screen_at's x = (column + 0.5 − 0.5·w)·scale + 0.5, lane by lane.
    let half_w = V::splat(0.5 * width as f32);
    let (two, one, half, scale_v) = (V::splat(2.0), V::ONE, V::splat(0.5), V::splat(scale));
    let (mut pixel, end) = (first, first + count);
    while pixel < end {
        let (column, from_top) = (pixel % width, pixel / width);
        let run = (width - column).min(end - pixel);
        // The row's y, as `screen_at` computes it, and `ray`'s 2y − 1.
        let (_, y) = camera.screen_at(column, height - 1 - from_top, 0.5, 0.5, scale);
        let b = V::splat(2.0 * y - 1.0);
        let mut j = 0;
        while j < run {
            let live = ((run - j) as usize).min(V::N);
            // column + j + k is below 2^24 (an image's width), so the sum is exact.
            let c = V::splat((column + j) as f32) + V::LANE_INDEX;
            let x = (c + half - half_w) * scale_v + half;
            let a = two * x - one;
            // forward + a·right + b·up, summed left to right as glam's `Vec3` ops are.
            let dx = fx + a * rx + b * ux;
            let dy = fy + a * ry + b * uy;
            let dz = fz + a * rz + b * uz;
            // glam's normalize: self · (1 / sqrt((x·x + y·y) + z·z)).
            let r = one / (dx * dx + dy * dy + dz * dz).sqrt();
            let k = (pixel - first + j) as usize;
            for (col, v) in [(&mut *ox, dx * r), (&mut *oy, dy * r), (&mut *oz, dz * r)] {
                col[k..k + live].copy_from_slice(&v.to_array().as_ref()[..live]);
            }
            j += live as u32;
        }
        pixel += run;
    }
}
