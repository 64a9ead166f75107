//! `FpAddSub`: pipelined `eXmY` adder/subtracter (`sub` input: 0 adds, 1 subtracts b), exactly
//! rounded (nearest even), equal bit for bit to its golden twin [`Format::add`] /
//! [`Format::sub`] (src/fp/arith.rs).
//!
//! [`Format::add`]: crate::fp::Format::add
//! [`Format::sub`]: crate::fp::Format::sub
//!
//! Latency 8 clocks, throughput one operation per clock:
//! 1. input registers;
//! 2. unpack (DAZ), special cases, magnitude compare and swap so that |big| >= |small|,
//!    exponent difference saturated to the align shifter's 5 bits (both differences are
//!    formed beside the magnitude compare, which picks one); registered;
//! 3. align the small significand (guard, round and sticky bits below it); registered;
//! 4. add or subtract the aligned significands; registered (the alignment shifter and the
//!    carry chain shared one stage at latency 7, 33 levels, 92.7 MHz on the ECP5: issue 16);
//! 5. normalize with a 5-level leading-zero shifter: shifts by 16 and 8; registered;
//! 6. shifts by 4, 2 and 1; registered;
//! 7. round to nearest even on `S` bits with an unbounded exponent; registered;
//! 8. overflow to infinity / flush below the smallest normal to a signed zero, pack;
//!    registered.
//!
//! An exactly zero sum is +0 unless both operands are negative zeros (x - x = +0,
//! (-0) + (-0) = -0), as IEEE prescribes for round to nearest.
//!
//! Const parameters (derived widths, checked in `default()`): `W = 1+E+M` word, `E` exponent
//! bits, `M` mantissa bits, `S = M+1` significand, `S1 = S+1` rounded significand with carry,
//! `X2 = E+2` two's complement working exponent, `T = S+4` sum (carry, significand, guard,
//! round, sticky). `T` is at most 32 (the shifter has levels 16, 8, 4, 2, 1).

use rust_hdl::prelude::*;

use super::{const_bits, const_index, inf_word, qnan_word};

/// Latency of [`FpAddSub`] in clocks.
pub const ADD_SUB_LATENCY: u32 = 8;

/// Bits of the clamped alignment shift: `S + 3` is below 32 for every format (`T <= 32`).
const ALIGN_SHIFT_BITS: usize = 5;

