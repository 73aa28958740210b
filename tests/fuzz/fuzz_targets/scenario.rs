//! Any bytes parsed as a scenario file, tessellated when small, and read
//! as a `.toml` part
//! (`entry::scenario`, shared with the stable seeded run in the test suite).

#![no_main]

#[allow(dead_code)] // each target calls one of the entry points
#[path = "../entry.rs"]
mod entry;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    entry::scenario(data, entry::FUZZ_MAX_TRIANGLES);
});
