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
//! RAM of their own. The instance cache fills a set's ways in turn (a way number per set); the
//! others take the ways in turn over the whole cache (no RAM read before a write).
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

#[cfg(test)]
mod tests {
    use super::*;

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
