//! Vector loops compiled twice: for any x86-64 (the build's baseline, SSE2) and for AVX2, the
//! wider one chosen when light runs on a CPU that has it. Both do the same operations in the
//! same order (Rust never fuses a multiply and an add on its own), so their answers agree bit
//! for bit; AVX2 does four doubles or eight floats at once where SSE2 does two or four.

/// Whether this CPU runs AVX2 (the standard library asks the CPU once and keeps the answer).
pub fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
