//! Exactly rounded arithmetic on `eXmY` words: each operation computes the exact result with
//! wide integers and rounds once through [`Format::round_pack`].
//!
//! Each operation is the golden twin of a pipelined operator in src/hw/fp/ (named in its doc),
//! which must equal it bit for bit.

use super::format::{Format, Unpacked};

impl Format {
    /// Exactly rounded `a + b`. Golden twin of [`hw::fp::FpAddSub`](crate::hw::fp::FpAddSub)
    /// (src/hw/fp/add_sub.rs).
    pub fn add(self, a: u32, b: u32) -> u32 {
        use Unpacked::*;
        match (self.unpack(a), self.unpack(b)) {
            (NaN, _) | (_, NaN) => self.nan(),
            (Inf { sign: sa }, Inf { sign: sb }) if sa != sb => self.nan(),
            (Inf { sign }, _) | (_, Inf { sign }) => self.infinity(sign),
            // Round to nearest: an exact zero sum is +0 unless both addends are -0.
            (Zero { sign: sa }, Zero { sign: sb }) => self.zero(sa && sb),
            (Zero { .. }, Normal { .. }) => self.canonical(b),
            (Normal { .. }, Zero { .. }) => self.canonical(a),
            (
                Normal {
                    sign: sa,
                    exp: ea,
                    sig: ma,
                },
                Normal {
                    sign: sb,
                    exp: eb,
                    sig: mb,
                },
            ) => {
                // Order by magnitude so the result takes the sign of the larger operand.
                let ((sa, ea, ma), (sb, eb, mb)) = if (ea, ma) >= (eb, mb) {
                    ((sa, ea, ma), (sb, eb, mb))
                } else {
                    ((sb, eb, mb), (sa, ea, ma))
                };
                let gap = (ea - eb) as u32;
                let subtract = sa != sb;
                let low_exp = eb - self.man_bits as i32;
                if gap >= self.man_bits + 3 {
                    // The smaller operand lies wholly below the rounding position of the larger
                    // one shifted left by 2: it only decides the sticky bit.
                    let big = ma << 2;
                    let sig = if subtract { big - 1 } else { big };
                    self.round_pack64(sa, sig, ea - self.man_bits as i32 - 2, true)
                } else {
                    // gap <= man_bits + 2, so the aligned sum fits 2 * 24 + 3 bits.
                    let big = ma << gap;
                    let small = mb;
                    if subtract && big == small {
                        self.zero(false) // x - x is +0 when rounding to nearest
                    } else if subtract {
                        self.round_pack64(sa, big - small, low_exp, false)
                    } else {
                        self.round_pack64(sa, big + small, low_exp, false)
                    }
                }
            }
        }
    }

    /// Exactly rounded `a - b`. Golden twin of [`hw::fp::FpAddSub`](crate::hw::fp::FpAddSub)
    /// with `sub` set (src/hw/fp/add_sub.rs).
    pub fn sub(self, a: u32, b: u32) -> u32 {
        self.add(a, self.flip_sign(b))
    }

    /// Exactly rounded `a * b`. Golden twin of [`hw::fp::FpMul`](crate::hw::fp::FpMul)
    /// (src/hw/fp/mul.rs).
    pub fn mul(self, a: u32, b: u32) -> u32 {
        use Unpacked::*;
        let sign = self.sign_of(a) != self.sign_of(b);
        match (self.unpack(a), self.unpack(b)) {
            (NaN, _) | (_, NaN) => self.nan(),
            (Inf { .. }, Zero { .. }) | (Zero { .. }, Inf { .. }) => self.nan(),
            (Inf { .. }, _) | (_, Inf { .. }) => self.infinity(sign),
            (Zero { .. }, _) | (_, Zero { .. }) => self.zero(sign),
            (
                Normal {
                    exp: ea, sig: ma, ..
                },
                Normal {
                    exp: eb, sig: mb, ..
                },
            ) => self.round_pack64(sign, ma * mb, ea + eb - 2 * self.man_bits as i32, false),
        }
    }

