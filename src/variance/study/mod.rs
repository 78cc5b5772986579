//! The study as work: its cases and identity (the sharded work of `raywave variance --shard`),
//! the study file, the jobs and how each is run, a job's result as a part keeps it, and the
//! cache of converged references.

pub mod cache;
pub mod job_record;
pub mod jobs;
pub mod plan;
pub mod study_file;
