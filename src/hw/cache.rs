//! What the processor's three read-only caches share: their shape (sets and ways, the
//! paper's 512 items at most), the check of a shape, and an empty tag RAM.
//!
//! Each has 1, 2 or 4 ways, a tag RAM per way read at once (a way the cache does not have is
//! never written, and synthesis removes it). Where the words are read after the tag compare
//! (the instance cache, [`super::engine::InstanceRays`], and the triangle cache,
//! [`super::TriangleTester`], whose buffers keep the way they hit in) the words of every way
//! are in one RAM deep enough for all of them (line `set << way_shift | way`, so its block
//! RAMs are those of the direct-mapped cache of as many items); the node cache
//! ([`super::TraversalUnit`]) reads a set's words with its tags, so each way's words have a
//! RAM of their own. Each cache fills a set's ways in turn, counted by a [`FillCounts`].
//!
//! Golden twin: none; a cache changes when a word arrives, never which word.

use rust_hdl::prelude::*;

/// Most items of a cache (the paper's 512): its RAMs are this deep, a smaller cache uses the
/// first lines.
pub const MAX_CACHE_SETS: u32 = 512;

/// Most ways of a set-associative cache (the instance cache has this many tag RAMs; a
/// smaller cache leaves the others unwritten, and synthesis removes them).
pub const MAX_CACHE_WAYS: u32 = 4;

/// Whether a cache can have `sets` sets of `ways` ways: 1, 2 or 4 ways, and sets a power of
/// two with `sets * ways` at most [`MAX_CACHE_SETS`], or 0 sets for none.
pub fn cache_shape_supported(sets: u32, ways: u32) -> bool {
    ways.is_power_of_two()
        && ways <= MAX_CACHE_WAYS
        && (sets == 0 || (sets.is_power_of_two() && sets * ways <= MAX_CACHE_SETS))
}

/// How far a set's lines are apart in a RAM that holds every way: `log2(ways)`.
pub fn way_shift(ways: u32) -> u32 {
    ways.trailing_zeros()
}

/// A cache's tag RAM, every set's word zero (its valid bit clear): a block RAM read before it
/// is written must not give Icarus an undefined tag.
pub fn empty_cache_tags<const B: usize>() -> RAM<Bits<B>, 9> {
    RAM::new(
        (0..u64::from(MAX_CACHE_SETS))
            .map(|k| (Bits::<9>::from(k), Bits::<B>::from(0u64)))
            .collect(),
    )
}

/// Per set, the way its next fill writes: round robin over the set's ways.
///
/// Contract: `way` is the count of the set `read_set` named a clock before, masked to the
/// ways there are (`way_mask`, ways - 1), so with one way it is the constant 0 and synthesis
/// removes the counts' block RAM (read unmasked, it was kept: stop 52's placement). A clock
/// with `fill` high steps `fill_set`'s count past `fill_way`, the way that fill wrote (the
/// cache's own copy of `way`, read a clock or more before). Latency one clock, a fill every
/// clock.
///
/// Golden twin: none (which way a line takes changes a hit, never a word); the caches' tests
/// check the turns with this module's test helper `assert_fills_in_turn`.
#[derive(LogicBlock)]
pub struct FillCounts {
    pub clock: Signal<In, Clock>,
    pub read_set: Signal<In, Bits<9>>,
    pub way_mask: Signal<In, Bits<2>>,
    pub way: Signal<Out, Bits<2>>,
    pub fill: Signal<In, Bit>,
    pub fill_set: Signal<In, Bits<9>>,
    pub fill_way: Signal<In, Bits<2>>,
    counts: RAM<Bits<2>, 9>,
}

impl Default for FillCounts {
    fn default() -> Self {
        Self {
            clock: Default::default(),
            read_set: Default::default(),
            way_mask: Default::default(),
            way: Default::default(),
            fill: Default::default(),
            fill_set: Default::default(),
            fill_way: Default::default(),
            counts: empty_cache_tags(),
        }
    }
}

impl Logic for FillCounts {
    #[hdl_gen]
    fn update(&mut self) {
        self.counts.read_clock.next = self.clock.val();
        self.counts.write_clock.next = self.clock.val();
        self.counts.read_address.next = self.read_set.val();
        self.way.next = self.counts.read_data.val() & self.way_mask.val();
        self.counts.write_address.next = self.fill_set.val();
        self.counts.write_data.next = (self.fill_way.val() + 1) & self.way_mask.val();
        self.counts.write_enable.next = self.fill.val();
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Asserts that each set's fills, `(set, way)` in the order they happened, took the
    /// set's ways in turn from way 0, and that each set listed in `wrapping` filled more lines
    /// than it has ways (so that its turn wrapped). One count for the whole cache fails this
    /// as soon as two sets fill.
    pub(crate) fn assert_fills_in_turn(fills: &[(u32, u32)], ways: u32, wrapping: &[u32]) {
        let mut sets: Vec<u32> = fills.iter().map(|fill| fill.0).collect();
        sets.sort_unstable();
        sets.dedup();
        for set in sets {
            let taken: Vec<u32> = fills
                .iter()
                .filter(|fill| fill.0 == set)
                .map(|fill| fill.1)
                .collect();
            let in_turn: Vec<u32> = (0..taken.len() as u32).map(|k| k % ways).collect();
            assert_eq!(taken, in_turn, "{ways} ways, set {set}");
            if wrapping.contains(&set) {
                assert!(
                    taken.len() > ways as usize,
                    "{ways} ways, set {set}: {taken:?}"
                );
            }
        }
    }

    /// The shapes the CLI accepts: every power-of-two set count with 1, 2 or 4 ways up to 512
    /// items, and none of 3 ways, 1,024 items, or a set count that is not a power of two.
    #[test]
    fn shapes() {
        assert!(cache_shape_supported(512, 1));
        assert!(cache_shape_supported(256, 2));
        assert!(cache_shape_supported(128, 4));
        assert!(cache_shape_supported(0, 2));
        assert!(!cache_shape_supported(512, 2));
        assert!(!cache_shape_supported(256, 4));
        assert!(!cache_shape_supported(64, 3));
        assert!(!cache_shape_supported(96, 1));
        assert!(!cache_shape_supported(32, 8));
        assert_eq!((way_shift(1), way_shift(2), way_shift(4)), (0, 1, 2));
    }
}
