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

/// The value of `$avx2`, a call of a copy built with `#[target_feature(enable = "avx2")]`, when
/// the CPU runs AVX2 (returned from the calling function), else of `$any`, the same work as
/// built: the tail of a function that dispatches to its two copies.
macro_rules! avx2_or {
    ($avx2:expr, $any:expr) => {{
        #[cfg(target_arch = "x86_64")]
        if $crate::simd::has_avx2() {
            // SAFETY: the CPU runs AVX2, the one feature the called copy is built for.
            return unsafe { $avx2 };
        }
        $any
    }};
}
pub(crate) use avx2_or;
