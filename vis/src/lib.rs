//! Slipgate: portal-flow potentially visible sets.
