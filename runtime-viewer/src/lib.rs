//! Slipgate: surface-cached software renderer for compiled BSPs.
