//! The `eXmY` format descriptor: field widths, special values, parsing and conversions.

use std::fmt;
use std::str::FromStr;

/// An `eXmY` floating-point format: 1 sign bit, `exp_bits` exponent bits, `man_bits` stored
/// mantissa bits. Words are `u32`, right-aligned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Format {
    pub exp_bits: u32,
    pub man_bits: u32,
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "invalid number format `{text}`: {reason}; expected eXmY such as e7m16 \
     (X exponent bits {min_e}..={max_e}, Y mantissa bits {min_m}..={max_m})",
    min_e = Format::MIN_EXP_BITS,
    max_e = Format::MAX_EXP_BITS,
    min_m = Format::MIN_MAN_BITS,
    max_m = Format::MAX_MAN_BITS
)]
pub struct FormatError {
    pub text: String,
    pub reason: String,
}

/// A word split into its meaning, after flushing subnormal inputs to zero.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Unpacked {
    Zero {
        sign: bool,
    },
    Inf {
        sign: bool,
    },
    NaN,
    /// value = (-1)^sign * sig * 2^(exp - man_bits), sig has its hidden bit set.
    Normal {
        sign: bool,
        exp: i32,
        sig: u64,
    },
}

impl Format {
    pub const MIN_EXP_BITS: u32 = 2;
    pub const MAX_EXP_BITS: u32 = 8;
    pub const MIN_MAN_BITS: u32 = 1;
    pub const MAX_MAN_BITS: u32 = 23;

    /// The paper's 24-bit format and dynrt's default.
    pub const E7M16: Format = Format {
        exp_bits: 7,
        man_bits: 16,
    };
    /// IEEE binary32 (with flush-to-zero).
    pub const E8M23: Format = Format {
        exp_bits: 8,
        man_bits: 23,
    };
    /// IEEE binary16 field layout (with flush-to-zero).
    pub const E5M10: Format = Format {
        exp_bits: 5,
        man_bits: 10,
    };

    pub fn new(exp_bits: u32, man_bits: u32) -> Result<Format, FormatError> {
        let text = format!("e{exp_bits}m{man_bits}");
        if !(Self::MIN_EXP_BITS..=Self::MAX_EXP_BITS).contains(&exp_bits) {
            return Err(FormatError {
                text,
                reason: format!("{exp_bits} exponent bits is out of range"),
            });
        }
        if !(Self::MIN_MAN_BITS..=Self::MAX_MAN_BITS).contains(&man_bits) {
            return Err(FormatError {
                text,
                reason: format!("{man_bits} mantissa bits is out of range"),
            });
        }
        Ok(Format { exp_bits, man_bits })
    }

    /// Parses `eXmY` (case-insensitive).
    pub fn parse(text: &str) -> Result<Format, FormatError> {
        let err = |reason: &str| FormatError {
            text: text.to_string(),
            reason: reason.to_string(),
        };
        let lower = text.trim().to_ascii_lowercase();
        let rest = lower
            .strip_prefix('e')
            .ok_or_else(|| err("it must start with `e`"))?;
        let (x, y) = rest
            .split_once('m')
            .ok_or_else(|| err("it must contain `m`"))?;
        let digits =
            |s: &str| !s.is_empty() && s.len() <= 3 && s.bytes().all(|b| b.is_ascii_digit());
        if !digits(x) || !digits(y) {
            return Err(err("the field widths must be decimal numbers"));
        }
        Format::new(x.parse().unwrap(), y.parse().unwrap()).map_err(|e| FormatError {
            text: text.to_string(),
            ..e
        })
    }

    /// Total width in bits: 1 + X + Y.
    pub fn width(self) -> u32 {
        1 + self.exp_bits + self.man_bits
    }
    /// Number of hex digits of one word.
    pub fn hex_digits(self) -> usize {
        self.width().div_ceil(4) as usize
    }
    pub fn word_mask(self) -> u32 {
        if self.width() == 32 {
            u32::MAX
        } else {
            (1 << self.width()) - 1
        }
    }
    pub fn bias(self) -> i32 {
        (1 << (self.exp_bits - 1)) - 1
    }
    /// Largest unbiased exponent of a finite value.
    pub fn emax(self) -> i32 {
        self.bias()
    }
    /// Smallest unbiased exponent of a normal value.
    pub fn emin(self) -> i32 {
        1 - self.bias()
    }
    pub(crate) fn exp_field_max(self) -> u32 {
        (1 << self.exp_bits) - 1
    }
    pub(crate) fn man_mask(self) -> u32 {
        (1 << self.man_bits) - 1
    }
    pub(crate) fn sign_mask(self) -> u32 {
        1 << (self.exp_bits + self.man_bits)
    }