#[derive(LogicBlock)]
pub struct FpAddSub<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
> {
    pub clock: Signal<In, Clock>,
    pub in_valid: Signal<In, Bit>,
    pub a: Signal<In, Bits<W>>,
    pub b: Signal<In, Bits<W>>,
    /// 1: compute a - b, 0: compute a + b.
    pub sub: Signal<In, Bit>,
    pub out_valid: Signal<Out, Bit>,
    pub result: Signal<Out, Bits<W>>,
    // Stage 1: input registers.
    in_a: DFF<Bits<W>>,
    in_b: DFF<Bits<W>>,
    in_sub: DFF<Bit>,
    in_valid_r: DFF<Bit>,
    // Unpack, compare, swap (combinational).
    sign_a: Signal<Local, Bit>,
    sign_b: Signal<Local, Bit>,
    exp_a: Signal<Local, Bits<E>>,
    exp_b: Signal<Local, Bits<E>>,
    zero_a: Signal<Local, Bit>,
    zero_b: Signal<Local, Bit>,
    inf_a: Signal<Local, Bit>,
    inf_b: Signal<Local, Bit>,
    nan_a: Signal<Local, Bit>,
    nan_b: Signal<Local, Bit>,
    mag_a: Signal<Local, Bits<W>>,
    mag_b: Signal<Local, Bits<W>>,
    /// |a| >= |b| after DAZ: the raw magnitudes' compare, corrected for zeros after it.
    a_first: Signal<Local, Bit>,
    sig_a: Signal<Local, Bits<S>>,
    sig_b: Signal<Local, Bits<S>>,
    diff_ab: Signal<Local, Bits<E>>,
    diff_ba: Signal<Local, Bits<E>>,
    shift_ab: Signal<Local, Bits<ALIGN_SHIFT_BITS>>,
    shift_ba: Signal<Local, Bits<ALIGN_SHIFT_BITS>>,
    // Stage 2 registers.
    big_sig: DFF<Bits<S>>,
    small_sig: DFF<Bits<S>>,
    big_exp: DFF<Bits<E>>,
    /// The exponent difference, saturated to [`ALIGN_SHIFT_BITS`] bits: the align shifter
    /// then has 5 levels, not `E` (the two unused levels sat in the processor's
    /// `add.shift -> add.al_small` paths, issue 16).
    shift: DFF<Bits<ALIGN_SHIFT_BITS>>,
    big_sign: DFF<Bit>,
    eff_sub: DFF<Bit>,
    nan: DFF<Bit>,
    inf: DFF<Bit>,
    inf_sign: DFF<Bit>,
    zero_sign: DFF<Bit>,
    valid2: DFF<Bit>,
    // Align (combinational).
    small_ext: Signal<Local, Bits<T>>,
    small_aligned: Signal<Local, Bits<T>>,
    lost_mask: Signal<Local, Bits<T>>,
    sticky_in: Signal<Local, Bit>,
    small_final: Signal<Local, Bits<T>>,
    // Stage 3 registers: the aligned operands.
    al_big: DFF<Bits<S>>,
    al_small: DFF<Bits<T>>,
    al_exp: DFF<Bits<E>>,
    al_sign: DFF<Bit>,
    al_eff_sub: DFF<Bit>,
    al_nan: DFF<Bit>,
    al_inf: DFF<Bit>,
    al_inf_sign: DFF<Bit>,
    al_zero_sign: DFF<Bit>,
    al_valid: DFF<Bit>,
    big_ext: Signal<Local, Bits<T>>,
    // Stage 4 registers.
    sum: DFF<Bits<T>>,
    sum_exp: DFF<Bits<E>>,
    sum_sign: DFF<Bit>,
    nan3: DFF<Bit>,
    inf3: DFF<Bit>,
    inf_sign3: DFF<Bit>,
    zero_sign3: DFF<Bit>,
    valid3: DFF<Bit>,
    // Normalize (combinational).
    norm16: Signal<Local, Bits<T>>,
    norm8: Signal<Local, Bits<T>>,
    norm4: Signal<Local, Bits<T>>,
    norm2: Signal<Local, Bits<T>>,
    norm1: Signal<Local, Bits<T>>,
    lz16: Signal<Local, Bits<X2>>,
    lz8: Signal<Local, Bits<X2>>,
    lz4: Signal<Local, Bits<X2>>,
    lz2: Signal<Local, Bits<X2>>,
    lz1: Signal<Local, Bits<X2>>,
    // Round, pack (combinational, after stage 6).
    sig: Signal<Local, Bits<S>>,
    round_bit: Signal<Local, Bit>,
    sticky: Signal<Local, Bit>,
    round_up: Signal<Local, Bit>,
    sig_rounded: Signal<Local, Bits<S1>>,
    carry: Signal<Local, Bit>,
    exp_final: Signal<Local, Bits<X2>>,
    exp_negative: Signal<Local, Bit>,
    sign_word: Signal<Local, Bits<W>>,
    zero_word: Signal<Local, Bits<W>>,
    inf_sign_word: Signal<Local, Bits<W>>,
    packed_word: Signal<Local, Bits<W>>,
    // Stage 5 registers.
    mid_norm: DFF<Bits<T>>,
    mid_lz: DFF<Bits<X2>>,
    mid_exp: DFF<Bits<E>>,
    mid_sign: DFF<Bit>,
    mid_nan: DFF<Bit>,
    mid_inf: DFF<Bit>,
    mid_inf_sign: DFF<Bit>,
    mid_zero_sign: DFF<Bit>,
    mid_is_zero: DFF<Bit>,
    mid_valid: DFF<Bit>,
    // Stage 6 registers.
    norm: DFF<Bits<T>>,
    lz: DFF<Bits<X2>>,
    exp4: DFF<Bits<E>>,
    sign4: DFF<Bit>,
    nan4: DFF<Bit>,
    inf4: DFF<Bit>,
    inf_sign4: DFF<Bit>,
    zero_sign4: DFF<Bit>,
    is_zero4: DFF<Bit>,
    valid4: DFF<Bit>,
    // Stage 7: rounded result registers.
    rnd_sig: DFF<Bits<S1>>,
    rnd_exp: DFF<Bits<X2>>,
    rnd_sign: DFF<Bit>,
    rnd_zero_sign: DFF<Bit>,
    rnd_inf_sign: DFF<Bit>,
    rnd_nan: DFF<Bit>,
    rnd_inf: DFF<Bit>,
    rnd_is_zero: DFF<Bit>,
    rnd_valid: DFF<Bit>,
    // Stage 8: output registers.
    out_result: DFF<Bits<W>>,
    out_valid_r: DFF<Bit>,
    // Format constants.
    c_man_bits: Constant<Bits<8>>,
    c_sign_pos: Constant<Bits<8>>,
    c_hidden: Constant<Bits<S>>,
    c_mag_mask: Constant<Bits<W>>,
    c_shift_max: Constant<Bits<ALIGN_SHIFT_BITS>>,
    c_align_bits: Constant<Bits<8>>,
    c_ones: Constant<Bits<T>>,
    c_one: Constant<Bits<T>>,
    c_top16: Constant<Bits<T>>,
    c_top8: Constant<Bits<T>>,
    c_top4: Constant<Bits<T>>,
    c_top2: Constant<Bits<T>>,
    c_top1: Constant<Bits<T>>,
    c_sticky_mask: Constant<Bits<T>>,
    c_exp_sign_pos: Constant<Bits<8>>,
    c_exp_max: Constant<Bits<X2>>,
    c_qnan: Constant<Bits<W>>,
    c_inf: Constant<Bits<W>>,
    c_sign_bit: Constant<Bits<W>>,
}

