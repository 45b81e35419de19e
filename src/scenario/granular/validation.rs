//! Granular validation cases.