    pub fn zero(self, sign: bool) -> u32 {
        if sign {
            self.sign_mask()
        } else {
            0
        }
    }
    pub fn infinity(self, sign: bool) -> u32 {
        self.zero(sign) | (self.exp_field_max() << self.man_bits)
    }
    /// The one canonical quiet NaN: sign 0, exponent all ones, mantissa 10...0.
    pub fn nan(self) -> u32 {
        (self.exp_field_max() << self.man_bits) | (1 << (self.man_bits - 1))
    }
    pub fn max_finite(self, sign: bool) -> u32 {
        self.zero(sign) | ((self.exp_field_max() - 1) << self.man_bits) | self.man_mask()
    }
    pub fn min_normal(self, sign: bool) -> u32 {
        self.zero(sign) | (1 << self.man_bits)
    }
    pub fn one(self) -> u32 {
        (self.bias() as u32) << self.man_bits
    }

    pub fn sign_of(self, w: u32) -> bool {
        w & self.sign_mask() != 0
    }
    pub fn exp_field(self, w: u32) -> u32 {
        (w >> self.man_bits) & self.exp_field_max()
    }
    pub fn man_field(self, w: u32) -> u32 {
        w & self.man_mask()
    }
    /// True for any NaN encoding (not only the canonical one).
    pub fn is_nan(self, w: u32) -> bool {
        self.exp_field(w) == self.exp_field_max() && self.man_field(w) != 0
    }
    pub fn is_inf(self, w: u32) -> bool {
        self.exp_field(w) == self.exp_field_max() && self.man_field(w) == 0
    }
    /// Zero or a subnormal encoding (which reads as zero).
    pub fn is_zero(self, w: u32) -> bool {
        self.exp_field(w) == 0
    }

    pub(crate) fn unpack(self, w: u32) -> Unpacked {
        let sign = self.sign_of(w);
        let e = self.exp_field(w);
        let m = self.man_field(w);
        if e == 0 {
            Unpacked::Zero { sign }
        } else if e == self.exp_field_max() {
            if m == 0 {
                Unpacked::Inf { sign }
            } else {
                Unpacked::NaN
            }
        } else {
            Unpacked::Normal {
                sign,
                exp: e as i32 - self.bias(),
                sig: u64::from(m | (1 << self.man_bits)),
            }
        }
    }

    /// Rounds the exact value `(-1)^sign * (sig + s) * 2^exp2` to the format, where `s` is 0
    /// when `sticky` is false and some unknown fraction in (0, 1) when it is true.
    ///
    /// Callers that set `sticky` must pass a `sig` of at least `man_bits + 2` bits so the lost
    /// bits lie strictly below the rounding position. Rounding is to nearest, ties to even, to
    /// `man_bits + 1` significant bits with an unbounded exponent; then a result below the
    /// smallest normal flushes to zero (tininess after rounding) and one above the largest
    /// finite value becomes infinity.
    ///
    /// Golden twin of [`hw::fp::FpRoundPack`](crate::hw::fp::FpRoundPack)
    /// (src/hw/fp/round_pack.rs), the last two stages of the multiplier and the divider.
    pub(crate) fn round_pack(self, sign: bool, sig: u128, exp2: i32, sticky: bool) -> u32 {
        // Keep 64 bits and fold the rest into the sticky bit: 64 bits are far more than the
        // man_bits + 2 that rounding needs, and the u64 path is several times faster.
        match u64::try_from(sig) {
            Ok(small) => self.round_pack64(sign, small, exp2, sticky),
            Err(_) => {
                let shift = 64 - sig.leading_zeros();
                let lost = sig & ((1u128 << shift) - 1) != 0;
                self.round_pack64(
                    sign,
                    (sig >> shift) as u64,
                    exp2 + shift as i32,
                    sticky || lost,
                )
            }
        }
    }

    /// [`Format::round_pack`] for significands that fit 64 bits.
    pub(crate) fn round_pack64(self, sign: bool, sig: u64, exp2: i32, sticky: bool) -> u32 {
        if sig == 0 {
            debug_assert!(
                !sticky,
                "sticky bits below a zero significand are meaningless"
            );
            return self.zero(sign);
        }
        let precision = self.man_bits + 1;
        let len = 64 - sig.leading_zeros();
        debug_assert!(
            !sticky || len > precision,
            "sticky needs bits below the rounding position"
        );
        let (mut kept, mut exp) = if len > precision {
            let shift = len - precision;
            let kept = sig >> shift;
            let rem = sig & ((1u64 << shift) - 1);
            let half = 1u64 << (shift - 1);
            let up = rem > half || (rem == half && (sticky || kept & 1 == 1));
            (kept + u64::from(up), exp2 + shift as i32)
        } else {
            (
                (sig as u64) << (precision - len),
                exp2 - (precision - len) as i32,
            )
        };
        if kept == 1 << precision {
            kept >>= 1;
            exp += 1;
        }
        // `exp` now weighs the lsb of `kept`; the value's unbiased exponent is exp + man_bits.
        let e = exp + self.man_bits as i32;
        if e > self.emax() {
            self.infinity(sign)
        } else if e < self.emin() {
            self.zero(sign)
        } else {
            let field = (e + self.bias()) as u32;
            self.zero(sign) | (field << self.man_bits) | (kept as u32 & self.man_mask())
        }
    }

