//! Vector loops compiled three times: for any x86-64 (the build's baseline, SSE2), for AVX2 and
//! for AVX-512, the widest one the CPU runs chosen when light runs. Every build does the same
//! operations in the same order (Rust never fuses a multiply and an add on its own), so their
//! answers agree bit for bit; AVX2 does four doubles or eight floats at once where SSE2 does
//! two or four, AVX-512 twice as many again, and its mask registers take the comparisons and
//! selects the loops are written with.

/// The vector builds of [`widest`], narrowest first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Build {
    /// The baseline every x86-64 runs.
    Any,
    Avx2,
    /// AVX-512 with the extensions every CPU with it since 2017 has: `F`, `VL`, `BW`, `DQ`.
    Avx512,
}

/// The widest build this CPU runs (the standard library asks the CPU once and keeps the
/// answer).
fn widest_build() -> Build {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        if has!("avx512f") && has!("avx512vl") && has!("avx512bw") && has!("avx512dq") {
            return Build::Avx512;
        }
        if has!("avx2") {
            return Build::Avx2;
        }
    }
    Build::Any
}

/// `work()`, built for the widest vectors this CPU runs ([`widest_build`]). Callers pass an
/// `#[inline(always)]` closure calling an `#[inline(always)]` function that holds the loops:
/// both are inlined into each build, which widens them (a closure left out of line would run
/// as the baseline in every build).
#[inline(always)]
pub fn widest<R>(work: impl FnOnce() -> R) -> R {
    in_build(widest_build(), work)
}

/// `work()` as `build` compiles it. The CPU must run `build`: only [`widest`] and tests holding
/// the builds to one answer ([`builds_here`]) call it.
#[inline(always)]
fn in_build<R>(build: Build, work: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    match build {
        // SAFETY: the CPU runs AVX-512 (F, VL, BW, DQ), the features `in_avx512` is built for.
        Build::Avx512 => return unsafe { in_avx512(work) },
        // SAFETY: the CPU runs AVX2, the one feature `in_avx2` is built for.
        Build::Avx2 => return unsafe { in_avx2(work) },
        Build::Any => {}
    }
    work()
}

/// `work()` compiled with AVX2 enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn in_avx2<R>(work: impl FnOnce() -> R) -> R {
    work()
}

/// `work()` compiled with AVX-512 enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl,avx512bw,avx512dq")]
fn in_avx512<R>(work: impl FnOnce() -> R) -> R {
    work()
}

/// `work()` as each build this CPU runs compiles it, narrowest first, with the build: for tests
/// that hold every build to one answer.
#[cfg(test)]
pub fn builds_here<R>(work: impl Fn() -> R) -> Vec<(Build, R)> {
    [Build::Any, Build::Avx2, Build::Avx512]
        .into_iter()
        .filter(|&b| b <= widest_build())
        .map(|b| (b, in_build(b, &work)))
        .collect()
}
