//! Kernel tests: the scalar kernels (intersection, shadow-caster culling, spawn offsets, shading,
//! film) against values worked out by hand, and their twins (the wavefront engine's 8- and
//! 16-lane kernels, the mesh BVH's leaves and traversal, the peer engines) against the scalar
//! kernels or brute force, ray by ray and bit for bit. One test binary; each file is a module
//! (docs/TESTING.md).

#[path = "../common/mod.rs"]
mod common;

mod bvh_leaves;
mod film;
mod hit_rays;
mod intersection;
mod mesh_bvh;
// The peer engines live with their benchmark; these tests check them and use part of them.
#[allow(dead_code)]
#[path = "../../benches/mesh_rays/peer/mod.rs"]
mod peer;
mod peer_agreement;
mod point_set_lanes;
mod shading_pixels;
mod shadow_casters;
mod spawn;
mod texels;
mod traversal_counts;
mod wavefront_kernels;
