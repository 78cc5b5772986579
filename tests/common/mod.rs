//! Helpers shared by the integration tests (each kind's `tests/KIND/main.rs` declares it with
//! `#[path = "../common/mod.rs"] mod common;`, and its files `use crate::common;`), one file per
//! idea: `rays` (constructors and the edge-case table), `scenes` (bare, bundled and RPI scenes, the
//! bias tests' lights and settings), `analytic` (the closed-form penumbra scene), `strategies`
//! (proptest inputs), `random` (seeded inputs from `rand`), `bin` (running the binary in a
//! scratch directory), `hostile` (the hostile-input catalogue's harness), `view` (`raywave view`
//! on a free port, and raw HTTP requests to it), `slurm` (a single-node Slurm cluster in a temp
//! dir), `gnu_parallel` (a command run once per shard), `skip` (a test that lacks an outside
//! tool: skipped, or failed in CI).
#![allow(dead_code, unused_imports)]

pub mod analytic;
pub mod bin;
pub mod docs;
pub mod gnu_parallel;
pub mod hostile;
pub mod random;
pub mod rays;
pub mod scenes;
pub mod skip;
pub mod slurm;
pub mod strategies;
pub mod view;

pub use random::{Draw, TestRng, seeded};
pub use rays::{edge_rays, ray, triangle};
pub use scenes::{PENTAGON, SQUARE, bundled_scenes, rpi_scenes, scene_of, soft_settings};
