//! The lanes a bit mask selects, lowest first: how the vector tests' masks
//! (boxes a ray enters, triangles and spheres it hits) are walked; and one
//! of two values picked by a mask instead of a branch.

/// Iterator over the indices of the set bits of a lane mask, lowest first.
#[derive(Clone, Copy, Debug)]
pub struct SetLanes(u32);

/// The lanes whose bits are set in `mask`, lowest first.
#[inline(always)]
pub fn set_lanes(mask: u32) -> SetLanes {
    SetLanes(mask)
}

impl Iterator for SetLanes {
    type Item = usize;

    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let lane = self.0.trailing_zeros() as usize;
        // Clears the lowest set bit.
        self.0 &= self.0 - 1;
        Some(lane)
    }
}

/// `if condition { a } else { b }` for values the compiler should compute
/// both of and pick without a branch (where the condition is a coin toss,
/// a branch would be mispredicted half the time).
#[inline(always)]
pub fn select(condition: bool, a: f64, b: f64) -> f64 {
    let mask = u64::from(condition).wrapping_neg();
    f64::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_set_bit_once_lowest_first() {
        for mask in 0u32..=255 {
            let lanes: Vec<usize> = set_lanes(mask).collect();
            let expected: Vec<usize> = (0..8).filter(|&lane| mask & (1 << lane) != 0).collect();
            assert_eq!(lanes, expected, "{mask:08b}");
        }
        assert_eq!(set_lanes(1 << 31).collect::<Vec<_>>(), [31]);
    }
}