    /// One rounding from f64 (exact decomposition, then `round_pack`).
    pub fn from_f64(self, x: f64) -> u32 {
        if x.is_nan() {
            return self.nan();
        }
        let sign = x.is_sign_negative();
        if x.is_infinite() {
            return self.infinity(sign);
        }
        if x == 0.0 {
            return self.zero(sign);
        }
        let bits = x.to_bits();
        let biased = ((bits >> 52) & 0x7ff) as i32;
        let frac = bits & ((1u64 << 52) - 1);
        let (sig, exp2) = if biased == 0 {
            (frac, -1074)
        } else {
            (frac | (1 << 52), biased - 1075)
        };
        self.round_pack64(sign, sig, exp2, false)
    }

    /// One rounding from f32 (f32 -> f64 is exact).
    pub fn from_f32(self, x: f32) -> u32 {
        self.from_f64(f64::from(x))
    }

    /// Exact conversion of a small integer (pixel coordinates, loop counts); rounds like any
    /// other conversion when the integer needs more than `man_bits + 1` bits. The floats
    /// [`hw::RayGen`](crate::hw::RayGen) counts are its values for the pixel coordinates.
    pub fn from_int(self, i: i64) -> u32 {
        self.round_pack64(i < 0, i.unsigned_abs(), 0, false)
    }

    /// Exact value of a word (subnormal encodings read as signed zero, NaN as f64 NaN).
    pub fn to_f64(self, w: u32) -> f64 {
        match self.unpack(w) {
            Unpacked::Zero { sign } => {
                if sign {
                    -0.0
                } else {
                    0.0
                }
            }
            Unpacked::Inf { sign } => {
                if sign {
                    f64::NEG_INFINITY
                } else {
                    f64::INFINITY
                }
            }
            Unpacked::NaN => f64::NAN,
            Unpacked::Normal { sign, exp, sig } => {
                let v = sig as f64 * 2f64.powi(exp - self.man_bits as i32);
                if sign {
                    -v
                } else {
                    v
                }
            }
        }
    }

    /// An 8-bit colour channel from a word, as the hardware shader computes it:
    /// clamp to [0, 1] (NaN and -0 give 0), multiply by 255 in the format (one rounding),
    /// then round to the nearest integer, ties to even. The hardware's sequence is
    /// [`units::channel_byte`](crate::units::channel_byte), the golden twin of
    /// [`hw::ChannelByte`](crate::hw::ChannelByte).
    pub fn to_u8(self, w: u32) -> u8 {
        let clamped = if self.is_nan(w) || !self.lt(0, w) {
            0
        } else if self.lt(self.one(), w) {
            self.one()
        } else {
            w
        };
        self.round_to_integer(self.mul(clamped, self.from_int(255)))
            .min(255) as u8
    }

    /// Rounds a non-negative finite word to the nearest integer, ties to even.
    fn round_to_integer(self, w: u32) -> u64 {
        match self.unpack(w) {
            Unpacked::Normal {
                sign: false,
                exp,
                sig,
            } => {
                let frac_bits = self.man_bits as i32 - exp;
                if frac_bits <= 0 {
                    sig << (-frac_bits) as u32
                } else if frac_bits > 40 {
                    0
                } else {
                    let int = sig >> frac_bits;
                    let rem = sig & ((1 << frac_bits) - 1);
                    let half = 1u64 << (frac_bits - 1);
                    int + u64::from(rem > half || (rem == half && int & 1 == 1))
                }
            }
            _ => 0,
        }
    }
}

impl Default for Format {
    fn default() -> Self {
        Format::E7M16
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "e{}m{}", self.exp_bits, self.man_bits)
    }
}

impl FromStr for Format {
    type Err = FormatError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Format::parse(s)
    }
}

impl Format {
    /// The largest format value <= x (x finite).
    pub fn round_down(self, x: f64) -> f64 {
        let w = self.from_f64(x);
        let v = self.to_f64(w);
        if v <= x {
            v
        } else {
            self.step(w, false)
        }
    }

    /// The smallest format value >= x (x finite).
    pub fn round_up(self, x: f64) -> f64 {
        let w = self.from_f64(x);
        let v = self.to_f64(w);
        if v >= x {
            v
        } else {
            self.step(w, true)
        }
    }

    /// The largest format value < x (x finite): one representable step below
    /// [`Format::round_down`] when that is `x` itself.
    pub fn below(self, x: f64) -> f64 {
        let v = self.round_down(x);
        if v < x {
            v
        } else {
            self.step(self.from_f64(v), false)
        }
    }

    /// The smallest format value > x (x finite).
    pub fn above(self, x: f64) -> f64 {
        let v = self.round_up(x);
        if v > x {
            v
        } else {
            self.step(self.from_f64(v), true)
        }
    }

    /// The neighbour of word `w` towards +inf (`up`) or -inf.
    fn step(self, w: u32, up: bool) -> f64 {
        if self.is_zero(w) {
            let m = self.to_f64(self.min_normal(false));
            return if up { m } else { -m };
        }
        let away = up != self.sign_of(w); // moving away from zero grows the magnitude
        let n = if away { w + 1 } else { w - 1 };
        self.to_f64(if self.is_zero(n) { self.zero(false) } else { n })
    }
}