    /// Exactly rounded `a / b`. Golden twin of [`hw::fp::FpDiv`](crate::hw::fp::FpDiv)
    /// (src/hw/fp/div.rs).
    pub fn div(self, a: u32, b: u32) -> u32 {
        use Unpacked::*;
        let sign = self.sign_of(a) != self.sign_of(b);
        match (self.unpack(a), self.unpack(b)) {
            (NaN, _) | (_, NaN) => self.nan(),
            (Inf { .. }, Inf { .. }) | (Zero { .. }, Zero { .. }) => self.nan(),
            (Inf { .. }, _) | (_, Zero { .. }) => self.infinity(sign),
            (Zero { .. }, _) | (_, Inf { .. }) => self.zero(sign),
            (
                Normal {
                    exp: ea, sig: ma, ..
                },
                Normal {
                    exp: eb, sig: mb, ..
                },
            ) => {
                // ma / mb lies in (1/2, 2); M+3 extra quotient bits leave at least M+2 bits
                // above the remainder, as round_pack's sticky contract needs.
                let extra = self.man_bits + 3;
                let num = ma << extra; // at most 24 + 26 bits
                let den = mb;
                self.round_pack64(sign, num / den, ea - eb - extra as i32, num % den != 0)
            }
        }
    }

    /// Exactly rounded square root; sqrt(-0) = -0, negative operands give NaN. Golden twin of
    /// [`hw::fp::FpSqrt`](crate::hw::fp::FpSqrt) (src/hw/fp/sqrt.rs).
    pub fn sqrt(self, a: u32) -> u32 {
        match self.unpack(a) {
            Unpacked::NaN | Unpacked::Normal { sign: true, .. } | Unpacked::Inf { sign: true } => {
                self.nan()
            }
            Unpacked::Zero { sign } => self.zero(sign),
            Unpacked::Inf { sign: false } => self.infinity(false),
            Unpacked::Normal { exp, sig, .. } => {
                // value = sig * 2^q; make q even, then scale by 2^(2k) so the integer root has
                // at least man_bits + 3 bits (round_pack's sticky contract).
                let mut q = exp - self.man_bits as i32;
                let mut radicand = u128::from(sig);
                if q % 2 != 0 {
                    radicand <<= 1;
                    q -= 1;
                }
                let k = self.man_bits + 3;
                radicand <<= 2 * k;
                let root = isqrt(radicand);
                self.round_pack(false, root, q / 2 - k as i32, root * root != radicand)
            }
        }
    }

    /// IEEE `<`: false when either operand is NaN; -0 and +0 are equal. Golden twin of
    /// [`hw::fp::FpCompare`](crate::hw::fp::FpCompare)'s `lt` (src/hw/fp/compare.rs), as
    /// are [`Format::le`] and [`Format::eq`] of its `le` and `eq`.
    pub fn lt(self, a: u32, b: u32) -> bool {
        match (self.order_key(a), self.order_key(b)) {
            (Some(x), Some(y)) => x < y,
            _ => false,
        }
    }
    /// IEEE `<=`: false when either operand is NaN.
    pub fn le(self, a: u32, b: u32) -> bool {
        match (self.order_key(a), self.order_key(b)) {
            (Some(x), Some(y)) => x <= y,
            _ => false,
        }
    }
    /// IEEE `==`: false when either operand is NaN; -0 == +0.
    pub fn eq(self, a: u32, b: u32) -> bool {
        match (self.order_key(a), self.order_key(b)) {
            (Some(x), Some(y)) => x == y,
            _ => false,
        }
    }

    /// IEEE 754-2019 `minimum`: NaN if either is NaN, and -0 < +0.
    pub fn min(self, a: u32, b: u32) -> u32 {
        self.min_max(a, b, true)
    }
    /// IEEE 754-2019 `maximum`: NaN if either is NaN, and -0 < +0.
    pub fn max(self, a: u32, b: u32) -> u32 {
        self.min_max(a, b, false)
    }

    /// Clears the sign (of the flushed operand); NaN gives the canonical NaN.
    pub fn abs(self, a: u32) -> u32 {
        let c = self.canonical(a);
        if self.is_nan(c) {
            c
        } else {
            c & !self.sign_mask()
        }
    }
    /// Flips the sign (of the flushed operand); NaN gives the canonical NaN.
    pub fn neg(self, a: u32) -> u32 {
        let c = self.canonical(a);
        if self.is_nan(c) {
            c
        } else {
            self.flip_sign(c)
        }
    }

