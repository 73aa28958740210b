//! Any bytes read as a `kneeform batch` manifest, its items planned as
//! `batch` plans them (`entry::manifest`, shared with the stable seeded run
//! in the test suite).

#![no_main]

#[allow(dead_code)] // each target calls one of the entry points
#[path = "../entry.rs"]
mod entry;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    entry::manifest(data);
});
