//! The `eXmY` floating-point number format and its exact software arithmetic.
//!
//! Contract (docs/ARCHITECTURE.md, "Number format"): sign, X exponent bits (bias 2^(X-1)-1), Y stored mantissa
//! bits with a hidden 1. Round to nearest, ties to even. Subnormal inputs and results are
//! flushed to zero keeping the sign, with tininess detected *after* rounding (the result is
//! rounded to Y+1 significant bits with an unbounded exponent, and flushed when that rounded
//! value is below the smallest normal; this is what x86 SSE does with FTZ and DAZ set).
//! Overflow gives infinity; invalid operations give the one canonical quiet NaN (sign 0,
//! exponent all ones, mantissa 10...0); infinities and signed zeros follow IEEE 754.
//! With `e8m23` every operation equals IEEE binary32 with flush-to-zero.
//!
//! A value is carried as a `u32` word holding the format's `1 + X + Y` bits right-aligned.
//! Supported formats: 2 <= X <= 8 (so the exponent range fits IEEE binary32's, which keeps
//! every conversion exact through f64) and 1 <= Y <= 23.

mod arith;
mod format;
pub mod vectors;

pub use arith::BinOp;
pub use format::{Format, FormatError};

#[cfg(test)]
mod tests;
