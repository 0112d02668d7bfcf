//! Run-time choice of instruction set for the two hot loops of the build
//! (the insertion and the BRIO keys).
//!
//! The crate is compiled for the target's baseline (for x86_64, SSE2), so
//! that its binaries run on any CPU of the target. The hot loops are also
//! compiled a second time, for x86-64-v3 (AVX2, FMA, BMI1/2, LZCNT,
//! POPCNT; every x86_64 CPU since 2013–2015), through
//! `#[target_feature]`, and the build runs that copy when the CPU has the
//! features. Both copies come from the same source and give the same
//! result bit for bit: Rust never fuses or reorders floating-point
//! operations, whatever the target features (no FMA instruction is
//! emitted unless `mul_add` is called, and the crate never calls it on
//! these paths). The v3 copy executes about 13% fewer instructions on the
//! 50³ grid and 8.5% fewer on uniform points (BENCHMARKS.md).

/// Instruction sets the build's hot loops can run on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Isa {
    /// The best the CPU offers, detected at run time.
    Detect,
    /// The target's baseline only (what the crate is compiled for): tests
    /// compare it with [`Isa::Detect`].
    #[cfg_attr(not(test), allow(dead_code))]
    Baseline,
}

impl Isa {
    /// Whether to run the x86-64-v3 copies: asked for, and the CPU has
    /// them.
    pub(crate) fn use_v3(self) -> bool {
        self == Isa::Detect && has_v3()
    }
}

/// Whether the CPU has every x86-64-v3 feature that the `#[target_feature]`
/// copies enable (`avx2,fma,bmi1,bmi2,lzcnt,popcnt`; AVX2 implies AVX and
/// the SSE levels). The answer is cached by the standard library.
pub(crate) fn has_v3() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        is_x86_feature_detected!("avx2")
            && is_x86_feature_detected!("fma")
            && is_x86_feature_detected!("bmi1")
            && is_x86_feature_detected!("bmi2")
            && is_x86_feature_detected!("lzcnt")
            && is_x86_feature_detected!("popcnt")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}
