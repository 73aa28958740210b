//! The integration tests, one binary: helpers in `util`, one module per
//! capability.

mod analytic;
mod architecture;
mod cli;
mod diff;
mod direct;
mod engine;
mod evidence;
mod first_hour;
mod frames;
mod fuzz_seeded;
mod harness;
mod hostile;
mod oracle;
mod readme;
mod report;
mod resolution;
mod second_hour;
mod shard;
mod standalone;
mod surface;
mod util;
mod verdict;
mod view3d;
mod zones;
