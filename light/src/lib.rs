//! Slipgate lighting support: a small, safe wrapper around Embree 3 used
//! for visibility (shadow) and nearest-hit ray queries.

pub mod embree;
