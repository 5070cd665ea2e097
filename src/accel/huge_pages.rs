//! Large read-mostly arrays (BVH nodes, triangle leaves) on 2 MiB pages.
//!
//! A ray through a large mesh reads a few dozen nodes and leaves scattered
//! over tens of megabytes. With 4 KiB pages each of those reads needs an
//! address translation of its own, and the few thousand a core's TLB holds
//! cover about 12 MiB: in a larger tree most reads also wait for a walk of
//! the page tables. Linux backs memory with transparent 2 MiB pages where a
//! program asks for them (`transparent_hugepage = madvise`, a common
//! default), and then the same TLB covers gigabytes. Embree asks the same
//! for its BVHs (`os_malloc`, `common/sys/alloc.cpp`).

/// Bytes of one transparent huge page on x86-64 and AArch64 Linux.
const HUGE_PAGE: usize = 2 << 20;

/// The whole huge pages inside the `bytes` bytes from address `start`:
/// advice for a range must not reach past the allocation it is about.
fn whole_pages(start: usize, bytes: usize) -> Option<std::ops::Range<usize>> {
    let first = start.checked_next_multiple_of(HUGE_PAGE)?;
    let end = start.checked_add(bytes)? / HUGE_PAGE * HUGE_PAGE;
    (end > first).then_some(first..end)
}

/// An empty vector with room for `capacity` values whose allocation is
/// already advised ([`advise`]): the advice comes before any write by
/// construction.
pub fn with_capacity<T>(capacity: usize) -> Vec<T> {
    let values = Vec::with_capacity(capacity);
    advise(&values);
    values
}

/// `len` copies of `value` in an advised allocation ([`with_capacity`]).
pub fn filled<T: Clone>(len: usize, value: T) -> Vec<T> {
    let mut values = with_capacity(len);
    values.resize(len, value);
    values
}

/// Asks the kernel to back the huge pages inside `values`' allocation with
/// huge pages. Call it before anything is written there: pages already
/// touched keep their size until the kernel collapses them, if ever.
/// Advice only, whose answer is ignored: if the kernel declines, or on
/// other systems, the pages stay as they were, and so does everything else.
fn advise<T>(values: &Vec<T>) {
    let bytes = values.capacity() * std::mem::size_of::<T>();
    let Some(pages) = whole_pages(values.as_ptr() as usize, bytes) else {
        return;
    };
    #[cfg(target_os = "linux")]
    // SAFETY: the range lies inside `values`' own allocation (`whole_pages`),
    // and MADV_HUGEPAGE changes only which pages back it, never its
    // contents, its protection or whether it is mapped.
    #[allow(unsafe_code)]
    unsafe {
        libc::madvise(pages.start as *mut libc::c_void, pages.len(), libc::MADV_HUGEPAGE);
    }
    #[cfg(not(target_os = "linux"))]
    let _ = pages;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advice_covers_only_whole_pages_inside_the_allocation() {
        let mib = 1 << 20;
        // Aligned at both ends: all of it.
        assert_eq!(whole_pages(4 * mib, 6 * mib), Some(4 * mib..10 * mib));
        // Unaligned start and end: rounded inwards.
        assert_eq!(whole_pages(4 * mib + 4096, 6 * mib), Some(6 * mib..10 * mib));
        assert_eq!(whole_pages(3 * mib, 6 * mib), Some(4 * mib..8 * mib));
        // Less than a whole page inside: nothing.
        assert_eq!(whole_pages(3 * mib, 2 * mib), None);
        assert_eq!(whole_pages(4 * mib, 2 * mib - 1), None);
        assert_eq!(whole_pages(0, 0), None);
        // Near the end of the address space: no overflow.
        assert_eq!(whole_pages(usize::MAX - 4096, 8192), None);
        for (start, bytes) in [(12_345, 50 * mib), (2 * mib - 1, 4 * mib + 3), (7 * mib, 9 * mib)] {
            let pages = whole_pages(start, bytes).expect("a whole page inside");
            assert!(pages.start >= start && pages.end <= start + bytes);
            assert_eq!(pages.start % HUGE_PAGE, 0);
            assert_eq!(pages.end % HUGE_PAGE, 0);
        }
    }

    /// Advice changes no value, even given after the memory was written
    /// (where advice that freed or remapped pages would lose it).
    #[test]
    fn advice_keeps_what_the_memory_holds() {
        let value = |i: usize| (i as u32).wrapping_mul(2_654_435_761) | 1;
        let values: Vec<u32> = (0..3 << 20).map(value).collect();
        advise(&values);
        assert!(values.iter().enumerate().all(|(i, &v)| v == value(i)));
    }
}
