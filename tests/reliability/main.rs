//! Reliability tests: the hostile-input and hostile-output catalogue (docs/RELIABILITY.md) for
//! scenes, flags, outputs, bench records and the variance cache, each case checking the exit
//! code, the message, no panic, no hang and that nothing changed it should not; and SIGINT or
//! SIGTERM at any phase. One test binary; each file is a module (docs/TESTING.md).

#[path = "../common/mod.rs"]
mod common;

mod hostile;
mod hostile_all_or_none;
mod hostile_cache;
mod hostile_flags;
mod hostile_inputs;
mod hostile_outputs;
mod hostile_outputs_commands;
mod hostile_outputs_textures;
mod hostile_records;
mod hostile_shards;
mod interrupt;
