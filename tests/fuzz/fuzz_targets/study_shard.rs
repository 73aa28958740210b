//! Any bytes read as a study shard (`shard.json`, a NUL byte, `shard.bin`),
//! resealed and checked as `merge` checks it (`entry::study_shard`, shared
//! with the stable seeded run in the test suite).

#![no_main]

#[allow(dead_code)] // each target calls one of the entry points
#[path = "../entry.rs"]
mod entry;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    entry::study_shard(data);
});
