//! Result files: CSV, STL and PNG (being written).
