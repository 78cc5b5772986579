//! Any bytes as a saved bench record (`raywave::output::bench_record::load`): an error or a record,
//! never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("raywave-fuzz-record-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join("record.json");
    std::fs::write(&path, data).unwrap();
    let _ = raywave::output::bench_record::load(&path, "record");
});
