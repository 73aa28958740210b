//! The integration tests, one binary: helpers in `util`, one module per
//! capability.

mod analytic;
mod cli;
mod engine;
mod oracle;
mod util;
