//! Any bytes read as an analysis shard's `shard.json`, resealed and checked as `merge` checks it
//! (`entry::shard_json`, shared with the stable seeded run in the test suite).

#![no_main]

#[allow(dead_code)] // each target calls one of the entry points
#[path = "../entry.rs"]
mod entry;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    entry::shard_json(data);
});
