//! kneeform CLI.
fn main() {}
