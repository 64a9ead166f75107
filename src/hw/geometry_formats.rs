//! Dispatch from a runtime [`Format`](crate::fp::Format) to the monomorphized geometry units
//! (transform, intersection, ray generation).
//!
//! They take the operators' eight const parameters (see `crate::hw::fp::formats`) plus
//! `DL`, the divider latency (`div_latency(M)`), which sizes the delay lines that carry operands
//! past the divider; Rust cannot derive it from `M` inside a generic. The format list is the
//! operators' own table (`fp_format_table!`), so a format has geometry units exactly when it has
//! operators.

/// `dispatch_geometry_format!(format, func(args...))` calls
/// `func::<W, E, M, S, S1, X2, T, P, DL>(args...)` for `format` and evaluates to `Ok(result)`,
/// or to `Err(UnsupportedFormat)` for a format without hardware.
#[macro_export]
macro_rules! dispatch_geometry_format {
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
                    { $crate::hw::fp::div::div_latency($m) as usize },
                >$args),
            )*
            _ => Err($crate::hw::fp::UnsupportedFormat(format)),
        }
    }};
    ($fmt:expr, $func:ident ( $($arg:expr),* $(,)? )) => {
        $crate::fp_format_table!(dispatch_geometry_format ! { @arms $fmt, $func, ($($arg),*) })
    };
}