    fn flip_sign(self, a: u32) -> u32 {
        a ^ self.sign_mask()
    }

    /// The word as it is read: subnormal encodings become signed zero, every NaN the canonical
    /// one, bits above the format's width are dropped.
    pub fn canonical(self, a: u32) -> u32 {
        match self.unpack(a) {
            Unpacked::Zero { sign } => self.zero(sign),
            Unpacked::NaN => self.nan(),
            _ => a & self.word_mask(),
        }
    }

    /// A totally ordered integer for non-NaN words, equal for both zeros.
    fn order_key(self, a: u32) -> Option<i64> {
        if self.is_nan(a) {
            return None;
        }
        let magnitude = if self.is_zero(a) {
            0
        } else {
            i64::from(a & (self.sign_mask() - 1))
        };
        Some(if self.sign_of(a) {
            -magnitude
        } else {
            magnitude
        })
    }

    fn min_max(self, a: u32, b: u32, want_min: bool) -> u32 {
        if self.is_nan(a) || self.is_nan(b) {
            return self.nan();
        }
        let (a, b) = (self.canonical(a), self.canonical(b));
        // Ordering the sign-magnitude words with -0 below +0.
        let key = |w: u32| {
            let m = i64::from(w & (self.sign_mask() - 1));
            if self.sign_of(w) {
                -m - 1
            } else {
                m
            }
        };
        if (key(a) <= key(b)) == want_min {
            a
        } else {
            b
        }
    }
}

/// Floor of the square root, bit by bit.
fn isqrt(n: u128) -> u128 {
    let mut rem = n;
    let mut root = 0u128;
    let mut bit = 1u128 << 126;
    while bit > n {
        bit >>= 2;
    }
    while bit != 0 {
        if rem >= root + bit {
            rem -= root + bit;
            root = (root >> 1) + bit;
        } else {
            root >>= 1;
        }
        bit >>= 2;
    }
    root
}

/// An operator of the `dynrt fp` command and of the hardware operator set. All but `Sqrt` are
/// binary; `Sqrt` is the one unary operator: it reads `a` and ignores `b`, so the vector files
/// and testbenches keep their `a b` lines for every operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Sqrt,
    Lt,
    Le,
    Eq,
}

impl BinOp {
    pub const ALL: [BinOp; 8] = [
        BinOp::Add,
        BinOp::Sub,
        BinOp::Mul,
        BinOp::Div,
        BinOp::Sqrt,
        BinOp::Lt,
        BinOp::Le,
        BinOp::Eq,
    ];

    pub fn parse(name: &str) -> Option<BinOp> {
        BinOp::ALL.into_iter().find(|op| op.name() == name)
    }
    pub fn name(self) -> &'static str {
        match self {
            BinOp::Add => "add",
            BinOp::Sub => "sub",
            BinOp::Mul => "mul",
            BinOp::Div => "div",
            BinOp::Sqrt => "sqrt",
            BinOp::Lt => "lt",
            BinOp::Le => "le",
            BinOp::Eq => "eq",
        }
    }
    pub fn is_comparison(self) -> bool {
        matches!(self, BinOp::Lt | BinOp::Le | BinOp::Eq)
    }
    /// True for `Sqrt`, which ignores its second operand.
    pub fn is_unary(self) -> bool {
        self == BinOp::Sqrt
    }
    /// The result word (0 or 1 for comparisons); a unary operator ignores `b`.
    pub fn eval(self, f: Format, a: u32, b: u32) -> u32 {
        match self {
            BinOp::Add => f.add(a, b),
            BinOp::Sub => f.sub(a, b),
            BinOp::Mul => f.mul(a, b),
            BinOp::Div => f.div(a, b),
            BinOp::Sqrt => f.sqrt(a),
            BinOp::Lt => u32::from(f.lt(a, b)),
            BinOp::Le => u32::from(f.le(a, b)),
            BinOp::Eq => u32::from(f.eq(a, b)),
        }
    }
}

impl std::fmt::Display for BinOp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
