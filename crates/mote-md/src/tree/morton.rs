//! Morton (Z-order) keys: the bits of the three cell coordinates
//! interleaved, so that sorting by key lists the particles octant by octant
//! at every level of the octree (Warren & Salmon 1993, "A parallel hashed
//! oct-tree N-body algorithm").

/// Bits per axis: 3 × 21 = 63 bits fit a `u64`.
pub const BITS: u32 = 21;

/// Spreads the low 21 bits of `v` so that bit k lands on bit 3k.
#[inline]
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// The key of cell (ix, iy, iz), each below 2²¹: x takes the highest bit of
/// every triple, then y, then z, so the octant of a point at level ℓ is
/// `(key >> 3 (20 − ℓ)) & 7` = 4 [x high] + 2 [y high] + [z high].
#[inline]
pub fn key(ix: u64, iy: u64, iz: u64) -> u64 {
    spread(ix) << 2 | spread(iy) << 1 | spread(iz)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interleaves_bits() {
        assert_eq!(key(1, 0, 0), 0b100);
        assert_eq!(key(0, 1, 0), 0b010);
        assert_eq!(key(0, 0, 1), 0b001);
        assert_eq!(key(2, 0, 0), 0b100_000);
        let m = (1 << BITS) - 1;
        assert_eq!(key(m, m, m), (1u64 << 63) - 1);
        // Bit by bit against the definition.
        let (ix, iy, iz) = (0x15_a5a5u64, 0x0f_0f0fu64, 0x1c_3333u64);
        let mut expect = 0u64;
        for b in 0..BITS {
            expect |= ((ix >> b) & 1) << (3 * b + 2);
            expect |= ((iy >> b) & 1) << (3 * b + 1);
            expect |= ((iz >> b) & 1) << (3 * b);
        }
        assert_eq!(key(ix, iy, iz), expect);
    }
}
