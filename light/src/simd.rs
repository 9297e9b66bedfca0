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

/// `work()`, built for AVX2 and run so when the CPU has it, else as the build targets. Callers
/// pass an `#[inline(always)]` closure calling an `#[inline(always)]` function that holds the
/// loops: both are inlined into the AVX2 copy, which widens them (a closure left out of line
/// would run as the build targets in either copy).
#[inline(always)]
pub fn avx2_or_any<R>(work: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: the CPU runs AVX2, the one feature `in_avx2` is built for.
        return unsafe { in_avx2(work) };
    }
    work()
}

/// `work()` compiled with AVX2 enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn in_avx2<R>(work: impl FnOnce() -> R) -> R {
    work()
}
