//! kneeform engine.
