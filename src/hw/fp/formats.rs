//! The `eXmY` formats the hardware operators are instantiated for, and the dispatch from a
//! runtime [`Format`] to the monomorphized modules.
//!
//! The list lives once, in `fp_format_table!`; [`dispatch_fp_format!`] turns it into a `match`
//! that calls a generic function with the const parameters every operator takes, in this order:
//! `W = 1+E+M, E, M, S = M+1, S1 = M+2, X2 = E+2, T = M+5, P = 2(M+1)`.
//! Adding a format is adding a pair to the table (limits: `E >= 4`, `M <= 27`, `W <= 32`).

use crate::fp::{BinOp, Format};

use super::add_sub::ADD_SUB_LATENCY;
use super::compare::COMPARE_LATENCY;
use super::div::div_latency;
use super::mul::MUL_LATENCY;
use super::sqrt::sqrt_latency;

/// The single list of supported formats, as `(exponent bits, mantissa bits)`.
/// Calls `$callback! { $($extra)* ; (E, M) ... }`.
#[macro_export]
#[doc(hidden)]
macro_rules! fp_format_table {
    ($callback:ident ! { $($extra:tt)* }) => {
        $callback! { $($extra)* ;
            (5, 10) (5, 12) (6, 11) (6, 14) (7, 12) (7, 14) (7, 16) (7, 18) (7, 20)
            (8, 16) (8, 18) (8, 20) (8, 23)
        }
    };
}

/// `dispatch_fp_format!(format, func(args...))` calls
/// `func::<W, E, M, S, S1, X2, T, P>(args...)` for the monomorphized instance of `format`
/// and evaluates to `Ok(result)`, or to `Err(UnsupportedFormat)` for a format not in the table.
#[macro_export]
macro_rules! dispatch_fp_format {
    (@arms $fmt:expr, $func:ident, $args:tt ; $(($e:literal, $m:literal))*) => {{
        let format: $crate::fp::Format = $fmt;
        match (format.exp_bits, format.man_bits) {
            $(
                ($e, $m) => Ok($func::<
                    { 1 + $e + $m },
                    $e,
                    $m,
                    { $m + 1 },
                    { $m + 2 },
                    { $e + 2 },
                    { $m + 5 },
                    { 2 * ($m + 1) },
                >$args),
            )*
            _ => Err($crate::hw::fp::UnsupportedFormat(format)),
        }
    }};
    ($fmt:expr, $func:ident ( $($arg:expr),* $(,)? )) => {
        $crate::fp_format_table!(dispatch_fp_format ! { @arms $fmt, $func, ($($arg),*) })
    };
}

macro_rules! format_list {
    ( ; $(($e:literal, $m:literal))*) => {
        &[$(($e, $m)),*]
    };
}

const SUPPORTED: &[(u32, u32)] = fp_format_table!(format_list! {});

/// A format with no hardware instance.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "no floating-point hardware for format {0}; supported formats: {list} \
     (add it to fp_format_table! in src/hw/fp/formats.rs)",
    list = supported_formats().iter().map(|f| f.to_string()).collect::<Vec<_>>().join(", ")
)]
pub struct UnsupportedFormat(pub Format);

/// Every format the hardware operators exist for.
pub fn supported_formats() -> Vec<Format> {
    SUPPORTED
        .iter()
        .map(|&(e, m)| Format::new(e, m).expect("the format table holds valid formats"))
        .collect()
}

/// `Ok(())` if `fmt` has hardware, else the error naming the supported formats.
pub fn check_supported(fmt: Format) -> Result<(), UnsupportedFormat> {
    if SUPPORTED.contains(&(fmt.exp_bits, fmt.man_bits)) {
        Ok(())
    } else {
        Err(UnsupportedFormat(fmt))
    }
}

/// Latency in clocks of the operator computing `op` in `fmt` (from `in_valid` to `out_valid`).
pub fn latency(op: BinOp, fmt: Format) -> u32 {
    match op {
        BinOp::Add | BinOp::Sub => ADD_SUB_LATENCY,
        BinOp::Mul => MUL_LATENCY,
        BinOp::Div => div_latency(fmt.man_bits),
        BinOp::Sqrt => sqrt_latency(fmt.man_bits),
        BinOp::Lt | BinOp::Le | BinOp::Eq => COMPARE_LATENCY,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn widths<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
    >() -> [usize; 8] {
        [W, E, M, S, S1, X2, T, P]
    }

    #[test]
    fn dispatch_passes_the_derived_widths_of_each_format() {
        for f in supported_formats() {
            let (e, m) = (f.exp_bits as usize, f.man_bits as usize);
            let got = dispatch_fp_format!(f, widths()).unwrap();
            assert_eq!(
                got,
                [1 + e + m, e, m, m + 1, m + 2, e + 2, m + 5, 2 * (m + 1)],
                "{f}"
            );
        }
    }

    #[test]
    fn the_formats_the_studies_need_are_supported() {
        for name in [
            "e5m10", "e6m11", "e7m12", "e7m14", "e7m16", "e8m16", "e7m18", "e8m20", "e8m23",
            "e5m12", "e6m14", "e8m18",
        ] {
            let f = Format::parse(name).unwrap();
            assert!(check_supported(f).is_ok(), "{name}");
        }
    }

    #[test]
    fn unsupported_format_error_lists_the_supported_ones() {
        let f = Format::parse("e6m10").unwrap();
        let err = dispatch_fp_format!(f, widths()).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.contains("e6m10") && msg.contains("e7m16") && msg.contains("e8m23"),
            "{msg}"
        );
    }
}
