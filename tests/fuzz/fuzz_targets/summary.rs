//! Any bytes read as a `summary.json`, its grid placed as `kneeform report` does
//! (`entry::summary`, shared with the stable seeded run in the test suite).

#![no_main]

#[allow(dead_code)] // each target calls one of the entry points
#[path = "../entry.rs"]
mod entry;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    entry::summary(data);
});
