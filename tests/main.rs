//! The integration tests, one binary: helpers in `util`, one module per
//! capability.

mod engine;
mod util;
