//! `SigMul`: the unsigned `S x S -> P` significand multiplier, a combinational leaf.
//!
//! rust-hdl 0.46 only multiplies 16 x 16 bits, so this leaf carries its own Verilog
//! (`always @(*) p = a * b;`, a full-width product because `p` is `P = 2S` bits wide) and an
//! `update()` computing the same product in Rust. Yosys maps it onto MULT18X18 blocks
//! (one for S <= 17 (e7m16), four for S = 24 (e8m23)). No latency of its own: the operator
//! around it registers its inputs and its output. No golden twin of its own: it is the exact
//! product `ma * mb` inside [`Format::mul`](crate::fp::Format::mul), checked through
//! [`FpMul`](super::FpMul).

use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct SigMul<const S: usize, const P: usize> {
    pub a: Signal<In, Bits<S>>,
    pub b: Signal<In, Bits<S>>,
    pub p: Signal<Out, Bits<P>>,
}

impl<const S: usize, const P: usize> Default for SigMul<S, P> {
    fn default() -> Self {
        assert_eq!(P, 2 * S, "SigMul: P must be 2 * S");
        assert!(S <= 32, "SigMul: at most 32-bit operands");
        Self {
            a: Default::default(),
            b: Default::default(),
            p: Default::default(),
        }
    }
}

impl<const S: usize, const P: usize> Logic for SigMul<S, P> {
    fn update(&mut self) {
        let product = self.a.val().to_u64() * self.b.val().to_u64();
        self.p.next = product.into();
    }
    fn connect(&mut self) {
        self.p.connect();
    }
    fn hdl(&self) -> Verilog {
        Verilog::Custom("always @(*) p = a * b;".into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The Rust side of the leaf: full products, including the largest operands.
    #[test]
    fn rust_update_gives_full_width_product() {
        let seed = 7;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut leaf = SigMul::<24, 48>::default();
        for i in 0..1000 {
            let (a, b): (u64, u64) = if i == 0 {
                ((1 << 24) - 1, (1 << 24) - 1)
            } else {
                (rng.gen_range(0..1 << 24), rng.gen_range(0..1 << 24))
            };
            leaf.a.next = a.into();
            leaf.b.next = b.into();
            leaf.update_all();
            leaf.update();
            assert_eq!(leaf.p.val().to_u64(), a * b, "{a} * {b}");
        }
    }
}
