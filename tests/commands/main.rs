//! Command tests: the built binary run as a user runs it: the command line and its errors, the
//! start-up CPU check (under QEMU), `bench` (records, verdicts, A/B), `diff`, `trace-pixel` and its exports (on
//! scenes/trace_demo.obj, `trace_demo/`), `view` over HTTP, in a browser and its page's modules
//! under node, the JSON Schemas of its output, every command the documentation shows, and the
//! batch systems that run a sharded study (`batch_*`: a real Slurm cluster, GNU parallel, the
//! Kubernetes Jobs of docs/scaling/). One test binary; each file is a module (docs/TESTING.md).

#[path = "../common/mod.rs"]
mod common;
mod trace_demo;

mod batch_k8s;
mod batch_parallel;
mod batch_slurm;
mod bench_ab;
mod bench_cmd;
mod bench_shards;
mod bench_trackers;
mod bench_verdict;
mod cli;
mod cli_errors;
mod cost_map;
mod cpu_check;
mod diff;
mod docs_commands;
mod schema;
mod textures;
mod trace_pixel;
mod trace_pixel_exports;
mod variance_shards;
mod view_browser;
mod view_http;
mod view_jobs;
mod view_js;
mod view_load;
mod view_token;
