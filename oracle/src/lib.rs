//! Exact oracle (placeholder).
