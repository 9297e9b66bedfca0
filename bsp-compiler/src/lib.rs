//! Slipgate: .map to BSP29/BSP2 compiler.