/// Mask of the top `k` bits of a `t`-bit word (all bits when `k >= t`).
fn top_mask(t: usize, k: usize) -> u64 {
    let ones = (1u64 << t) - 1;
    if k >= t {
        ones
    } else {
        ones & !((1u64 << (t - k)) - 1)
    }
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
    > Default for FpAddSub<W, E, M, S, S1, X2, T>
{
    fn default() -> Self {
        assert!(W == 1 + E + M && S == M + 1 && S1 == S + 1 && X2 == E + 2 && T == S + 4);
        assert!(
            T <= 32,
            "FpAddSub: the normalizer handles at most 31 leading zeros"
        );
        assert!(
            S + 3 < (1 << ALIGN_SHIFT_BITS),
            "FpAddSub: shift clamp must fit the align shifter"
        );
        Self {
            clock: Default::default(),
            in_valid: Default::default(),
            a: Default::default(),
            b: Default::default(),
            sub: Default::default(),
            out_valid: Default::default(),
            result: Default::default(),
            in_a: Default::default(),
            in_b: Default::default(),
            in_sub: Default::default(),
            in_valid_r: Default::default(),
            sign_a: Default::default(),
            sign_b: Default::default(),
            exp_a: Default::default(),
            exp_b: Default::default(),
            zero_a: Default::default(),
            zero_b: Default::default(),
            inf_a: Default::default(),
            inf_b: Default::default(),
            nan_a: Default::default(),
            nan_b: Default::default(),
            mag_a: Default::default(),
            mag_b: Default::default(),
            a_first: Default::default(),
            sig_a: Default::default(),
            sig_b: Default::default(),
            diff_ab: Default::default(),
            diff_ba: Default::default(),
            shift_ab: Default::default(),
            shift_ba: Default::default(),
            big_sig: Default::default(),
            small_sig: Default::default(),
            big_exp: Default::default(),
            shift: Default::default(),
            big_sign: Default::default(),
            eff_sub: Default::default(),
            nan: Default::default(),
            inf: Default::default(),
            inf_sign: Default::default(),
            zero_sign: Default::default(),
            valid2: Default::default(),
            small_ext: Default::default(),
            small_aligned: Default::default(),
            lost_mask: Default::default(),
            sticky_in: Default::default(),
            small_final: Default::default(),
            al_big: Default::default(),
            al_small: Default::default(),
            al_exp: Default::default(),
            al_sign: Default::default(),
            al_eff_sub: Default::default(),
            al_nan: Default::default(),
            al_inf: Default::default(),
            al_inf_sign: Default::default(),
            al_zero_sign: Default::default(),
            al_valid: Default::default(),
            big_ext: Default::default(),
            sum: Default::default(),
            sum_exp: Default::default(),
            sum_sign: Default::default(),
            nan3: Default::default(),
            inf3: Default::default(),
            inf_sign3: Default::default(),
            zero_sign3: Default::default(),
            valid3: Default::default(),
            norm16: Default::default(),
            norm8: Default::default(),
            norm4: Default::default(),
            norm2: Default::default(),
            norm1: Default::default(),
            lz16: Default::default(),
            lz8: Default::default(),
            lz4: Default::default(),
            lz2: Default::default(),
            lz1: Default::default(),
            sig: Default::default(),
            round_bit: Default::default(),
            sticky: Default::default(),
            round_up: Default::default(),
            sig_rounded: Default::default(),
            carry: Default::default(),
            exp_final: Default::default(),
            exp_negative: Default::default(),
            sign_word: Default::default(),
            zero_word: Default::default(),
            inf_sign_word: Default::default(),
            packed_word: Default::default(),
            mid_norm: Default::default(),
            mid_lz: Default::default(),
            mid_exp: Default::default(),
            mid_sign: Default::default(),
            mid_nan: Default::default(),
            mid_inf: Default::default(),
            mid_inf_sign: Default::default(),
            mid_zero_sign: Default::default(),
            mid_is_zero: Default::default(),
            mid_valid: Default::default(),
            norm: Default::default(),
            lz: Default::default(),
            exp4: Default::default(),
            sign4: Default::default(),
            nan4: Default::default(),
            inf4: Default::default(),
            inf_sign4: Default::default(),
            zero_sign4: Default::default(),
            is_zero4: Default::default(),
            valid4: Default::default(),
            rnd_sig: Default::default(),
            rnd_exp: Default::default(),
            rnd_sign: Default::default(),
            rnd_zero_sign: Default::default(),
            rnd_inf_sign: Default::default(),
            rnd_nan: Default::default(),
            rnd_inf: Default::default(),
            rnd_is_zero: Default::default(),
            rnd_valid: Default::default(),
            out_result: Default::default(),
            out_valid_r: Default::default(),
            c_man_bits: const_index(M),
            c_sign_pos: const_index(W - 1),
            c_hidden: const_bits::<S>(1 << M),
            c_mag_mask: const_bits::<W>((1 << (W - 1)) - 1),
            c_shift_max: const_bits::<ALIGN_SHIFT_BITS>((1 << ALIGN_SHIFT_BITS) - 1),
            c_align_bits: const_bits::<8>(ALIGN_SHIFT_BITS as u64),
            c_ones: const_bits::<T>((1 << T) - 1),
            c_one: const_bits::<T>(1),
            c_top16: const_bits::<T>(top_mask(T, 16)),
            c_top8: const_bits::<T>(top_mask(T, 8)),
            c_top4: const_bits::<T>(top_mask(T, 4)),
            c_top2: const_bits::<T>(top_mask(T, 2)),
            c_top1: const_bits::<T>(top_mask(T, 1)),
            c_sticky_mask: const_bits::<T>(7),
            c_exp_sign_pos: const_index(X2 - 1),
            c_exp_max: const_bits::<X2>((1 << E) - 1),
            c_qnan: const_bits::<W>(qnan_word(E, M)),
            c_inf: const_bits::<W>(inf_word(E, M)),
            c_sign_bit: const_bits::<W>(1 << (W - 1)),
        }
    }
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
    > Logic for FpAddSub<W, E, M, S, S1, X2, T>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            in_a,
            in_b,
            in_sub,
            in_valid_r,
            big_sig,
            small_sig,
            big_exp,
            shift,
            big_sign,
            eff_sub,
            nan,
            inf,
            inf_sign,
            zero_sign,
            valid2,
            al_big,
            al_small,
            al_exp,
            al_sign,
            al_eff_sub,
            al_nan,
            al_inf,
            al_inf_sign,
            al_zero_sign,
            al_valid,
            sum,
            sum_exp,
            sum_sign,
            nan3,
            inf3,
            inf_sign3,
            zero_sign3,
            valid3,
            mid_norm,
            mid_lz,
            mid_exp,
            mid_sign,
            mid_nan,
            mid_inf,
            mid_inf_sign,
            mid_zero_sign,
            mid_is_zero,
            mid_valid,
            norm,
            lz,
            exp4,
            sign4,
            nan4,
            inf4,
            inf_sign4,
            zero_sign4,
            is_zero4,
            valid4,
            rnd_sig,
            rnd_exp,
            rnd_sign,
            rnd_zero_sign,
            rnd_inf_sign,
            rnd_nan,
            rnd_inf,
            rnd_is_zero,
            rnd_valid,
            out_result,
            out_valid_r
        );
        // Stage 1.
        self.in_a.d.next = self.a.val();
        self.in_b.d.next = self.b.val();
        self.in_sub.d.next = self.sub.val();
        self.in_valid_r.d.next = self.in_valid.val();

        // Unpack; b's sign is flipped for a subtraction. A zero exponent field is zero (DAZ).
        self.sign_a.next = self.in_a.q.val().get_bit(self.c_sign_pos.val().index());
        self.sign_b.next =
            self.in_b.q.val().get_bit(self.c_sign_pos.val().index()) ^ self.in_sub.q.val();
        self.exp_a.next = self
            .in_a
            .q
            .val()
            .get_bits::<E>(self.c_man_bits.val().index());
        self.exp_b.next = self
            .in_b
            .q
            .val()
            .get_bits::<E>(self.c_man_bits.val().index());
        self.zero_a.next = self.exp_a.val() == 0;
        self.zero_b.next = self.exp_b.val() == 0;
        self.inf_a.next = (self.exp_a.val().all()) & (self.in_a.q.val().get_bits::<M>(0) == 0);
        self.inf_b.next = (self.exp_b.val().all()) & (self.in_b.q.val().get_bits::<M>(0) == 0);
        self.nan_a.next = (self.exp_a.val().all()) & (self.in_a.q.val().get_bits::<M>(0).any());
        self.nan_b.next = (self.exp_b.val().all()) & (self.in_b.q.val().get_bits::<M>(0).any());
        self.mag_a.next = self.in_a.q.val() & self.c_mag_mask.val();
        self.sig_a.next =
            bit_cast::<S, M>(self.in_a.q.val().get_bits::<M>(0)) | self.c_hidden.val();
        if self.zero_a.val() {
            self.sig_a.next = 0.into();
        }
        self.mag_b.next = self.in_b.q.val() & self.c_mag_mask.val();
        self.sig_b.next =
            bit_cast::<S, M>(self.in_b.q.val().get_bits::<M>(0)) | self.c_hidden.val();
        if self.zero_b.val() {
            self.sig_b.next = 0.into();
        }

        // The alignment shift for either order: the exponent difference, saturated to 31
        // because every shift from S+3 on leaves nothing but sticky (S + 3 <= 31, checked
        // in `default()`). Saturating tests the bits above the shifter's five, one LUT after
        // the subtraction; clamping to S+3 took a second carry chain (`in_a -> shift`, 139.1
        // MHz alone on the ECP5, issue 16). Both are ready when the magnitude compare picks
        // one (clamping after the pick: 123 MHz).
        self.diff_ab.next = self.exp_a.val() - self.exp_b.val();
        self.diff_ba.next = self.exp_b.val() - self.exp_a.val();
        self.shift_ab.next = bit_cast::<ALIGN_SHIFT_BITS, E>(self.diff_ab.val());
        if (self.diff_ab.val() >> self.c_align_bits.val()).any() {
            self.shift_ab.next = self.c_shift_max.val();
        }
        self.shift_ba.next = bit_cast::<ALIGN_SHIFT_BITS, E>(self.diff_ba.val());
        if (self.diff_ba.val() >> self.c_align_bits.val()).any() {
            self.shift_ba.next = self.c_shift_max.val();
        }

        // Stage 2: the operand of larger magnitude goes first.
        // The compare starts at the input registers; zeroing a DAZ operand's magnitude in
        // front of it put two LUT levels before its carry chain (`exp_a -> shift`, 136.8 MHz
        // alone on the ECP5: issue 16). A zero goes second unless both are zero.
        self.a_first.next =
            self.zero_b.val() | ((!self.zero_a.val()) & (self.mag_a.val() >= self.mag_b.val()));
        if self.a_first.val() {
            self.big_sig.d.next = self.sig_a.val();
            self.small_sig.d.next = self.sig_b.val();
            self.big_exp.d.next = self.exp_a.val();
            self.shift.d.next = self.shift_ab.val();
            self.big_sign.d.next = self.sign_a.val();
        } else {
            self.big_sig.d.next = self.sig_b.val();
            self.small_sig.d.next = self.sig_a.val();
            self.big_exp.d.next = self.exp_b.val();
            self.shift.d.next = self.shift_ba.val();
            self.big_sign.d.next = self.sign_b.val();
        }
        self.eff_sub.d.next = self.sign_a.val() ^ self.sign_b.val();
        self.nan.d.next = (self.nan_a.val() | self.nan_b.val())
            | ((self.inf_a.val() & self.inf_b.val()) & (self.sign_a.val() ^ self.sign_b.val()));
        self.inf.d.next = self.inf_a.val() | self.inf_b.val();
        if self.inf_a.val() {
            self.inf_sign.d.next = self.sign_a.val();
        } else {
            self.inf_sign.d.next = self.sign_b.val();
        }
        self.zero_sign.d.next = self.sign_a.val() & self.sign_b.val();
        self.valid2.d.next = self.in_valid_r.q.val();

        // Align: small >> shift with everything shifted out collected in a sticky bit.
        self.small_ext.next = bit_cast::<T, S>(self.small_sig.q.val()) << 3;
        self.small_aligned.next = self.small_ext.val() >> self.shift.q.val();
        self.lost_mask.next = !(self.c_ones.val() << self.shift.q.val());
        self.sticky_in.next = (self.small_ext.val() & self.lost_mask.val()).any();
        self.small_final.next = self.small_aligned.val();
        if self.sticky_in.val() {
            self.small_final.next = self.small_aligned.val() | self.c_one.val();
        }

        // Stage 3: the aligned operands, so that the add's carry chain starts at a register.
        self.al_big.d.next = self.big_sig.q.val();
        self.al_small.d.next = self.small_final.val();
        self.al_exp.d.next = self.big_exp.q.val();
        self.al_sign.d.next = self.big_sign.q.val();
        self.al_eff_sub.d.next = self.eff_sub.q.val();
        self.al_nan.d.next = self.nan.q.val();
        self.al_inf.d.next = self.inf.q.val();
        self.al_inf_sign.d.next = self.inf_sign.q.val();
        self.al_zero_sign.d.next = self.zero_sign.q.val();
        self.al_valid.d.next = self.valid2.q.val();

        // Stage 4.
        self.big_ext.next = bit_cast::<T, S>(self.al_big.q.val()) << 3;
        if self.al_eff_sub.q.val() {
            self.sum.d.next = self.big_ext.val() - self.al_small.q.val();
        } else {
            self.sum.d.next = self.big_ext.val() + self.al_small.q.val();
        }
        self.sum_exp.d.next = self.al_exp.q.val();
        self.sum_sign.d.next = self.al_sign.q.val();
        self.nan3.d.next = self.al_nan.q.val();
        self.inf3.d.next = self.al_inf.q.val();
        self.inf_sign3.d.next = self.al_inf_sign.q.val();
        self.zero_sign3.d.next = self.al_zero_sign.q.val();
        self.valid3.d.next = self.al_valid.q.val();

        // Normalize: shift left until the top bit is set, counting the shift.
        self.norm16.next = self.sum.q.val();
        self.lz16.next = 0.into();
        if (self.sum.q.val() & self.c_top16.val()) == 0 {
            self.norm16.next = self.sum.q.val() << 16;
            self.lz16.next = 16.into();
        }
        self.norm8.next = self.norm16.val();
        self.lz8.next = self.lz16.val();
        if (self.norm16.val() & self.c_top8.val()) == 0 {
            self.norm8.next = self.norm16.val() << 8;
            self.lz8.next = self.lz16.val() + 8;
        }
        // Stage 5: half-way through normalization (shifts by 16 and 8 done).
        self.mid_norm.d.next = self.norm8.val();
        self.mid_lz.d.next = self.lz8.val();
        self.mid_exp.d.next = self.sum_exp.q.val();
        self.mid_sign.d.next = self.sum_sign.q.val();
        self.mid_nan.d.next = self.nan3.q.val();
        self.mid_inf.d.next = self.inf3.q.val();
        self.mid_inf_sign.d.next = self.inf_sign3.q.val();
        self.mid_zero_sign.d.next = self.zero_sign3.q.val();
        self.mid_is_zero.d.next = self.sum.q.val() == 0;
        self.mid_valid.d.next = self.valid3.q.val();

        self.norm4.next = self.mid_norm.q.val();
        self.lz4.next = self.mid_lz.q.val();
        if (self.mid_norm.q.val() & self.c_top4.val()) == 0 {
            self.norm4.next = self.mid_norm.q.val() << 4;
            self.lz4.next = self.mid_lz.q.val() + 4;
        }
        self.norm2.next = self.norm4.val();
        self.lz2.next = self.lz4.val();
        if (self.norm4.val() & self.c_top2.val()) == 0 {
            self.norm2.next = self.norm4.val() << 2;
            self.lz2.next = self.lz4.val() + 2;
        }
        self.norm1.next = self.norm2.val();
        self.lz1.next = self.lz2.val();
        if (self.norm2.val() & self.c_top1.val()) == 0 {
            self.norm1.next = self.norm2.val() << 1;
            self.lz1.next = self.lz2.val() + 1;
        }
        // Stage 6.
        self.norm.d.next = self.norm1.val();
        self.lz.d.next = self.lz1.val();
        self.exp4.d.next = self.mid_exp.q.val();
        self.sign4.d.next = self.mid_sign.q.val();
        self.nan4.d.next = self.mid_nan.q.val();
        self.inf4.d.next = self.mid_inf.q.val();
        self.inf_sign4.d.next = self.mid_inf_sign.q.val();
        self.zero_sign4.d.next = self.mid_zero_sign.q.val();
        self.is_zero4.d.next = self.mid_is_zero.q.val();
        self.valid4.d.next = self.mid_valid.q.val();

        // Round: the top S bits are the significand, then round bit, then sticky bits.
        self.sig.next = self.norm.q.val().get_bits::<S>(4);
        self.round_bit.next = self.norm.q.val().get_bit(3);
        self.sticky.next = (self.norm.q.val() & self.c_sticky_mask.val()).any();
        self.round_up.next = self.round_bit.val() & (self.sticky.val() | self.sig.val().get_bit(0));
        self.sig_rounded.next = bit_cast::<S1, S>(self.sig.val()) + self.round_up.val();
        // The top bit of the sum weighs 2^(big_exp + 1). The rounding's carry out (bit S of
        // `sig_rounded`) is read off `sig` (all ones, rounding up), beside the increment.
        self.carry.next = self.sig.val().all() & self.round_up.val();
        self.exp_final.next =
            ((bit_cast::<X2, E>(self.exp4.q.val()) + 1) - self.lz.q.val()) + self.carry.val();
        // Stage 7, registered: the rounded significand and exponent (splits the logic depth).
        self.rnd_sig.d.next = self.sig_rounded.val();
        self.rnd_exp.d.next = self.exp_final.val();
        self.rnd_sign.d.next = self.sign4.q.val();
        self.rnd_zero_sign.d.next = self.zero_sign4.q.val();
        self.rnd_inf_sign.d.next = self.inf_sign4.q.val();
        self.rnd_nan.d.next = self.nan4.q.val();
        self.rnd_inf.d.next = self.inf4.q.val();
        self.rnd_is_zero.d.next = self.is_zero4.q.val();
        self.rnd_valid.d.next = self.valid4.q.val();

        self.exp_negative.next = self
            .rnd_exp
            .q
            .val()
            .get_bit(self.c_exp_sign_pos.val().index());
        self.sign_word.next = 0.into();
        if self.rnd_sign.q.val() {
            self.sign_word.next = self.c_sign_bit.val();
        }
        self.zero_word.next = 0.into();
        if self.rnd_zero_sign.q.val() {
            self.zero_word.next = self.c_sign_bit.val();
        }
        self.inf_sign_word.next = self.c_inf.val();
        if self.rnd_inf_sign.q.val() {
            self.inf_sign_word.next = self.c_inf.val() | self.c_sign_bit.val();
        }
        self.packed_word.next = (bit_cast::<W, E>(self.rnd_exp.q.val().get_bits::<E>(0))
            << self.c_man_bits.val())
            | bit_cast::<W, M>(self.rnd_sig.q.val().get_bits::<M>(0));

        // Stage 8.
        if self.rnd_nan.q.val() {
            self.out_result.d.next = self.c_qnan.val();
        } else if self.rnd_inf.q.val() {
            self.out_result.d.next = self.inf_sign_word.val();
        } else if self.rnd_is_zero.q.val() {
            self.out_result.d.next = self.zero_word.val();
        } else if (!self.exp_negative.val()) & (self.rnd_exp.q.val() >= self.c_exp_max.val()) {
            self.out_result.d.next = self.c_inf.val() | self.sign_word.val();
        } else if self.exp_negative.val() | (self.rnd_exp.q.val() == 0) {
            self.out_result.d.next = self.sign_word.val();
        } else {
            self.out_result.d.next = self.packed_word.val() | self.sign_word.val();
        }
        self.out_valid_r.d.next = self.rnd_valid.q.val();
        self.result.next = self.out_result.q.val();
        self.out_valid.next = self.out_valid_r.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::{vectors, Format};
    use crate::hw::fp::test_harness::{assert_matches_model, run_pipelined};

    fn check<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
    >(
        f: Format,
        sub: bool,
        seed: u64,
        n: usize,
    ) {
        println!("seed {seed}");
        let v = vectors::random_pairs(f, seed, n);
        let got = run_pipelined(
            FpAddSub::<W, E, M, S, S1, X2, T>::default(),
            &v,
            ADD_SUB_LATENCY as usize,
            |u, c| u.clock.next = Clock { clk: c },
            |u, valid, a, b| {
                u.in_valid.next = valid;
                u.sub.next = sub;
                u.a.next = (a as u64).into();
                u.b.next = (b as u64).into();
            },
            |u| (u.out_valid.val(), u.result.val().to_u64() as u32),
        );
        if sub {
            assert_matches_model(&format!("sub {f}"), &v, &got, |a, b| f.sub(a, b));
        } else {
            assert_matches_model(&format!("add {f}"), &v, &got, |a, b| f.add(a, b));
        }
    }

    #[test]
    fn rust_hdl_simulation_matches_model_e7m16() {
        check::<24, 7, 16, 17, 18, 9, 21>(Format::E7M16, false, 201, 400);
        check::<24, 7, 16, 17, 18, 9, 21>(Format::E7M16, true, 202, 400);
    }

    #[test]
    fn rust_hdl_simulation_matches_model_e8m23() {
        check::<32, 8, 23, 24, 25, 10, 28>(Format::E8M23, false, 203, 300);
        check::<32, 8, 23, 24, 25, 10, 28>(Format::E8M23, true, 204, 300);
    }
}
