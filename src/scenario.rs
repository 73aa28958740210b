//! Synthetic height-field parts (being written).
