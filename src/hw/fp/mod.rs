//! The `eXmY` floating-point operators as fully pipelined rust-hdl hardware.
//!
//! One file per operator: [`FpAddSub`] (add and subtract), [`FpMul`], [`FpDiv`], [`FpSqrt`]
//! (the one unary operator: no `b` port) and [`FpCompare`] (`lt`, `le`, `eq`). Each accepts a
//! new operation every clock and delivers it a fixed number of clocks later (see [`latency`]),
//! with a `valid` bit travelling alongside.
//! Results equal `dynrt::fp` bit for bit (round to nearest even, subnormals flushed on input and
//! output with tininess detected after rounding, overflow to infinity, one canonical quiet NaN).
//!
//! rust-hdl widths are types, and stable Rust has no const-generic arithmetic, so every module is
//! generic over its word width and the derived internal widths (checked in its constructor), and
//! format-dependent offsets and masks are `Constant` fields (Verilog localparams). The table in
//! [`formats`] lists the supported formats with their derived widths; `dispatch_fp_format!`
//! dispatches from a runtime [`Format`](crate::fp::Format) to the monomorphized instance.
//!
//! Latencies (clocks from `in_valid` to `out_valid`): add/sub 7, mul 4, div and sqrt `M + 5`
//! (e7m16: 21, e8m23: 28), compare 2. Every stage is at most about 7 LUT4 levels deep after
//! `synth_xilinx -family xc2v` (the final rounding and the range check/packing are separate
//! stages for that reason).
//!
//! Using an operator inside another unit: make the unit generic over the same const parameters
//! (`W, E, M, S, S1, X2, T, P`, see [`formats`]), instantiate e.g.
//! `FpMul::<W, E, M, S, S1, X2, P>::default()` as a field, drive `clock`, `in_valid`, `a`, `b`
//! (and `sub`) from the kernel, and delay side data by the operator's latency. The unit's own
//! entry point then goes through `dispatch_fp_format!` once, like `crate::emit::fp_unit_rtl`.
//!
//! Golden twins (src/fp/arith.rs, src/fp/format.rs): [`FpAddSub`] is `Format::add` / `sub`,
//! [`FpMul`] `Format::mul`, [`FpDiv`] `Format::div`, [`FpSqrt`] `Format::sqrt`, [`FpCompare`]
//! `Format::lt` / `le` / `eq`, [`FpRoundPack`] `Format::round_pack`; each of those names its
//! operator back.

pub mod add_sub;
pub mod compare;
pub mod div;
pub mod formats;
pub mod mul;
pub mod round_pack;
pub mod sig_mul;
pub mod sqrt;
#[cfg(test)]
pub(crate) mod test_harness;

pub use add_sub::FpAddSub;
pub use compare::FpCompare;
pub use div::FpDiv;
pub use formats::{check_supported, latency, supported_formats, UnsupportedFormat};
pub use mul::FpMul;
pub use round_pack::FpRoundPack;
pub use sig_mul::SigMul;
pub use sqrt::FpSqrt;

use rust_hdl::prelude::*;

/// An 8-bit constant used as a bit index or shift amount inside kernels.
pub(crate) fn const_index(n: usize) -> Constant<Bits<8>> {
    assert!(n < 256);
    Constant::new((n as u64).into())
}

/// A `N`-bit constant.
pub(crate) fn const_bits<const N: usize>(v: u64) -> Constant<Bits<N>> {
    assert!(
        N >= 64 || v >> N == 0,
        "constant {v:#x} does not fit in {N} bits"
    );
    Constant::new(v.into())
}

/// Exponent bias `2^(E-1) - 1`.
pub(crate) fn bias(e: usize) -> u64 {
    (1u64 << (e - 1)) - 1
}

/// The canonical quiet NaN: sign 0, exponent all ones, mantissa `100..0`.
pub(crate) fn qnan_word(e: usize, m: usize) -> u64 {
    (((1u64 << e) - 1) << m) | (1u64 << (m - 1))
}

/// Positive infinity: exponent all ones, mantissa zero.
pub(crate) fn inf_word(e: usize, m: usize) -> u64 {
    ((1u64 << e) - 1) << m
}
